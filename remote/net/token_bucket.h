#pragma once
// Bandwidth emulation: the dissertation measured its remote cases over an emulated link (1 Mbps),
// made by delaying the sender. A token bucket of bytes, refilled at the link's rate up to
// `burst_bytes`. Pure: the caller passes the time (seconds on any clock it keeps, never going
// back), so tests need no sleeping.
//
// A send of n bytes may go once the bucket holds min(n, burst) bytes; it then takes all n, so a
// message larger than the burst goes when the bucket is full and leaves it in debt, and the next
// one waits until the debt is paid. Whatever the sizes, bytes sent by time t never exceed
// burst + rate * t, and a sender that always waits as told sends at exactly the rate in the long
// run.
#include <cstddef>

namespace isowall::remote {

class TokenBucket {
  public:
    TokenBucket() = default;  // unlimited: never a delay
    // `bits_per_second` > 0 and finite, `burst_bytes` > 0 (std::invalid_argument otherwise). The
    // bucket starts full, at the time of the first call.
    TokenBucket(double bits_per_second, std::size_t burst_bytes);

    bool limited() const { return bytes_per_s_ > 0; }
    double bits_per_second() const { return bytes_per_s_ * 8; }
    std::size_t burst_bytes() const { return burst_bytes_; }

    // Seconds to wait from `now_s` before `bytes` may go: 0 when they may go now, never negative.
    double delay_s(std::size_t bytes, double now_s) const;
    // Spends `bytes` at `now_s` (whether or not they were due: the bucket may go into debt).
    void take(std::size_t bytes, double now_s);
    // Tokens (bytes) at `now_s`: at most the burst, negative while in debt.
    double tokens(double now_s) const;

  private:
    double bytes_per_s_ = 0;  // 0 = unlimited
    std::size_t burst_bytes_ = 0;
    double tokens_ = 0;
    double last_s_ = 0;
    bool started_ = false;  // false until the first take: the bucket is full
};

}  // namespace isowall::remote
