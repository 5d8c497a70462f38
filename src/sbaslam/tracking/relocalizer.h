#pragma once
// Relocalisation after tracking loss: the frame's descriptors are matched against the map points
// of each candidate keyframe in turn (the tracker's: place recognition's, then the tracked map's
// most recent), a pose is found by PnP inside seeded RANSAC, refined by motion-only BA and
// confirmed by a projection search (ORB-SLAM's Relocalization).

#include <cstdint>
#include <functional>
#include <random>
#include <vector>

#include "sbaslam/map/keyframe.h"
#include "sbaslam/tracking/frame.h"

namespace sbaslam::tracking {

struct PnpRansacOptions {
  int iterations = 300;
  int min_inliers = 12;
  double chi2_threshold = 5.991;  // on the level-weighted squared reprojection error
};

struct PnpResult {
  bool success = false;
  SE3 T_cw;
  std::vector<char> inlier;
  int inliers = 0;
};

// Seeded RANSAC over minimal AP3P solutions, refined on all inliers. `levels` gives each
// observation's octave (for its sigma).
PnpResult solve_pnp_ransac(const std::vector<Vec3>& points_world, const std::vector<Vec2>& pixels,
                           const std::vector<int>& levels, const map::CameraRig& rig,
                           const PnpRansacOptions& options, std::mt19937_64& rng);

class Relocalizer {
 public:
  Relocalizer(const map::CameraRig& rig, std::uint64_t seed) : rig_(rig), rng_(seed) {}

  // Whether a pose found in a candidate keyframe may stand (the tracker's odometry check).
  using PoseCheck = std::function<bool(const SE3& T_cw)>;

  // Tries the candidates in order; on success the frame has its pose and matches. A pose that
  // `accept` refuses is counted in refused() and the next candidate is tried.
  bool relocalize(Frame& frame, const std::vector<map::KeyFrame*>& candidates,
                  const PoseCheck& accept = nullptr);
  int refused() const { return refused_; }

 private:
  bool try_keyframe(Frame& frame, map::KeyFrame& kf);

  const map::CameraRig& rig_;
  std::mt19937_64 rng_;
  int refused_ = 0;
};

}  // namespace sbaslam::tracking
