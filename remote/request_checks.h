#pragma once
// What `isowall serve` checks of a request before it casts a ray (issue "Nothing lies, nothing
// hangs", class 7): a request the server cannot draw gets an error naming the field instead of an
// empty frame. Pure functions of values, so a test builds any case in one line.
//
// The frustum is checked where the request is decoded (view_protocol.cpp: a WireError naming
// view.frustum.FIELD), as the camera is; the isovalue needs the dataset, so the server checks it
// against the volume's value range when the request arrives.
#include <string>

#include "core/camera.h"

namespace isowall::remote {

// Beyond this a float has lost the units a view is drawn in (the camera's limit too).
inline constexpr double kMaxFrustumReach = 1e9;
// The narrowest span (right - left, top - bottom, far_z - near_z) and the nearest perspective
// near_z: with every number within kMaxFrustumReach, the projection matrix stays finite.
inline constexpr double kMinFrustumSpan = 1e-9;

// Why `f` cannot be drawn, or empty. The text begins with the field ("right: expected more than
// left (1), got 1"). Rules: every number within kMaxFrustumReach of zero; left < right,
// bottom < top, near_z < far_z, each span at least kMinFrustumSpan; a perspective near_z of at
// least kMinFrustumSpan. A frustum that passes has a finite projection matrix and finite pixel
// rays (tests/remote_request_checks_test.cpp).
std::string frustum_problem(const Frustum& f);

// Why `iso` is not an isovalue of a volume whose values span [value_min, value_max], or empty:
// "expected a value in [0, 255] (the dataset's range), got 300".
std::string iso_problem(double iso, double value_min, double value_max);

}  // namespace isowall::remote
