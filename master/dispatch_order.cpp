#include "master/dispatch_order.h"

#include <algorithm>

namespace isowall {

DispatchOrder::DispatchOrder(int ranks, Dispatch order)
    : order_(order),
      clock_(static_cast<std::size_t>(std::max(ranks, 0)), 0.0),
      busy_(clock_.size(), false) {}

void DispatchOrder::begin_frame() {
    std::fill(clock_.begin(), clock_.end(), 0.0);
    std::fill(busy_.begin(), busy_.end(), false);
    asking_.clear();
    holds_ = 0;
}

void DispatchOrder::clock(int rank, double seconds) {
    double& c = clock_.at(static_cast<std::size_t>(rank));
    c = std::max(c, seconds);
}

void DispatchOrder::ask(int rank) {
    busy_.at(static_cast<std::size_t>(rank)) = false;
    if (std::find(asking_.begin(), asking_.end(), rank) == asking_.end()) asking_.push_back(rank);
}

std::optional<int> DispatchOrder::next() {
    if (asking_.empty()) return std::nullopt;
    auto pick = asking_.begin();
    if (order_ == Dispatch::emulated) {
        // The earliest clock; among equal clocks, the first to ask.
        pick = std::min_element(asking_.begin(), asking_.end(),
                                [&](int a, int b) { return clock_of(a) < clock_of(b); });
        for (std::size_t r = 0; r < busy_.size(); ++r)
            if (busy_[r] && clock_[r] < clock_of(*pick)) {
                ++holds_;
                return std::nullopt;
            }
    }
    const int rank = *pick;
    asking_.erase(pick);
    return rank;
}

void DispatchOrder::served(int rank, bool busy) {
    busy_.at(static_cast<std::size_t>(rank)) = busy;
}

}  // namespace isowall
