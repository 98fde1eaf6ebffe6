// The multiscale pyramid of a store (store/store_format.h): what each level holds, and
// levels that are damaged.
#include <gtest/gtest.h>

#include <fstream>
#include <iterator>

#include "core/error.h"
#include "store/store_reader.h"
#include "store/store_writer.h"
#include "tests/store_test_util.h"
#include "tests/test_util.h"

namespace isowall::store {
namespace {
namespace fs = std::filesystem;

using test::import_to;

std::string read_text(const fs::path& f) {
    std::ifstream in(f);
    return {std::istreambuf_iterator<char>(in), {}};
}

// The one line an InputError from `f` gives, or a failure.
std::string error_of(const std::function<void()>& f) {
    try {
        f();
    } catch (const InputError& e) {
        EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
        return e.what();
    }
    ADD_FAILURE() << "no error";
    return "";
}

TEST(StoreLevels, EachLevelHoldsEveryOtherVoxelOfTheOneBelow) {
    // 300x260x200 in bricks of 32: sides 300, 150, 75, 38, 19: five levels, the last one brick.
    const Volume v = test::pattern_volume({300, 260, 200});
    const fs::path store = import_to(v, "store_levels");
    const StoreReader r(store);
    const StoreLayout& l = r.layout();
    ASSERT_EQ(l.levels, 5);
    EXPECT_EQ(l.level(4).dims, glm::ivec3(19, 17, 13));
    EXPECT_EQ(l.level(4).grid(), glm::ivec3(1));
    EXPECT_EQ(l.level(2).spacing, v.spacing() * 4.0f);
    const auto src = v.view<std::uint16_t>();
    std::vector<std::byte> brick(l.brick_bytes());
    for (int k = 1; k < l.levels; ++k) {
        const StoreLayout lk = l.level(k);
        std::size_t bad = 0, padding = 0;
        for (std::size_t i = 0; i < lk.chunk_count(); ++i) {
            const glm::ivec3 b = lk.brick_at(i);
            r.read_chunk(b, brick, k);
            const auto* p = reinterpret_cast<const std::uint16_t*>(brick.data());
            const int s = l.brick();
            for (int z = 0; z < s; ++z)
                for (int y = 0; y < s; ++y)
                    for (int x = 0; x < s; ++x) {
                        const glm::ivec3 at = b * s + glm::ivec3(x, y, z);
                        const std::uint16_t got = p[(std::size_t(z) * s + y) * s + x];
                        if (glm::any(glm::greaterThanEqual(at, lk.dims)))
                            padding += got != 0;  // Zarr's padding past the edge: zeros
                        else
                            bad += got != src.at(at.x << k, at.y << k, at.z << k);
                    }
        }
        EXPECT_EQ(bad, 0u) << "level " << k;
        EXPECT_EQ(padding, 0u) << "level " << k;
    }
    // --levels 1: level 0 alone.
    const fs::path flat = import_to(v, "store_levels_flat", 1);
    EXPECT_EQ(StoreReader(flat).layout().levels, 1);
    EXPECT_FALSE(fs::exists(flat / "1"));
}

TEST(StoreLevels, AMissingOrMisshapenLevelIsRefusedNamingIt) {
    const fs::path store = import_to(test::pattern_volume({70, 130, 40}), "store_levels_bad");
    ASSERT_EQ(StoreReader(store).layout().levels, 4);  // sides 130, 65, 33, 17
    {
        const std::string key = chunk_key({1, 0, 0}, 1);
        fs::rename(store / key, store / (key + ".away"));
        const std::string e = error_of([&] { StoreReader r(store); });
        EXPECT_NE(e.find(key), std::string::npos) << e;
        EXPECT_NE(e.find("missing"), std::string::npos) << e;
        fs::rename(store / (key + ".away"), store / key);
    }
    {
        const fs::path za = store / "2" / ".zarray";
        const std::string good = read_text(za);
        std::string bad = good;
        const auto at = bad.find("33");  // the shape's y: 130 -> 65 -> 33
        ASSERT_NE(at, std::string::npos) << bad;
        bad.replace(at, 2, "34");
        std::ofstream(za) << bad;
        const std::string e = error_of([&] { StoreReader r(store); });
        EXPECT_NE(e.find("2/.zarray: shape"), std::string::npos) << e;
        std::ofstream(za) << good;
    }
    {
        const fs::path at = store / ".zattrs";
        std::string attrs = read_text(at);
        const auto i = attrs.find("\"levels\": 4");
        ASSERT_NE(i, std::string::npos) << attrs;
        attrs.replace(i, 11, "\"levels\": 9");
        std::ofstream(at) << attrs;
        const std::string e = error_of([&] { StoreReader r(store); });
        EXPECT_NE(e.find("isowall.levels"), std::string::npos) << e;
    }
}

}  // namespace
}  // namespace isowall::store
