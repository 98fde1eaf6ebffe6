#include "volume/plane_source.h"

#include <cstring>
#include <exception>
#include <stdexcept>
#include <utility>

namespace isowall {

DecodedPlanes::DecodedPlanes(glm::ivec3 dims, VoxelType type, glm::vec3 spacing, std::string source,
                             Decode decode, bool read_ahead)
    : dims_(dims),
      type_(type),
      spacing_(spacing),
      source_(std::move(source)),
      decode_(std::move(decode)),
      read_ahead_(read_ahead) {}

DecodedPlanes::~DecodedPlanes() {
    if (!ahead_.joinable()) return;
    if (cancel_ && have_ < dims_.z) cancel_();
    ahead_.join();
}

void DecodedPlanes::finish_ahead() {
    if (!ahead_.joinable()) return;
    ahead_.join();
    if (ahead_error_) std::rethrow_exception(std::exchange(ahead_error_, nullptr));
    have_ = ahead_end_;
}

std::span<const std::byte> DecodedPlanes::planes(int z0, int z1) {
    if (z0 < z0_ || z0 > z1_ || z1 < z1_ || z1 > dims_.z)
        throw std::logic_error("DecodedPlanes: planes asked out of order");
    finish_ahead();
    const std::size_t plane = plane_bytes();
    // The planes decoded from z0 on move to the front; the rest of [z0, z1) is decoded after them.
    if (z0 > z0_ && have_ > z0)
        std::memmove(buffer_.data(), buffer_.data() + std::size_t(z0 - z0_) * plane,
                     std::size_t(have_ - z0) * plane);
    have_ = std::max(have_, z0);
    z0_ = z0;
    z1_ = z1;
    // Room for this call's planes and, reading ahead, as many more after them.
    const int target = read_ahead_ ? std::min(z1 + (z1 - z0), dims_.z) : z1;
    const int more = std::max(0, target - std::max(have_, z1));
    const std::size_t room = std::size_t(std::max(have_, z1) - z0 + more) * plane;
    if (buffer_.size() < room) buffer_.resize(room);
    peak_ = std::max(peak_, buffer_.size());
    if (have_ < z1) decode_(have_, z1, buffer_.data() + std::size_t(have_ - z0) * plane);
    have_ = std::max(have_, z1);
    if (more > 0) {
        // The next planes are decoded while the caller works on these (another slice of the
        // buffer: the span handed out is not written).
        ahead_end_ = have_ + more;
        std::byte* to = buffer_.data() + std::size_t(have_ - z0) * plane;
        ahead_ = std::thread([this, from = have_, end = ahead_end_, to] {
            try {
                decode_(from, end, to);
            } catch (...) {
                ahead_error_ = std::current_exception();
            }
        });
    }
    return std::span<const std::byte>(buffer_).first(std::size_t(z1 - z0) * plane);
}

}  // namespace isowall
