#include "remote/net/token_bucket.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace isowall::remote {
namespace {

// Floating-point refills land a hair short of what a wait of exactly delay_s() should give; a
// shortfall this small (a millionth of a byte) counts as none, so the caller is never asked to
// wait for a gap the clock cannot represent, and the long-run rate is unchanged.
constexpr double kSlackBytes = 1e-6;

}  // namespace

TokenBucket::TokenBucket(double bits_per_second, std::size_t burst_bytes)
    : bytes_per_s_(bits_per_second / 8), burst_bytes_(burst_bytes) {
    if (!(bits_per_second > 0) || !std::isfinite(bits_per_second))
        throw std::invalid_argument("TokenBucket: rate must be positive and finite, got " +
                                    std::to_string(bits_per_second) + " bit/s");
    if (burst_bytes == 0) throw std::invalid_argument("TokenBucket: burst must be positive");
}

double TokenBucket::tokens(double now_s) const {
    if (!started_) return static_cast<double>(burst_bytes_);
    const double elapsed = std::max(0.0, now_s - last_s_);  // a clock never goes back
    return std::min(static_cast<double>(burst_bytes_), tokens_ + elapsed * bytes_per_s_);
}

double TokenBucket::delay_s(std::size_t bytes, double now_s) const {
    if (!limited()) return 0;
    const double need = static_cast<double>(std::min(bytes, burst_bytes_));
    const double short_by = need - tokens(now_s);
    return short_by > kSlackBytes ? short_by / bytes_per_s_ : 0;
}

void TokenBucket::take(std::size_t bytes, double now_s) {
    if (!limited()) return;
    tokens_ = tokens(now_s) - static_cast<double>(bytes);
    last_s_ = started_ ? std::max(last_s_, now_s) : now_s;
    started_ = true;
}

}  // namespace isowall::remote
