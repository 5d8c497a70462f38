#include "sbaslam/optimize/sim3_refinement.h"

#include <ceres/autodiff_cost_function.h>
#include <ceres/loss_function.h>
#include <ceres/manifold.h>
#include <ceres/problem.h>
#include <ceres/solver.h>

#include <cmath>

#include "sbaslam/core/error.h"

namespace sbaslam::optimize {
namespace {

// S12 as Ceres blocks: rotation [qx qy qz qw] (Eigen's memory order, EigenQuaternionManifold),
// translation, and the log of the scale, so that the scale stays positive without a bound and
// fix_scale is one constant block.
struct Sim3Parameters {
  double q[4];
  double t[3];
  double log_s;
};

Sim3Parameters to_parameters(const Sim3& S) {
  const Quat& q = S.so3().quaternion();
  const Vec3& t = S.translation();
  return {{q.x(), q.y(), q.z(), q.w()}, {t.x(), t.y(), t.z()}, std::log(S.scale())};
}

Sim3 from_parameters(const Sim3Parameters& x, double scale) {
  return Sim3(scale, SO3(Quat(x.q[3], x.q[0], x.q[1], x.q[2])), Vec3(x.t[0], x.t[1], x.t[2]));
}

// Pixel error of `point` mapped by S12 (by S12^-1 when `inverse`) and projected, scaled by
// 1/sigma so that its squared norm is the observation's chi2. A point that ends up behind the
// camera (or at infinity) fails the evaluation: Ceres then rejects the step, where a zero residual
// would reward carrying points past the camera.
class Sim3ProjectionResidual {
 public:
  Sim3ProjectionResidual(const Vec3& point, const Vec2& uv, double sigma2,
                         const PinholeIntrinsics& k, bool inverse)
      : point_(point), uv_(uv), inv_sigma_(1.0 / std::sqrt(sigma2)), k_(k), inverse_(inverse) {}

  template <typename T>
  bool operator()(const T* q, const T* t, const T* log_s, T* r) const {
    using std::exp;
    using std::isfinite;
    using Vec3T = Eigen::Matrix<T, 3, 1>;
    const Eigen::Map<const Eigen::Quaternion<T>> R(q);
    const Eigen::Map<const Vec3T> translation(t);
    const Vec3T p = point_.cast<T>();
    const Vec3T x = inverse_ ? Vec3T(R.conjugate() * (p - translation) * exp(-log_s[0]))
                             : Vec3T(exp(log_s[0]) * (R * p) + translation);
    // A step to an absurd scale (exp overflows) fails too, rather than giving NaN residuals.
    if (!(x.z() > T(0.0)) || !isfinite(x.x()) || !isfinite(x.y()) || !isfinite(x.z())) return false;
    r[0] = (T(k_.fx) * x.x() / x.z() + T(k_.cx - uv_.x())) * T(inv_sigma_);
    r[1] = (T(k_.fy) * x.y() / x.z() + T(k_.cy - uv_.y())) * T(inv_sigma_);
    return true;
  }

 private:
  Vec3 point_;
  Vec2 uv_;
  double inv_sigma_;
  PinholeIntrinsics k_;
  bool inverse_;
};

// The two residuals of a pair: in camera 1 (S12 p2) and in camera 2 (S12^-1 p1).
struct PairResiduals {
  Sim3ProjectionResidual in1, in2;
  PairResiduals(const Sim3Correspondence& c, const PinholeCamera& camera1,
                const PinholeCamera& camera2)
      : in1(c.p2_c, c.uv1, c.sigma2_1, camera1.intrinsics(), false),
        in2(c.p1_c, c.uv2, c.sigma2_2, camera2.intrinsics(), true) {}
};

// ORB-SLAM's edge test: both chi2 within the gate, and the point in front of both cameras.
bool is_inlier(const PairResiduals& pair, const Sim3Parameters& x, double max_chi2) {
  double r1[2], r2[2];
  if (!pair.in1(x.q, x.t, &x.log_s, r1) || !pair.in2(x.q, x.t, &x.log_s, r2)) return false;
  return r1[0] * r1[0] + r1[1] * r1[1] <= max_chi2 && r2[0] * r2[0] + r2[1] * r2[1] <= max_chi2;
}

bool in_front(const PairResiduals& pair, const Sim3Parameters& x) {
  double r[2];
  return pair.in1(x.q, x.t, &x.log_s, r) && pair.in2(x.q, x.t, &x.log_s, r);
}

// One robust round over the pairs flagged in `use` (all in front of both cameras at x).
void solve_round(const std::vector<PairResiduals>& pairs, const std::vector<char>& use,
                 double huber_delta, int iterations, bool fix_scale, Sim3Parameters& x) {
  using Cost = ceres::AutoDiffCostFunction<Sim3ProjectionResidual, 2, 4, 3, 1>;
  if (iterations <= 0) return;
  ceres::HuberLoss huber(huber_delta);  // outlives the problem, which only borrows it
  ceres::Problem::Options problem_options;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    if (!use[i]) continue;
    problem.AddResidualBlock(new Cost(new Sim3ProjectionResidual(pairs[i].in1)), &huber, x.q, x.t,
                             &x.log_s);
    problem.AddResidualBlock(new Cost(new Sim3ProjectionResidual(pairs[i].in2)), &huber, x.q, x.t,
                             &x.log_s);
  }
  if (problem.NumResidualBlocks() == 0) return;
  problem.SetManifold(x.q, new ceres::EigenQuaternionManifold);
  if (fix_scale) problem.SetParameterBlockConstant(&x.log_s);
  // Seven unknowns over up to a few hundred residuals: dense QR, one thread (deterministic).
  ceres::Solver::Options solver;
  solver.max_num_iterations = iterations;
  solver.linear_solver_type = ceres::DENSE_QR;
  solver.num_threads = 1;
  solver.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(solver, &problem, &summary);
}

void validate(const std::vector<Sim3Correspondence>& c, const Sim3& initial,
              const Sim3RefinementOptions& options) {
  if (!(options.huber_chi2 > 0.0) || !std::isfinite(options.huber_chi2))
    fail("Sim3 refinement: huber_chi2 must be positive and finite, got {}", options.huber_chi2);
  if (options.iterations_first < 0 || options.iterations_second < 0)
    fail("Sim3 refinement: iteration counts must be >= 0, got {} and {}", options.iterations_first,
         options.iterations_second);
  if (!(initial.scale() > 0.0))
    fail("Sim3 refinement: the initial scale must be positive, got {}", initial.scale());
  for (std::size_t i = 0; i < c.size(); ++i)
    if (!(c[i].sigma2_1 > 0.0) || !(c[i].sigma2_2 > 0.0))
      fail("Sim3 refinement: correspondence {} has a non-positive sigma2", i);
}

}  // namespace

Sim3RefinementResult refine_sim3(const std::vector<Sim3Correspondence>& c, const Sim3& initial,
                                 const PinholeCamera& camera1, const PinholeCamera& camera2,
                                 const Sim3RefinementOptions& options) {
  validate(c, initial, options);
  std::vector<PairResiduals> pairs;
  pairs.reserve(c.size());
  for (const Sim3Correspondence& pair : c) pairs.emplace_back(pair, camera1, camera2);

  Sim3Parameters x = to_parameters(initial);
  const double delta = std::sqrt(options.huber_chi2);
  // A pair behind a camera at the start would fail Ceres' first evaluation, so it never enters.
  std::vector<char> use(c.size(), 0);
  for (std::size_t i = 0; i < c.size(); ++i) use[i] = in_front(pairs[i], x);
  solve_round(pairs, use, delta, options.iterations_first, options.fix_scale, x);
  for (std::size_t i = 0; i < c.size(); ++i)
    use[i] = use[i] && is_inlier(pairs[i], x, options.huber_chi2);
  solve_round(pairs, use, delta, options.iterations_second, options.fix_scale, x);

  Sim3RefinementResult result;
  result.S12 = from_parameters(x, options.fix_scale ? initial.scale() : std::exp(x.log_s));
  result.inliers.assign(c.size(), 0);
  for (std::size_t i = 0; i < c.size(); ++i) {
    result.inliers[i] = use[i] && is_inlier(pairs[i], x, options.huber_chi2);
    result.inlier_count += result.inliers[i];
  }
  return result;
}

}  // namespace sbaslam::optimize
