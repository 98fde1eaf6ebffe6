#pragma once
// The built-in default volume: a deterministic synthetic "head" generated in memory, so the quick
// start and the tests need no file. Two nested surfaces give occlusion at both isovalues:
//   skin (iso 50): a bumpy ellipsoid of soft tissue (value 100);
//   bone (iso 160): a skull-like shell with three holes, and inside it a separate torus (220).
#include <glm/vec3.hpp>

#include "volume/volume.h"

namespace isowall {

struct PhantomSpec {
    glm::ivec3 dims{200, 184, 168};  // deliberately not powers of two
    glm::vec3 spacing{1.0f};
};

inline constexpr double kPhantomSkinIso = 50.0;
inline constexpr double kPhantomBoneIso = 160.0;

Volume make_phantom(const PhantomSpec& spec = {});

}  // namespace isowall
