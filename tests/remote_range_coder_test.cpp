// The range coder of the cells encoding (remote/range_coder.h): bits and direct bits round-trip
// through adaptive probabilities, the decoder reads exactly the encoder's bytes (so a cut or a
// trailing byte shows), and no bit costs less than the floor the decoders' limits rest on.
#include <algorithm>
#include <bit>
#include <cstdint>
#include <cstdio>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "remote/range_coder.h"

namespace isowall::remote {
namespace {

struct Symbol {
    int context;  // -1: direct bits
    std::uint32_t value;
    int bits;
};

std::vector<Symbol> random_symbols(std::size_t n, double skew, unsigned seed) {
    std::mt19937 rng(seed);
    std::bernoulli_distribution one(skew);
    std::uniform_int_distribution<int> context(-1, 7), width(1, 32);
    std::vector<Symbol> out;
    for (std::size_t i = 0; i < n; ++i) {
        const int c = context(rng);
        if (c < 0) {
            const int w = width(rng);
            out.push_back({c, static_cast<std::uint32_t>(rng()) >> (32 - w), w});
        } else {
            out.push_back({c, one(rng) ? 1u : 0u, 1});
        }
    }
    return out;
}

std::vector<std::uint8_t> encode(const std::vector<Symbol>& symbols) {
    RangeEncoder e;
    std::vector<BitProbability> p(8);
    for (const Symbol& s : symbols) {
        if (s.context < 0)
            e.direct(s.value, s.bits);
        else
            e.bit(p[static_cast<std::size_t>(s.context)], s.value);
    }
    return e.finish();
}

// Decodes `symbols`' shapes from `bytes`; true when every value came back.
bool decodes(const std::vector<std::uint8_t>& bytes, const std::vector<Symbol>& symbols,
             RangeDecoder* out = nullptr) {
    RangeDecoder d(bytes);
    std::vector<BitProbability> p(8);
    bool same = true;
    for (const Symbol& s : symbols) {
        const std::uint32_t v =
            s.context < 0 ? d.direct(s.bits) : d.bit(p[static_cast<std::size_t>(s.context)]);
        same = same && v == s.value;
    }
    if (out) *out = d;
    return same;
}

TEST(RangeCoder, NothingCodedIsFiveBytesThatDecodeToTheirEnd) {
    const auto bytes = encode({});
    EXPECT_EQ(bytes.size(), 5u);
    RangeDecoder d(bytes);
    EXPECT_TRUE(d.at_end());
}

TEST(RangeCoder, SkewedAndEvenBitsAndDirectBitsRoundTrip) {
    for (const double skew : {0.5, 0.1, 0.01, 0.999}) {
        const auto symbols = random_symbols(20000, skew, 7);
        const auto bytes = encode(symbols);
        RangeDecoder d(std::span<const std::uint8_t>{});
        EXPECT_TRUE(decodes(bytes, symbols, &d)) << "skew " << skew;
        EXPECT_TRUE(d.at_end()) << "skew " << skew << ": the decoder ends on the last byte";
    }
}

TEST(RangeCoder, ACutStreamOverrunsAndALongerOneDoesNotEnd) {
    const auto symbols = random_symbols(3000, 0.2, 11);
    const auto bytes = encode(symbols);
    for (std::size_t n = 0; n < bytes.size(); ++n) {
        RangeDecoder d(std::span<const std::uint8_t>{});
        decodes(std::vector<std::uint8_t>(bytes.begin(), bytes.begin() + long(n)), symbols, &d);
        EXPECT_GT(d.overrun(), 0u) << "cut to " << n << " of " << bytes.size();
        EXPECT_FALSE(d.at_end());
    }
    auto longer = bytes;
    longer.push_back(0);
    RangeDecoder d(std::span<const std::uint8_t>{});
    EXPECT_TRUE(decodes(longer, symbols, &d));
    EXPECT_FALSE(d.at_end()) << "a trailing byte";
}

// A young probability moves by 1/2, 1/2, 1/4 (x4), 1/8 (x8), 1/16 (x16) of its distance, then
// by 1/32 from its 30th bit on, as range_coder.h says.
TEST(RangeCoder, AYoungProbabilityLearnsFastThenSettles) {
    BitProbability prob;
    std::vector<int> shifts;
    for (int i = 0; i < 40; ++i) {
        const std::uint32_t before = prob.p;
        range::update(prob, 1);
        const std::uint32_t moved = before - prob.p;
        int shift = 0;
        while (shift < 16 && (before >> shift) != moved) ++shift;
        shifts.push_back(prob.p == range::kLeast ? -1 : shift);
    }
    std::vector<int> expected;
    for (int i = 0; i < 40; ++i)
        expected.push_back(
            std::min(range::kMoveBits, static_cast<int>(std::bit_width(unsigned(i) + 2)) - 1));
    // The floor stops it first: count only the moves above kLeast.
    for (std::size_t i = 0; i < shifts.size() && shifts[i] >= 0; ++i)
        EXPECT_EQ(shifts[i], expected[i]) << "bit " << i;
    EXPECT_EQ(shifts[0], 1) << "the first bit moves it half way";
    EXPECT_EQ(prob.p, range::kLeast) << "40 ones take it to its floor";
    EXPECT_EQ(prob.seen, range::kSettled);
    BitProbability settled;
    settled.seen = range::kSettled;
    range::update(settled, 0);
    EXPECT_EQ(settled.p, (1u << 15) + (1u << 10)) << "a settled one moves 1/32 of the way";
}

// The floor the cells decoder's limits (kMaxValuesPerByte) rest on: a bit never costs less than
// log2(2048/2017) = 0.022 bits, so a byte holds at most 364 decisions, however certain.
TEST(RangeCoder, ABitAlwaysCostsAtLeastTheProbabilityFloor) {
    for (const unsigned b : {0u, 1u}) {
        const std::vector<Symbol> symbols(1'000'000, Symbol{0, b, 1});
        const auto bytes = encode(symbols);
        const double per_byte = double(symbols.size()) / double(bytes.size());
        std::printf("%zu bits of %u: %zu bytes, %.0f decisions a byte\n", symbols.size(), b,
                    bytes.size(), per_byte);
        EXPECT_LE(per_byte, 364.0);
        EXPECT_GE(per_byte, 300.0) << "the probability saturates near its bound";
        EXPECT_TRUE(decodes(bytes, symbols));
    }
}

}  // namespace
}  // namespace isowall::remote
