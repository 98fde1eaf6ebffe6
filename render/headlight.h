#pragma once
// The headlight's shading in C++, for code that predicts a picture's colours without drawing it
// (the remote server's choice of levels of detail, remote/lod_choice.h). It computes what the
// fragment shader (render/shaders/headlight.frag) draws: tests/renderer_test.cpp draws faces at
// several angles, front and back, and compares the pixels with colour().
// Headlight Phong: the light sits at the eye, so the light and view directions coincide and the
// half vector is the light direction. A back face (seen through a hole in an open surface) gets
// its normal flipped and a cooler colour.
#include <cmath>

#include <glm/vec3.hpp>

namespace isowall::headlight {

inline constexpr glm::vec3 kFrontColour{0.9f, 0.85f, 0.75f};
inline constexpr glm::vec3 kBackColour{0.6f, 0.68f, 0.85f};
inline constexpr float kAmbient = 0.08f;
inline constexpr float kDiffuse = 0.85f;
inline constexpr float kSpecular = 0.25f;
inline constexpr float kShininess = 40.0f;

// The colour (before clamping to [0,1]) of a surface whose unit normal meets the unit direction
// to the eye with this cosine: a front face where it is positive (its normal points to the eye,
// as the surface's normals do on its front: marching_cubes.h), else a back face, whose flipped
// normal meets the eye with the cosine's magnitude.
inline glm::vec3 colour(float normal_dot_to_eye) {
    const float lambert = std::abs(normal_dot_to_eye);
    const float highlight = kSpecular * std::pow(lambert, kShininess);
    const glm::vec3 base = normal_dot_to_eye >= 0 ? kFrontColour : kBackColour;
    return base * (kAmbient + kDiffuse * lambert) + glm::vec3(highlight);
}

}  // namespace isowall::headlight
