#include "sbaslam/mapping/triangulation.h"

#include <Eigen/SVD>
#include <algorithm>
#include <climits>
#include <cmath>

#include "sbaslam/match/hamming.h"
#include "sbaslam/match/orb_matcher.h"

namespace sbaslam::mapping {
namespace {

// Fundamental matrix mapping kf1 pixels to epipolar lines in kf2 (undistorted pixels).
Mat3 fundamental_21(const map::KeyFrame& kf1, const map::KeyFrame& kf2) {
  const SE3 T_21 = kf2.T_cw() * kf1.T_wc();
  const Mat3 E = hat(T_21.translation()) * T_21.rotation();
  const PinholeIntrinsics& k = kf1.rig().camera.intrinsics();
  Mat3 K;
  K << k.fx, 0.0, k.cx, 0.0, k.fy, k.cy, 0.0, 0.0, 1.0;
  const Mat3 K_inv = K.inverse();
  return K_inv.transpose() * E * K_inv;
}

struct Candidate {
  std::size_t index;
  float x, y;
  int octave;
};

std::vector<Candidate> unmatched_keypoints(const map::KeyFrame& kf) {
  std::vector<Candidate> out;
  const map::Measurements& m = kf.measurements();
  for (std::size_t i = 0; i < kf.keypoint_count(); ++i) {
    const map::MapPoint* mp = kf.map_point(i);
    if (mp && !mp->is_bad()) continue;
    out.push_back({i, m.keypoints_un[i].x, m.keypoints_un[i].y, m.keypoints_un[i].octave});
  }
  return out;
}

// kf2's candidates bucketed in square cells, so that the keypoints near an epipolar line are found
// by walking the cells the line crosses instead of testing every keypoint.
class EpipolarGrid {
 public:
  EpipolarGrid(const std::vector<Candidate>& candidates, const feature::ScaleLevels& levels) {
    // The widest band a keypoint may be matched in: 1.96 sigma at the top pyramid level.
    band_ = std::sqrt(3.84 * levels.sigma2.back());
    for (const Candidate& c : candidates) {
      width_ = std::max(width_, cell_of(c.x) + 1);
      height_ = std::max(height_, cell_of(c.y) + 1);
    }
    cells_.resize(static_cast<std::size_t>(width_ * height_));
    for (std::size_t i = 0; i < candidates.size(); ++i)
      cells_[index(cell_of(candidates[i].x), cell_of(candidates[i].y))].push_back(i);
  }

  // Calls visit(i) for the candidates in the cells within the widest band of the line l
  // (l . (x, y, 1) = 0), in no particular order.
  template <typename Visit>
  void for_each_near(const Vec3& l, Visit&& visit) const {
    const double norm = std::hypot(l.x(), l.y());
    const bool along_x = std::abs(l.y()) >= std::abs(l.x());
    // Walk the cells across the line's main direction; in each, the band spans this range.
    const double a = along_x ? l.x() : l.y(), b = along_x ? l.y() : l.x();
    const double spread = band_ * norm / std::abs(b);
    const int steps = along_x ? width_ : height_, span = along_x ? height_ : width_;
    for (int i = 0; i < steps; ++i) {
      const double t0 = i * kCell, t1 = (i + 1) * kCell;
      const double s0 = -(a * t0 + l.z()) / b, s1 = -(a * t1 + l.z()) / b;
      const int lo = std::max(0, cell_of(std::min(s0, s1) - spread));
      const int hi = std::min(span - 1, cell_of(std::max(s0, s1) + spread));
      for (int j = lo; j <= hi; ++j)
        for (std::size_t c : along_x ? cells_[index(i, j)] : cells_[index(j, i)]) visit(c);
    }
  }

 private:
  static constexpr double kCell = 32.0;
  static int cell_of(double v) {
    return static_cast<int>(std::clamp(std::floor(v / kCell), -1.0, 1e6));
  }
  std::size_t index(int x, int y) const {
    return static_cast<std::size_t>(std::max(0, y) * width_ + std::max(0, x));
  }

  double band_ = 0.0;
  int width_ = 1, height_ = 1;
  std::vector<std::vector<std::size_t>> cells_;
};

bool reprojects_well(const map::KeyFrame& kf, std::size_t i, const Vec3& p_world) {
  const Vec3 p = kf.T_cw() * p_world;
  if (p.z() <= 0.0) return false;
  const map::CameraRig& rig = kf.rig();
  const map::Measurements& m = kf.measurements();
  const Vec2 uv = rig.camera.project(p);
  const feature::OrbKeypoint& kp = m.keypoints_un[i];
  const double inv_sigma2 = rig.levels.inv_sigma2[static_cast<std::size_t>(kp.octave)];
  double e2 = (uv - Vec2(kp.x, kp.y)).squaredNorm();
  if (m.u_right[i] < 0.0f) return e2 * inv_sigma2 <= 5.991;
  const double ur = uv.x() - rig.bf / p.z();
  e2 += (ur - m.u_right[i]) * (ur - m.u_right[i]);
  return e2 * inv_sigma2 <= 7.8;
}

// cos of the parallax that a stereo keypoint's own baseline gives (2: no stereo).
double stereo_parallax_cos(const map::KeyFrame& kf, std::size_t i) {
  const float z = kf.measurements().depth[i];
  if (z <= 0.0f) return 2.0;
  return std::cos(2.0 * std::atan2(kf.rig().baseline() / 2.0, static_cast<double>(z)));
}

}  // namespace

std::vector<KeypointPair> match_for_triangulation(const map::KeyFrame& kf1,
                                                  const map::KeyFrame& kf2) {
  const Mat3 F21 = fundamental_21(kf1, kf2);
  const std::vector<Candidate> first = unmatched_keypoints(kf1);
  const std::vector<Candidate> second = unmatched_keypoints(kf2);
  const map::Measurements& m1 = kf1.measurements();
  const map::Measurements& m2 = kf2.measurements();
  const feature::ScaleLevels& levels = kf2.rig().levels;

  // kf1's centre in kf2: monocular pairs too close to this epipole are ambiguous.
  const Vec3 epipole_c = kf2.T_cw() * kf1.camera_center();
  const Vec2 epipole = kf2.rig().camera.project(epipole_c);
  const bool epipole_valid = epipole_c.z() > 0.0;

  const EpipolarGrid grid(second, levels);

  std::vector<match::Match> candidates;
  for (std::size_t a = 0; a < first.size(); ++a) {
    const Candidate& c1 = first[a];
    const Vec3 line = F21 * Vec3(c1.x, c1.y, 1.0);
    const double norm2 = line.x() * line.x() + line.y() * line.y();
    if (norm2 <= 0.0) continue;
    const bool stereo1 = m1.u_right[c1.index] >= 0.0f;
    const std::uint8_t* d1 = m1.descriptor(c1.index);
    int best = -1, best_distance = match::kThresholdLow + 1;
    grid.for_each_near(line, [&](std::size_t b) {
      const Candidate& c2 = second[b];
      const double num = line.x() * c2.x + line.y() * c2.y + line.z();
      if (num * num / norm2 >= 3.84 * levels.sigma2[static_cast<std::size_t>(c2.octave)]) return;
      const bool stereo2 = m2.u_right[c2.index] >= 0.0f;
      if (!stereo1 && !stereo2 && epipole_valid) {
        const double ex = epipole.x() - c2.x, ey = epipole.y() - c2.y;
        if (ex * ex + ey * ey < 100.0 * levels.scale[static_cast<std::size_t>(c2.octave)]) return;
      }
      // Ties go to the lower index, as in a scan in index order: the cells come in any order.
      const int d = match::descriptor_distance(d1, m2.descriptor(c2.index));
      if (d < best_distance || (d == best_distance && static_cast<int>(b) < best)) {
        best_distance = d;
        best = static_cast<int>(b);
      }
    });
    if (best >= 0) candidates.push_back({static_cast<int>(a), best, best_distance});
  }

  // One pair per kf2 keypoint (closest descriptor wins), then the rotation check.
  std::vector<int> owner(second.size(), -1);
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    int& o = owner[static_cast<std::size_t>(candidates[i].train)];
    if (o < 0 || candidates[i].distance < candidates[static_cast<std::size_t>(o)].distance)
      o = static_cast<int>(i);
  }
  match::RotationConsistency rotation;
  std::vector<KeypointPair> pairs;
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    if (owner[static_cast<std::size_t>(candidates[i].train)] != static_cast<int>(i)) continue;
    const KeypointPair pair{first[static_cast<std::size_t>(candidates[i].query)].index,
                            second[static_cast<std::size_t>(candidates[i].train)].index};
    rotation.add(static_cast<int>(pairs.size()), m1.keypoints_un[pair.first].angle,
                 m2.keypoints_un[pair.second].angle);
    pairs.push_back(pair);
  }
  std::vector<KeypointPair> kept;
  const std::vector<int> rejected = rotation.inconsistent();
  for (std::size_t i = 0; i < pairs.size(); ++i)
    if (!std::binary_search(rejected.begin(), rejected.end(), static_cast<int>(i)))
      kept.push_back(pairs[i]);
  return kept;
}

std::optional<Vec3> triangulate_dlt(const Vec2& xn1, const Vec2& xn2, const SE3& T_c1w,
                                    const SE3& T_c2w) {
  const Mat34 P1 = T_c1w.matrix3x4();
  const Mat34 P2 = T_c2w.matrix3x4();
  Eigen::Matrix4d A;
  A.row(0) = xn1.x() * P1.row(2) - P1.row(0);
  A.row(1) = xn1.y() * P1.row(2) - P1.row(1);
  A.row(2) = xn2.x() * P2.row(2) - P2.row(0);
  A.row(3) = xn2.y() * P2.row(2) - P2.row(1);
  const Eigen::JacobiSVD<Eigen::Matrix4d> svd(A, Eigen::ComputeFullV);
  const Vec4 h = svd.matrixV().col(3);
  if (std::abs(h(3)) < 1e-12) return std::nullopt;
  return Vec3(h.head<3>() / h(3));
}

std::vector<map::MapPoint*> create_new_map_points(
    map::Map& map, map::KeyFrame* kf, int neighbours, double min_parallax_cos,
    const std::function<void()>& after_each_neighbour) {
  std::vector<map::MapPoint*> created;
  const map::CameraRig& rig = kf->rig();
  const double ratio_factor = 1.5 * rig.levels.scale[1];
  for (map::KeyFrame* kf2 : kf->best_covisibles(static_cast<std::size_t>(neighbours))) {
    after_each_neighbour();
    if (kf2->is_bad()) continue;
    const double baseline = (kf2->camera_center() - kf->camera_center()).norm();
    if (rig.stereo) {
      if (baseline < rig.baseline()) continue;
    } else {
      const double median_depth = kf2->scene_depth_quantile(0.5);
      if (median_depth <= 0.0 || baseline / median_depth < 0.01) continue;
    }
    for (const KeypointPair& pair : match_for_triangulation(*kf, *kf2)) {
      const feature::OrbKeypoint& kp1 = kf->measurements().keypoints_un[pair.first];
      const feature::OrbKeypoint& kp2 = kf2->measurements().keypoints_un[pair.second];
      const Vec2 xn1 = rig.camera.normalized(Vec2(kp1.x, kp1.y));
      const Vec2 xn2 = rig.camera.normalized(Vec2(kp2.x, kp2.y));
      const Vec3 ray1 = kf->T_wc().so3() * xn1.homogeneous();
      const Vec3 ray2 = kf2->T_wc().so3() * xn2.homogeneous();
      const double cos_rays = ray1.dot(ray2) / (ray1.norm() * ray2.norm());
      const double cos_stereo1 = stereo_parallax_cos(*kf, pair.first);
      const double cos_stereo2 = stereo_parallax_cos(*kf2, pair.second);
      const double cos_stereo = std::min(cos_stereo1, cos_stereo2);

      std::optional<Vec3> p;
      if (cos_rays < cos_stereo && cos_rays > 0.0 &&
          (cos_stereo1 < 2.0 || cos_stereo2 < 2.0 || cos_rays < min_parallax_cos)) {
        p = triangulate_dlt(xn1, xn2, kf->T_cw(), kf2->T_cw());
      } else if (cos_stereo1 < cos_stereo2) {
        p = kf->unproject_stereo(pair.first);
      } else if (cos_stereo2 < cos_stereo1) {
        p = kf2->unproject_stereo(pair.second);
      }
      if (!p || !p->allFinite()) continue;
      if (!reprojects_well(*kf, pair.first, *p) || !reprojects_well(*kf2, pair.second, *p))
        continue;
      const double dist1 = (*p - kf->camera_center()).norm();
      const double dist2 = (*p - kf2->camera_center()).norm();
      if (dist1 == 0.0 || dist2 == 0.0) continue;
      const double ratio_dist = dist2 / dist1;
      const double ratio_octave = rig.levels.scale[static_cast<std::size_t>(kp1.octave)] /
                                  rig.levels.scale[static_cast<std::size_t>(kp2.octave)];
      if (ratio_dist * ratio_factor < ratio_octave || ratio_dist > ratio_octave * ratio_factor)
        continue;

      map::MapPoint* mp = map.create_map_point(*p, kf);
      mp->add_observation(kf, pair.first);
      mp->add_observation(kf2, pair.second);
      kf->add_map_point(mp, pair.first);
      kf2->add_map_point(mp, pair.second);
      mp->update_descriptor();
      mp->update_normal_and_depth();
      created.push_back(mp);
    }
  }
  return created;
}

}  // namespace sbaslam::mapping
