// The pure parts of remote/net/: the emulated link's token bucket (delays, burst, debt, the
// long-run rate) on a clock the test keeps, HOST:PORT endpoints, good and bad, and which
// addresses and listen names reach this machine only.
#include <gtest/gtest.h>

#include <arpa/inet.h>
#include <netinet/in.h>

#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/error.h"
#include "remote/net/endpoint.h"
#include "remote/net/token_bucket.h"

namespace isowall::remote {
namespace {

TEST(TokenBucket, UnlimitedNeverWaits) {
    TokenBucket b;
    EXPECT_FALSE(b.limited());
    b.take(std::size_t{1} << 30, 0);
    EXPECT_EQ(b.delay_s(std::size_t{1} << 30, 0), 0);
}

TEST(TokenBucket, RejectsABadRateOrBurst) {
    for (const double rate : {0.0, -1.0, std::numeric_limits<double>::infinity(),
                              std::numeric_limits<double>::quiet_NaN()})
        EXPECT_THROW(TokenBucket(rate, 1000), std::invalid_argument) << rate;
    EXPECT_THROW(TokenBucket(8000, 0), std::invalid_argument);
}

TEST(TokenBucket, StartsFullThenRefillsAtTheRate) {
    TokenBucket b(8000, 1000);  // 1000 bytes/s
    EXPECT_TRUE(b.limited());
    EXPECT_EQ(b.delay_s(1000, 5), 0) << "full at the first call, whenever it comes";
    b.take(1000, 5);
    EXPECT_DOUBLE_EQ(b.delay_s(500, 5), 0.5);
    EXPECT_DOUBLE_EQ(b.delay_s(500, 5.25), 0.25);
    EXPECT_EQ(b.delay_s(500, 5.5), 0);
    EXPECT_DOUBLE_EQ(b.tokens(100), 1000) << "refills no further than the burst";
}

TEST(TokenBucket, ALargeMessageGoesWhenFullAndLeavesDebt) {
    TokenBucket b(8000, 1000);
    EXPECT_EQ(b.delay_s(5000, 0), 0) << "larger than the burst: goes once the bucket is full";
    b.take(5000, 0);
    EXPECT_DOUBLE_EQ(b.tokens(0), -4000);
    EXPECT_DOUBLE_EQ(b.delay_s(1, 0), 4.001) << "the debt is paid before the next byte";
    EXPECT_DOUBLE_EQ(b.delay_s(5000, 0), 5) << "and the next large one waits for a full bucket";
}

TEST(TokenBucket, ClockGoingBackCountsAsNoTime) {
    TokenBucket b(8000, 1000);
    b.take(1000, 10);
    EXPECT_DOUBLE_EQ(b.delay_s(1000, 9), 1);
}

// Sends `sizes` as fast as the bucket lets them, returning the time of the last send; checks on
// the way that bytes sent by each time stay within burst + rate * time (when no message is
// larger than the burst).
double send_all_paced(TokenBucket& b, const std::vector<std::size_t>& sizes, bool check_bound) {
    double now = 0, sent = 0;
    const double bytes_per_s = b.bits_per_second() / 8;
    for (const std::size_t n : sizes) {
        const double wait = b.delay_s(n, now);
        EXPECT_GE(wait, 0);
        now += wait;
        EXPECT_EQ(b.delay_s(n, now), 0) << "waiting as told is enough, at t=" << now;
        b.take(n, now);
        sent += static_cast<double>(n);
        if (check_bound) {
            EXPECT_LE(sent, static_cast<double>(b.burst_bytes()) + bytes_per_s * now + 1e-3)
                << "t=" << now;
        }
    }
    return now;
}

TEST(TokenBucket, LongRunRateIsExact) {
    std::mt19937 rng(12);
    for (const std::size_t max_message :
         {std::size_t{1000}, std::size_t{16384}, std::size_t{200000}}) {
        std::uniform_int_distribution<std::size_t> size(1, max_message);
        std::vector<std::size_t> sizes(4000);
        double total = 0;
        for (std::size_t& n : sizes) total += static_cast<double>(n = size(rng));
        const double rate_bits = 1e6;
        TokenBucket b(rate_bits, 16384);
        const double end_s = send_all_paced(b, sizes, max_message <= 16384);
        // The first burst goes free, the last message is paid for after it went: both are small
        // against the total, so the measured rate is within 1% of the link's.
        const double measured_bits = total * 8 / end_s;
        EXPECT_NEAR(measured_bits / rate_bits, 1.0, 0.01)
            << "max message " << max_message << ": " << measured_bits << " bit/s";
    }
}

TEST(Endpoint, ParsesHostAndPort) {
    struct Case {
        const char* text;
        const char* host;
        int port;
    };
    for (const Case& c :
         {Case{"127.0.0.1:5000", "127.0.0.1", 5000}, Case{"localhost:1", "localhost", 1},
          Case{"[::1]:65535", "::1", 65535}, Case{"viz.example.org:8080", "viz.example.org", 8080},
          Case{"[fe80::1%eth0]:5000", "fe80::1%eth0", 5000}}) {
        const Endpoint e = parse_endpoint(c.text, "--connect", "endpoint");
        EXPECT_EQ(e.host, c.host) << c.text;
        EXPECT_EQ(e.port, c.port) << c.text;
        EXPECT_EQ(to_string(e), c.text) << "to_string writes what parse_endpoint reads";
    }
}

TEST(Endpoint, EachBadOneNamesSourceAndField) {
    for (const char* text :
         {"",          "127.0.0.1", "127.0.0.1:", ":5000",      "::1:5000",    "[::1]5000",
          "[::1:5000", "[]:5000",   "host:0",     "host:65536", "host:123456", "host:-1",
          "host:+5",   "host:5 ",   "host: 5",    "host:abc",   "ho st:5",     "host\n:5",
          "a/b:5",     "[::1]:",    "host:0x10"}) {
        try {
            parse_endpoint(text, "--connect", "endpoint");
            ADD_FAILURE() << "accepted \"" << text << "\"";
        } catch (const InputError& e) {
            const std::string what = e.what();
            EXPECT_EQ(what.rfind("--connect: endpoint: ", 0), 0u) << what;
            EXPECT_EQ(what.find('\n'), std::string::npos) << what;
        }
    }
    const std::string long_host(300, 'a');
    EXPECT_THROW(parse_endpoint(long_host + ":5", "view", "server"), InputError);
}

TEST(Endpoint, ErrorSaysWhatWasWrong) {
    const auto message = [](const char* text) {
        try {
            parse_endpoint(text, "view", "server");
        } catch (const InputError& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    EXPECT_NE(message("h:70000").find("port: expected an integer 1..65535, got \"70000\""),
              std::string::npos)
        << message("h:70000");
    EXPECT_NE(message("::1:5").find("brackets"), std::string::npos) << message("::1:5");
    EXPECT_NE(message("nohost").find("expected HOST:PORT"), std::string::npos) << message("nohost");
}

sockaddr_storage address(const char* text) {
    sockaddr_storage s{};
    if (auto* v4 = reinterpret_cast<sockaddr_in*>(&s);
        ::inet_pton(AF_INET, text, &v4->sin_addr) == 1) {
        v4->sin_family = AF_INET;
        return s;
    }
    auto* v6 = reinterpret_cast<sockaddr_in6*>(&s);
    EXPECT_EQ(::inet_pton(AF_INET6, text, &v6->sin6_addr), 1) << text;
    v6->sin6_family = AF_INET6;
    return s;
}

TEST(Loopback, AnAddressIsLoopbackBy127Slash8OrIpv6sOwn) {
    for (const char* yes : {"127.0.0.1", "127.255.3.4", "::1", "::ffff:127.0.0.1"})
        EXPECT_TRUE(is_loopback_address(address(yes))) << yes;
    for (const char* no : {"0.0.0.0", "10.0.0.1", "128.0.0.1", "::", "::ffff:10.0.0.1", "fe80::1"})
        EXPECT_FALSE(is_loopback_address(address(no))) << no;
    EXPECT_FALSE(is_loopback_address(sockaddr_storage{}));  // no family
}

// The gate decides on what a name resolves to, never on its spelling: a name that starts with
// "127." or "localhost" may resolve anywhere (scripts/loopback_gate_test.sh maps one to
// 0.0.0.0), and one that resolves to nothing is not loopback either.
TEST(Loopback, AListenNameIsLoopbackOnlyWhenEveryAddressItResolvesToIs) {
    for (const char* yes : {"127.0.0.1", "127.1.2.3", "::1", "localhost"})
        EXPECT_TRUE(listens_on_loopback_only(yes)) << yes;
    for (const char* no : {"0.0.0.0", "::", "", "127.example.invalid", "localhost.invalid"})
        EXPECT_FALSE(listens_on_loopback_only(no)) << no;
}

}  // namespace
}  // namespace isowall::remote
