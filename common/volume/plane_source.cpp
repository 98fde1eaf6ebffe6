#include "common/volume/plane_source.h"

#include <cstring>
#include <stdexcept>

namespace isowall {

DecodedPlanes::DecodedPlanes(glm::ivec3 dims, VoxelType type, glm::vec3 spacing, std::string source,
                             Decode decode)
    : dims_(dims),
      type_(type),
      spacing_(spacing),
      source_(std::move(source)),
      decode_(std::move(decode)) {}

std::span<const std::byte> DecodedPlanes::planes(int z0, int z1) {
    if (z0 < z0_ || z0 > z1_ || z1 < z1_ || z1 > dims_.z)
        throw std::logic_error("DecodedPlanes: planes asked out of order");
    const std::size_t plane = plane_bytes();
    // The planes kept from the last call move to the front; the rest are decoded after them.
    const int kept = z1_ - z0;
    if (kept > 0 && z0 > z0_)
        std::memmove(buffer_.data(), buffer_.data() + std::size_t(z0 - z0_) * plane,
                     std::size_t(kept) * plane);
    const std::size_t need = std::size_t(z1 - z0) * plane;
    if (buffer_.size() < need) buffer_.resize(need);
    peak_ = std::max(peak_, buffer_.size());
    if (z1_ < z1) decode_(z1_, z1, buffer_.data() + std::size_t(z1_ - z0) * plane);
    z0_ = z0;
    z1_ = z1;
    return std::span<const std::byte>(buffer_).first(need);
}

}  // namespace isowall
