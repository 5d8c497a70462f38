#include "sbaslam/loop/sim3_solver.h"

#include <Eigen/SVD>
#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <random>

#include "sbaslam/core/error.h"

namespace sbaslam::loop {
namespace {

// Second singular value of the cross-covariance relative to the first below which the points are
// taken as collinear: the rotation about their line is then undetermined.
constexpr double kMinSingularRatio = 1e-10;

// Umeyama's least-squares similarity, or nothing for degenerate points.
std::optional<Sim3> try_align(const std::vector<Vec3>& p1, const std::vector<Vec3>& p2,
                              bool fix_scale) {
  const double n = static_cast<double>(p1.size());
  Vec3 mean1 = Vec3::Zero(), mean2 = Vec3::Zero();
  for (std::size_t i = 0; i < p1.size(); ++i) {
    mean1 += p1[i];
    mean2 += p2[i];
  }
  mean1 /= n;
  mean2 /= n;
  Mat3 covariance = Mat3::Zero();
  double variance2 = 0.0;
  for (std::size_t i = 0; i < p1.size(); ++i) {
    const Vec3 d2 = p2[i] - mean2;
    covariance += (p1[i] - mean1) * d2.transpose();
    variance2 += d2.squaredNorm();
  }
  covariance /= n;
  variance2 /= n;
  const Eigen::JacobiSVD<Mat3> svd(covariance, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Vec3 d = svd.singularValues();
  if (!(d(0) > 0.0) || d(1) <= kMinSingularRatio * d(0) || !(variance2 > 0.0)) return std::nullopt;
  // A reflection is replaced by the nearest rotation, flipping the weakest axis (Umeyama's S).
  Vec3 signs(1.0, 1.0, 1.0);
  if (svd.matrixU().determinant() * svd.matrixV().determinant() < 0.0) signs(2) = -1.0;
  const Mat3 R = svd.matrixU() * signs.asDiagonal() * svd.matrixV().transpose();
  const double scale = fix_scale ? 1.0 : d.dot(signs) / variance2;
  return Sim3(scale, SO3::from_matrix(R), mean1 - scale * (R * mean2));
}

// The reprojection test of a hypothesis, with each correspondence's gates precomputed.
class HypothesisScorer {
 public:
  HypothesisScorer(const std::vector<Sim3Correspondence>& c, const PinholeCamera& camera1,
                   const PinholeCamera& camera2, double chi2)
      : c_(c), camera1_(camera1), camera2_(camera2) {
    for (const Sim3Correspondence& pair : c) {
      max_error1_.push_back(chi2 * pair.sigma2_1);
      max_error2_.push_back(chi2 * pair.sigma2_2);
    }
  }

  // Flags the correspondences that S12 explains in both images; returns their count.
  int score(const Sim3& S12, std::vector<char>& inliers) const {
    const Sim3 S21 = S12.inverse();
    int count = 0;
    for (std::size_t i = 0; i < c_.size(); ++i) {
      inliers[i] = fits(camera1_, S12 * c_[i].p2_c, c_[i].uv1, max_error1_[i]) &&
                   fits(camera2_, S21 * c_[i].p1_c, c_[i].uv2, max_error2_[i]);
      count += inliers[i];
    }
    return count;
  }

 private:
  static bool fits(const PinholeCamera& camera, const Vec3& p_c, const Vec2& uv, double gate) {
    return p_c.z() > 0.0 && (camera.project(p_c) - uv).squaredNorm() < gate;
  }

  const std::vector<Sim3Correspondence>& c_;
  const PinholeCamera& camera1_;
  const PinholeCamera& camera2_;
  std::vector<double> max_error1_, max_error2_;
};

// Samples needed to draw one all-inlier triple with the given probability.
int required_iterations(double inlier_ratio, const Sim3RansacOptions& options) {
  const double all_inliers = inlier_ratio * inlier_ratio * inlier_ratio;
  if (all_inliers >= 1.0) return 1;
  const double n = std::ceil(std::log(1.0 - options.probability) / std::log(1.0 - all_inliers));
  return static_cast<int>(std::clamp(n, 1.0, static_cast<double>(options.max_iterations)));
}

// Written out rather than std::uniform_int_distribution, whose output the standard leaves to
// the library: the same seed then gives the same samples everywhere.
std::array<std::size_t, 3> draw_triple(std::mt19937_64& rng, std::size_t n) {
  std::array<std::size_t, 3> sample{};
  for (std::size_t k = 0; k < 3; ++k) {
    do {
      sample[k] = static_cast<std::size_t>(static_cast<double>(rng() >> 11) * 0x1.0p-53 *
                                           static_cast<double>(n));
    } while ((k > 0 && sample[k] == sample[0]) || (k > 1 && sample[k] == sample[1]));
  }
  return sample;
}

void validate(const Sim3RansacOptions& options) {
  if (!(options.probability > 0.0 && options.probability < 1.0))
    fail("Sim3 RANSAC: probability must be in (0, 1), got {}", options.probability);
  if (options.min_inliers < 3)
    fail("Sim3 RANSAC: min_inliers must be >= 3, got {}", options.min_inliers);
  if (options.max_iterations < 1)
    fail("Sim3 RANSAC: max_iterations must be >= 1, got {}", options.max_iterations);
  if (!(options.chi2 > 0.0)) fail("Sim3 RANSAC: chi2 must be positive, got {}", options.chi2);
}

// Refits the hypothesis on all its inliers; keeps the refit unless it explains fewer pairs.
void refit(const std::vector<Sim3Correspondence>& c, const HypothesisScorer& scorer, bool fix_scale,
           Sim3RansacResult& result) {
  std::vector<Vec3> p1, p2;
  for (std::size_t i = 0; i < c.size(); ++i) {
    if (!result.inliers[i]) continue;
    p1.push_back(c[i].p1_c);
    p2.push_back(c[i].p2_c);
  }
  const std::optional<Sim3> S12 = try_align(p1, p2, fix_scale);
  if (!S12) return;
  std::vector<char> inliers(c.size(), 0);
  const int count = scorer.score(*S12, inliers);
  if (count < result.inlier_count) return;
  result.S12 = *S12;
  result.inliers = std::move(inliers);
  result.inlier_count = count;
}

}  // namespace

Sim3 align_points(const std::vector<Vec3>& p1, const std::vector<Vec3>& p2, bool fix_scale) {
  if (p1.size() != p2.size())
    fail("align_points: {} points in keyframe 1 but {} in keyframe 2", p1.size(), p2.size());
  if (p1.size() < 3) fail("align_points: needs at least 3 point pairs, got {}", p1.size());
  const std::optional<Sim3> S12 = try_align(p1, p2, fix_scale);
  if (!S12) fail("align_points: the {} point pairs are collinear or coincident", p1.size());
  return *S12;
}

Sim3RansacResult ransac_sim3(const std::vector<Sim3Correspondence>& c, const PinholeCamera& camera1,
                             const PinholeCamera& camera2, const Sim3RansacOptions& options) {
  validate(options);
  Sim3RansacResult result;
  result.inliers.assign(c.size(), 0);
  const std::size_t n = c.size();
  if (n < static_cast<std::size_t>(options.min_inliers)) return result;

  const HypothesisScorer scorer(c, camera1, camera2, options.chi2);
  std::mt19937_64 rng(options.seed);
  std::vector<Vec3> p1(3), p2(3);
  std::vector<char> inliers(n, 0);
  const double n_double = static_cast<double>(n);
  int needed = required_iterations(options.min_inliers / n_double, options);
  while (result.iterations < needed) {
    ++result.iterations;
    const std::array<std::size_t, 3> sample = draw_triple(rng, n);
    for (int k = 0; k < 3; ++k) {
      p1[k] = c[sample[k]].p1_c;
      p2[k] = c[sample[k]].p2_c;
    }
    const std::optional<Sim3> S12 = try_align(p1, p2, options.fix_scale);
    if (!S12) continue;
    const int count = scorer.score(*S12, inliers);
    if (count <= result.inlier_count) continue;
    result.S12 = *S12;
    result.inliers = inliers;
    result.inlier_count = count;
    needed = std::min(needed, required_iterations(count / n_double, options));
  }
  if (result.inlier_count < options.min_inliers) return result;
  refit(c, scorer, options.fix_scale, result);
  result.found = true;
  return result;
}

}  // namespace sbaslam::loop
