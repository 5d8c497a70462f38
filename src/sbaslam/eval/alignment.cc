#include "sbaslam/eval/alignment.h"

#include <Eigen/SVD>
#include <limits>

#include "sbaslam/core/error.h"

namespace sbaslam::eval {
namespace {

Eigen::Matrix3Xd first_positions(const PoseSeries& series, std::size_t n) {
  Eigen::Matrix3Xd positions(3, static_cast<Eigen::Index>(n));
  for (std::size_t i = 0; i < n; ++i)
    positions.col(static_cast<Eigen::Index>(i)) = series.poses[i].topRightCorner<3, 1>();
  return positions;
}

}  // namespace

AlignmentMode parse_alignment_mode(const std::string& name) {
  if (name == "none") return AlignmentMode::kNone;
  if (name == "se3") return AlignmentMode::kSe3;
  if (name == "sim3") return AlignmentMode::kSim3;
  if (name == "scale") return AlignmentMode::kScale;
  fail("unknown alignment '{}' (expected none, se3, sim3 or scale)", name);
}

std::string alignment_mode_name(AlignmentMode mode) {
  switch (mode) {
    case AlignmentMode::kNone:
      return "none";
    case AlignmentMode::kSe3:
      return "se3";
    case AlignmentMode::kSim3:
      return "sim3";
    case AlignmentMode::kScale:
      return "scale";
  }
  return "unknown";
}

Similarity umeyama_alignment(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& y,
                             bool with_scale) {
  if (x.cols() != y.cols())
    fail("alignment needs as many reference as estimate positions ({} vs {})", y.cols(), x.cols());
  if (x.cols() < 2) fail("alignment needs at least 2 positions, got {}", x.cols());
  const double n = static_cast<double>(x.cols());
  const Vec3 mean_x = x.rowwise().mean();
  const Vec3 mean_y = y.rowwise().mean();
  const Eigen::Matrix3Xd x_centred = x.colwise() - mean_x;
  const Eigen::Matrix3Xd y_centred = y.colwise() - mean_y;
  const double sigma_x = x_centred.squaredNorm() / n;
  const Mat3 cov_xy = (y_centred * x_centred.transpose()) / n;

  const Eigen::JacobiSVD<Mat3> svd(cov_xy, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Vec3 d = svd.singularValues();
  const int rank = (d.array() > std::numeric_limits<double>::epsilon()).count();
  if (rank < 2)
    fail("degenerate positions (covariance rank {}): Umeyama alignment is not possible", rank);
  Mat3 S = Mat3::Identity();
  if (svd.matrixU().determinant() * svd.matrixV().determinant() < 0.0) S(2, 2) = -1.0;

  Similarity result;
  result.R = svd.matrixU() * S * svd.matrixV().transpose();
  result.scale = with_scale ? (d.asDiagonal() * S).trace() / sigma_x : 1.0;
  result.t = mean_y - result.scale * (result.R * mean_x);
  return result;
}

Similarity align_estimate(PoseSeries& estimate, const PoseSeries& reference, AlignmentMode mode,
                          std::optional<std::size_t> n_to_align) {
  if (mode == AlignmentMode::kNone) return Similarity{};
  if (estimate.size() != reference.size())
    fail("alignment needs paired poses ({} reference, {} estimate)", reference.size(),
         estimate.size());
  std::size_t n = estimate.size();
  if (n_to_align) {
    if (*n_to_align < 2) fail("n-to-align must be at least 2 (got {})", *n_to_align);
    if (*n_to_align > n)
      fail("n-to-align {} exceeds the {} paired poses", *n_to_align, estimate.size());
    n = *n_to_align;
  }
  const bool with_scale = mode == AlignmentMode::kSim3 || mode == AlignmentMode::kScale;
  const Similarity sim =
      umeyama_alignment(first_positions(estimate, n), first_positions(reference, n), with_scale);

  Mat4 rigid = Mat4::Identity();
  rigid.topLeftCorner<3, 3>() = sim.R;
  rigid.topRightCorner<3, 1>() = sim.t;
  for (Mat4& pose : estimate.poses) {
    if (with_scale) pose.topRightCorner<3, 1>() *= sim.scale;
    if (mode != AlignmentMode::kScale) pose = rigid * pose;
  }
  return sim;
}

}  // namespace sbaslam::eval
