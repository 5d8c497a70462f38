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

// A few unknowns over hundreds of residuals: dense QR, one thread (deterministic).
ceres::Solver::Options small_problem_solver(int max_iterations) {
  ceres::Solver::Options solver;
  solver.max_num_iterations = max_iterations;
  solver.linear_solver_type = ceres::DENSE_QR;
  solver.num_threads = 1;
  solver.logging_type = ceres::SILENT;
  return solver;
}

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
  ceres::Solver::Summary summary;
  ceres::Solve(small_problem_solver(options.max_iterations), &problem, &summary);
  if (!summary.IsSolutionUsable()) return motion;
  RelativeMotion out = motion;
  out.R21 = Quat(q[3], q[0], q[1], q[2]).normalized().toRotationMatrix();
  out.t21 = t.normalized();
  return out;
}

// A correspondence that the motion puts behind camera 1 or 2 by more than the noise: the Sampson
// distance only measures the distance to the epipolar line, so a wrong match that lies on the line
// but on the far side of the point at infinity (negative depth) passes any distance gate. Such a
// match pulls the translation hardest, since it implies the largest "parallax". Its pixel distance
// from the point at infinity, along the line, is compared with the gate; far points whose noise
// crosses infinity stay.
bool behind_a_camera(const RelativeMotion& motion, const PinholeIntrinsics& k, const Vec2& p1,
                     const Vec2& p2, double tolerance_px) {
  const Vec2 n1 = normalized(p1, k);
  const Vec3 ray = motion.R21 * Vec3(n1.x(), n1.y(), 1.0);
  if (ray.z() <= 0.0) return true;
  const Vec2 at_infinity(k.fx * ray.x() / ray.z() + k.cx, k.fy * ray.y() / ray.z() + k.cy);
  const Vec2 n2 = normalized(p2, k);
  const Vec3 b(n2.x(), n2.y(), 1.0);
  const Vec3 b_ray = b.cross(ray);
  // Depth of the point in camera 1 (scale of |t| = 1): z1 (b x R a) = -(b x t).
  const double z1_sign = -b.cross(motion.t21).dot(b_ray);
  // And in camera 2: z2 (R a x b) = R a x t.
  const double z2_sign = ray.cross(motion.t21).dot(-b_ray);
  if (z1_sign >= 0.0 && z2_sign >= 0.0) return false;
  return (p2 - at_infinity).norm() > tolerance_px;
}

}  // namespace

RelativeMotion refine_motion(const RelativeMotion& motion, const Correspondences& c,
                             const PinholeIntrinsics& k, const RefinementOptions& options) {
  RelativeMotion current = motion;
  std::vector<char> use(c.size(), 0);
  for (int round = 0; round < options.rounds; ++round) {
    for (int i = 0; i < c.size(); ++i) {
      const double sigma = sigma_of(c, i);
      const double d = sampson_distance(current, k, c.p1[i], c.p2[i]) / sigma;
      use[i] =
          d * d <= options.inlier_chi2 &&
          !behind_a_camera(current, k, c.p1[i], c.p2[i], std::sqrt(options.inlier_chi2) * sigma);
    }
    current = solve_once(current, c, use, k, options);
  }
  return current;
}

namespace {

// Symmetric transfer error of one correspondence under the plane-induced homography
// H = R + t' n^T between normalised planes (t' = t / d, n the unit plane normal in camera 1),
// in units of each observation's sigma: H a against b, then H^-1 b against a.
struct PlaneTransferResidual {
  PlaneTransferResidual(const Vec2& x1, const Vec2& x2, double scale1, double scale2)
      : x1_(x1), x2_(x2), scale1_(scale1), scale2_(scale2) {}

  template <typename T>
  bool operator()(const T* q_xyzw, const T* t_over_d, const T* n, T* residual) const {
    const Eigen::Quaternion<T> q(q_xyzw[3], q_xyzw[0], q_xyzw[1], q_xyzw[2]);
    const Eigen::Matrix<T, 3, 1> t(t_over_d[0], t_over_d[1], t_over_d[2]);
    const Eigen::Matrix<T, 3, 1> normal(n[0], n[1], n[2]);
    const Eigen::Matrix<T, 3, 3> H = q.normalized().toRotationMatrix() + t * normal.transpose();
    const Eigen::Matrix<T, 3, 1> a(T(x1_.x()), T(x1_.y()), T(1));
    const Eigen::Matrix<T, 3, 1> b(T(x2_.x()), T(x2_.y()), T(1));
    const Eigen::Matrix<T, 3, 1> forward = H * a;
    const Eigen::Matrix<T, 3, 1> backward = H.inverse() * b;
    residual[0] = T(scale2_) * (forward.x() / forward.z() - b.x());
    residual[1] = T(scale2_) * (forward.y() / forward.z() - b.y());
    residual[2] = T(scale1_) * (backward.x() / backward.z() - a.x());
    residual[3] = T(scale1_) * (backward.y() / backward.z() - a.y());
    return true;
  }

  Vec2 x1_, x2_;
  double scale1_, scale2_;
};

// The plane's t / d for a decomposed candidate: the least-squares (lambda, t') of
// lambda A - t' n^T = R, A the normalised homography known up to scale.
Vec3 plane_translation(const Mat3& A, const RelativeMotion& m) {
  Eigen::Matrix<double, 9, 4> M = Eigen::Matrix<double, 9, 4>::Zero();
  Eigen::Matrix<double, 9, 1> rhs;
  for (int r = 0; r < 3; ++r)
    for (int col = 0; col < 3; ++col) {
      const int row = 3 * r + col;
      M(row, 0) = A(r, col);
      M(row, 1 + r) = -m.normal(col);
      rhs(row) = m.R21(r, col);
    }
  const Eigen::Matrix<double, 4, 1> x = M.colPivHouseholderQr().solve(rhs);
  return x.tail<3>();
}

// Squared forward (H) and backward (H_inverse) transfer errors of correspondence i in sigma units.
std::pair<double, double> transfer_chi2(const Mat3& H, const Mat3& H_inverse,
                                        const Correspondences& c, int i,
                                        const PinholeIntrinsics& k) {
  const Vec2 a = normalized(c.p1[i], k), b = normalized(c.p2[i], k);
  const Vec3 f = H * Vec3(a.x(), a.y(), 1.0), g = H_inverse * Vec3(b.x(), b.y(), 1.0);
  const Vec2 e2((f.x() / f.z() - b.x()) * k.fx, (f.y() / f.z() - b.y()) * k.fy);
  const Vec2 e1((g.x() / g.z() - a.x()) * k.fx, (g.y() / g.z() - a.y()) * k.fy);
  return {e2.squaredNorm() * c.inv_sigma2_2[i], e1.squaredNorm() * c.inv_sigma2_1[i]};
}

}  // namespace

RelativeMotion refine_plane_motion(const RelativeMotion& motion, const Mat3& H21,
                                   const Correspondences& c, const PinholeIntrinsics& k,
                                   const PlaneRefinementOptions& options) {
  const Mat3 K = camera_matrix(k);
  Vec3 t = plane_translation(K.inverse() * H21 * K, motion);
  Vec3 n = motion.normal.normalized();
  const Quat q0(motion.R21);
  double q[4] = {q0.x(), q0.y(), q0.z(), q0.w()};
  const double focal = 0.5 * (k.fx + k.fy);
  bool solved = false;
  for (int round = 0; round < options.rounds; ++round) {
    const Mat3 H = Quat(q[3], q[0], q[1], q[2]).normalized().toRotationMatrix() + t * n.transpose();
    const Mat3 H_inverse = H.inverse();
    ceres::Problem problem;
    int used = 0;
    for (int i = 0; i < c.size(); ++i) {
      const auto [chi2_forward, chi2_backward] = transfer_chi2(H, H_inverse, c, i, k);
      if (chi2_forward > options.inlier_chi2 || chi2_backward > options.inlier_chi2) continue;
      auto* cost = new ceres::AutoDiffCostFunction<PlaneTransferResidual, 4, 4, 3, 3>(
          new PlaneTransferResidual(normalized(c.p1[i], k), normalized(c.p2[i], k),
                                    focal * std::sqrt(c.inv_sigma2_1[i]),
                                    focal * std::sqrt(c.inv_sigma2_2[i])));
      problem.AddResidualBlock(cost, new ceres::HuberLoss(options.huber), q, t.data(), n.data());
      ++used;
    }
    if (used < 8) break;
    problem.SetManifold(q, new ceres::EigenQuaternionManifold);
    problem.SetManifold(n.data(), new ceres::SphereManifold<3>);
    ceres::Solver::Summary summary;
    ceres::Solve(small_problem_solver(options.max_iterations), &problem, &summary);
    if (!summary.IsSolutionUsable() || t.norm() < 1e-12) return motion;
    solved = true;
  }
  if (!solved) return motion;
  RelativeMotion out;
  out.R21 = Quat(q[3], q[0], q[1], q[2]).normalized().toRotationMatrix();
  // n and t / d share a sign: keep the candidate's orientation of the translation and normal.
  const double sign = t.dot(motion.t21) < 0.0 ? -1.0 : 1.0;
  out.t21 = sign * t.normalized();
  out.normal = n.z() < 0.0 ? Vec3(-n) : n;
  return out;
}

}  // namespace sbaslam::geometry
