#pragma once
// The 256 point pairs of the steered BRIEF test, and the circular patch used for the orientation.
//
// The pairs are our own: drawn once, from a fixed seed, from an isotropic Gaussian of
// sigma = patch_size / 5 (BRIEF's "G II" sampling) and kept inside a disc of radius 13 px, so a
// rotated pair never reaches further than 14 px from the keypoint. They are NOT ORB-SLAM's or
// OpenCV's learned pattern, so descriptors are not interchangeable with theirs (a vocabulary
// trained on ORB-SLAM's descriptors does not apply to ours).

#include <array>
#include <cstdint>

namespace sbaslam::feature {

struct PatternPoint {
  float x, y;
};

inline constexpr int kDescriptorBytes = 32;
inline constexpr int kDescriptorBits = 8 * kDescriptorBytes;
inline constexpr int kPatchSize = 31;
inline constexpr int kHalfPatch = 15;
inline constexpr int kPatternRadius = 13;

// Pairs (2 i, 2 i + 1) for bit i; bit i is set when I(first) < I(second).
const std::array<PatternPoint, 2 * kDescriptorBits>& brief_pattern();

// u_max[v] = largest |u| with (u, v) inside the circular orientation patch (radius 15). The disc is
// u^2 + v^2 <= 15^2 + 15, symmetric under transposition so that the centroid is rotation-fair.
const std::array<int, kHalfPatch + 1>& orientation_patch_umax();

}  // namespace sbaslam::feature
