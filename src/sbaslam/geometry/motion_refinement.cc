#include "sbaslam/geometry/motion_refinement.h"

#include <ceres/ceres.h>
#include <ceres/sphere_manifold.h>

#include <cmath>

namespace sbaslam::geometry {
namespace {

// Sampson distance of one correspondence, on normalised-plane points scaled back to pixels by
// the focal length (isotropic enough for a residual: fx and fy differ by well under 1%).
struct SampsonResidual {
  SampsonResidual(const Vec2& x1, const Vec2& x2, double pixel_scale)
      : x1_(x1), x2_(x2), scale_(pixel_scale) {}

  template <typename T>
  bool operator()(const T* q_xyzw, const T* t, T* residual) const {
    const Eigen::Quaternion<T> q(q_xyzw[3], q_xyzw[0], q_xyzw[1], q_xyzw[2]);
    const Eigen::Matrix<T, 3, 1> tt(t[0], t[1], t[2]);
    Eigen::Matrix<T, 3, 3> tx;
    tx << T(0), -tt.z(), tt.y(), tt.z(), T(0), -tt.x(), -tt.y(), tt.x(), T(0);
    const Eigen::Matrix<T, 3, 3> E = tx * q.normalized().toRotationMatrix();
    const Eigen::Matrix<T, 3, 1> a(T(x1_.x()), T(x1_.y()), T(1));
    const Eigen::Matrix<T, 3, 1> b(T(x2_.x()), T(x2_.y()), T(1));
    const Eigen::Matrix<T, 3, 1> Ea = E * a, Etb = E.transpose() * b;
    const T e = b.dot(Ea);
    const T gradient2 = Ea.x() * Ea.x() + Ea.y() * Ea.y() + Etb.x() * Etb.x() + Etb.y() * Etb.y();
    residual[0] = T(scale_) * e / ceres::sqrt(gradient2 + T(1e-300));
    return true;
  }

  Vec2 x1_, x2_;
  double scale_;
};

Vec2 normalized(const Vec2& uv, const PinholeIntrinsics& k) {
  return {(uv.x() - k.cx) / k.fx, (uv.y() - k.cy) / k.fy};
}

}  // namespace

double sampson_distance(const RelativeMotion& motion, const PinholeIntrinsics& k, const Vec2& p1,
                        const Vec2& p2) {
  const Quat q(motion.R21);
  const double q_xyzw[4] = {q.x(), q.y(), q.z(), q.w()};
  double r = 0.0;
  SampsonResidual(normalized(p1, k), normalized(p2, k), 0.5 * (k.fx + k.fy))(q_xyzw,
                                                                             motion.t21.data(), &r);
  return std::abs(r);
}

namespace {

double sigma_of(const Correspondences& c, int i) {
  // Both observations' noise enters the distance: the mean of their variances.
  return std::sqrt(0.5 * (1.0 / c.inv_sigma2_1[i] + 1.0 / c.inv_sigma2_2[i]));
}

RelativeMotion solve_once(const RelativeMotion& motion, const Correspondences& c,
                          const std::vector<char>& use, const PinholeIntrinsics& k,
                          const RefinementOptions& options) {
  const Quat q0(motion.R21);
  double q[4] = {q0.x(), q0.y(), q0.z(), q0.w()};
  Vec3 t = motion.t21.normalized();
  ceres::Problem problem;
  const double focal = 0.5 * (k.fx + k.fy);
  int used = 0;
  for (int i = 0; i < c.size(); ++i) {
    if (!use[i]) continue;
    const double sigma = sigma_of(c, i);
    auto* cost = new ceres::AutoDiffCostFunction<SampsonResidual, 1, 4, 3>(
        new SampsonResidual(normalized(c.p1[i], k), normalized(c.p2[i], k), focal / sigma));
    problem.AddResidualBlock(cost, new ceres::HuberLoss(options.huber_px), q, t.data());
    ++used;
  }
  if (used < 8) return motion;
  problem.SetManifold(q, new ceres::EigenQuaternionManifold);
  problem.SetManifold(t.data(), new ceres::SphereManifold<3>);
  ceres::Solver::Options solver;
  solver.max_num_iterations = options.max_iterations;
  solver.linear_solver_type = ceres::DENSE_QR;
  solver.num_threads = 1;
  solver.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(solver, &problem, &summary);
  if (!summary.IsSolutionUsable()) return motion;
  RelativeMotion out = motion;
  out.R21 = Quat(q[3], q[0], q[1], q[2]).normalized().toRotationMatrix();
  out.t21 = t.normalized();
  return out;
}

}  // namespace

RelativeMotion refine_motion(const RelativeMotion& motion, const Correspondences& c,
                             const PinholeIntrinsics& k, const RefinementOptions& options) {
  RelativeMotion current = motion;
  std::vector<char> use(c.size(), 0);
  for (int round = 0; round < options.rounds; ++round) {
    for (int i = 0; i < c.size(); ++i) {
      const double d = sampson_distance(current, k, c.p1[i], c.p2[i]) / sigma_of(c, i);
      use[i] = d * d <= options.inlier_chi2;
    }
    current = solve_once(current, c, use, k, options);
  }
  return current;
}

}  // namespace sbaslam::geometry
