#include "sbaslam/optimize/pose_graph.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <cmath>

#include "sbaslam/core/error.h"
#include "sbaslam/optimize/pose_parameter.h"

namespace sbaslam::optimize {
namespace {

inline double value(double x) {
  return x;
}
template <typename T, int N>
double value(const ceres::Jet<T, N>& x) {
  return value(x.a);
}

// Coefficients of V(phi, sigma) = A I + B K + C K^2 (K = hat(phi), theta^2 = |phi|^2), the matrix
// with t = V rho in core/lie.h's Sim3::exp. V is the integral over s in [0, 1] of e^{s sigma}
// R(s phi); on the plane orthogonal to phi, K acts as multiplication by i theta, so
// A + i theta B - theta^2 C = (e^z - 1) / z with z = sigma + i theta.
//
// Power series of (e^z - 1) / z = sum z^k / (k+1)!, with z^k = a_k + i theta b_k and
// sigma^k - a_k = theta^2 c_k: B and C become polynomials in sigma and theta^2 that never divide
// by theta. The closed forms are 0/0 at phi = 0, where a converged pose graph's errors sit, and
// autodiff would return NaN there; the series gives exact values and first derivatives.
template <typename T>
void series_coefficients(const T& sigma, const T& theta_sq, double r, T& A, T& B, T& C) {
  T p(1.0), a(1.0), b(0.0), c(0.0);  // sigma^k, a_k, b_k, c_k at k = 0
  A = B = C = T(0.0);
  double inv_factorial = 1.0;  // 1 / (k+1)!
  for (int k = 0;; ++k) {
    inv_factorial /= k + 1;
    A += p * inv_factorial;
    B += b * inv_factorial;
    C += c * inv_factorial;
    // Term k+1's values and first derivatives are below (k+2)^3 r^(k-1) / (k+2)!; from k = 4 on,
    // the derivatives at z = 0 are complete.
    const double r_pow = k >= 1 ? std::pow(r, k - 1) : 1.0;
    if (k >= 4 && (k + 2.0) * (k + 2.0) * r_pow * inv_factorial < 1e-17) return;
    const T a_next = sigma * a - theta_sq * b;
    c = sigma * c + b;
    b = a + sigma * b;
    a = a_next;
    p = sigma * p;
  }
}

// Closed forms, used only for |z| > 4, that is |sigma| > 2.4 (theta <= pi): a relative scale
// error beyond 11x in one edge. Below theta = 1e-5 they lose precision, and B and C are taken at
// theta = 0 (B = int s e^{s sigma}, C = int s^2 / 2 e^{s sigma}); that drops derivatives of
// relative size theta.
template <typename T>
void closed_form_coefficients(const T& sigma, const T& theta_sq, T& A, T& B, T& C) {
  using std::cos;
  using std::exp;
  using std::expm1;
  using std::sin;
  using std::sqrt;
  const T es = exp(sigma);
  A = expm1(sigma) / sigma;
  if (value(theta_sq) < 1e-10) {
    const T s2 = sigma * sigma;
    B = (es * (sigma - 1.0) + 1.0) / s2;
    C = (es * (s2 - 2.0 * sigma + 2.0) - 2.0) / (2.0 * s2 * sigma);
    return;
  }
  const T theta = sqrt(theta_sq);
  const T r_sq = sigma * sigma + theta_sq;
  const T re = (sigma * (es * cos(theta) - 1.0) + theta * es * sin(theta)) / r_sq;
  const T im = (sigma * es * sin(theta) - theta * (es * cos(theta) - 1.0)) / r_sq;
  B = im / theta;
  C = (A - re) / theta_sq;
}

// rho = V(phi, sigma)^-1 t. V^-1 = (1/A) I + beta K + gamma K^2 inverts A on phi and
// X + i theta B (X = A - theta^2 C) on the orthogonal plane: with D = X^2 + theta^2 B^2,
// beta = -B / D and gamma = (B^2 - C X) / (A D), again without dividing by theta.
template <typename T>
Eigen::Matrix<T, 3, 1> sim3_log_translation(const Eigen::Matrix<T, 3, 1>& phi, const T& sigma,
                                            const Eigen::Matrix<T, 3, 1>& t) {
  const T theta_sq = phi.squaredNorm();
  const double r = std::sqrt(value(sigma) * value(sigma) + value(theta_sq));
  T A, B, C;
  if (r <= 4.0) {
    series_coefficients(sigma, theta_sq, r, A, B, C);
  } else {
    closed_form_coefficients(sigma, theta_sq, A, B, C);
  }
  const T X = A - theta_sq * C;
  const T D = X * X + theta_sq * B * B;
  const Eigen::Matrix<T, 3, 1> phi_t = phi.cross(t);
  return t / A - (B / D) * phi_t + ((B * B - C * X) / (A * D)) * phi.cross(phi_t);
}

struct Measurement {
  Quat q;
  Vec3 t;
  double scale;
  double log_scale;
  double sqrt_weight;

  explicit Measurement(const PoseGraphEdge& edge)
      : q(edge.S_ji.so3().quaternion()),
        t(edge.S_ji.translation()),
        scale(edge.S_ji.scale()),
        log_scale(std::log(edge.S_ji.scale())),
        sqrt_weight(std::sqrt(edge.weight)) {}
};

// The weighted log of S_ji * S_iw * S_jw^-1, given the two poses ([qx qy qz qw tx ty tz]), the
// ratio s_i / s_j and the relative transform's log scale sigma. With kDof 6 (fixed scale) the
// error is the se(3) log of its rotation and translation, that is with sigma = 0.
template <int kDof, typename T>
void relative_error(const Measurement& m, const T* pose_i, const T* pose_j, const T& s_ij,
                    const T& sigma, T* residual) {
  using V3 = Eigen::Matrix<T, 3, 1>;
  const Eigen::Map<const Eigen::Quaternion<T>> q_i(pose_i), q_j(pose_j);
  const Eigen::Map<const V3> t_i(pose_i + 4), t_j(pose_j + 4);
  // S_iw * S_jw^-1 = (s_i / s_j, R_i R_j^T, t_i - s_i / s_j R_i R_j^T t_j).
  const Eigen::Quaternion<T> q_ij = q_i * q_j.conjugate();
  const V3 t_ij = t_i - s_ij * (q_ij * t_j);
  const Eigen::Quaternion<T> q_e = m.q.cast<T>() * q_ij;
  const V3 t_e = m.scale * (m.q.cast<T>() * t_ij) + m.t.cast<T>();
  const T q_wxyz[4] = {q_e.w(), q_e.x(), q_e.y(), q_e.z()};
  V3 phi;
  ceres::QuaternionToAngleAxis(q_wxyz, phi.data());
  const V3 rho = sim3_log_translation<T>(phi, kDof == 7 ? sigma : T(0.0), t_e);
  for (int k = 0; k < 3; ++k) {
    residual[k] = m.sqrt_weight * rho[k];
    residual[3 + k] = m.sqrt_weight * phi[k];
  }
  if constexpr (kDof == 7) residual[6] = m.sqrt_weight * sigma;
}

// Free scales: each vertex has a log-scale block, so s_i / s_j = exp(l_i - l_j) and the relative
// log scale is linear in the parameters.
struct SimilarityEdgeCost {
  Measurement m;
  template <typename T>
  bool operator()(const T* pose_i, const T* log_s_i, const T* pose_j, const T* log_s_j,
                  T* residual) const {
    using std::exp;
    const T log_s_ij = log_s_i[0] - log_s_j[0];
    relative_error<7>(m, pose_i, pose_j, exp(log_s_ij), log_s_ij + m.log_scale, residual);
    return true;
  }
};

// Fixed scales: the ratio s_i / s_j is a constant of the edge.
struct RigidEdgeCost {
  Measurement m;
  double s_ij;
  template <typename T>
  bool operator()(const T* pose_i, const T* pose_j, T* residual) const {
    relative_error<6>(m, pose_i, pose_j, T(s_ij), T(0.0), residual);
    return true;
  }
};

void check_input(const std::vector<Sim3>& vertices, const std::vector<bool>& fixed,
                 const std::vector<PoseGraphEdge>& edges, const PoseGraphOptions& options) {
  if (fixed.size() != vertices.size())
    fail("pose graph: {} fixed flags for {} vertices", fixed.size(), vertices.size());
  if (options.iterations < 0) fail("pose graph: negative iteration count {}", options.iterations);
  for (std::size_t v = 0; v < vertices.size(); ++v)
    if (!(vertices[v].scale() > 0.0) || !std::isfinite(vertices[v].scale()))
      fail("pose graph: vertex {} has scale {}", v, vertices[v].scale());
  for (std::size_t e = 0; e < edges.size(); ++e) {
    const PoseGraphEdge& edge = edges[e];
    if (edge.i >= vertices.size() || edge.j >= vertices.size())
      fail("pose graph: edge {} joins vertices {} and {} of {}", e, edge.i, edge.j,
           vertices.size());
    if (edge.i == edge.j) fail("pose graph: edge {} joins vertex {} to itself", e, edge.i);
    if (!(edge.weight >= 0.0) || !std::isfinite(edge.weight))
      fail("pose graph: edge {} has weight {}", e, edge.weight);
    if (!(edge.S_ji.scale() > 0.0) || !std::isfinite(edge.S_ji.scale()))
      fail("pose graph: edge {} has scale {}", e, edge.S_ji.scale());
  }
}

using PoseManifold3 =
    ceres::ProductManifold<ceres::EigenQuaternionManifold, ceres::EuclideanManifold<3>>;

// Per vertex a pose block [qx qy qz qw tx ty tz] (unit quaternion on its manifold) and, unless the
// scale is fixed, a log-scale block: positive scales without bounds, and the relative log scale
// is a difference of parameters.
class CeresPoseGraph {
 public:
  CeresPoseGraph(const std::vector<Sim3>& vertices, const std::vector<bool>& fixed,
                 const std::vector<PoseGraphEdge>& edges, bool fix_scale)
      : fix_scale_(fix_scale), problem_(problem_options()) {
    poses_.resize(vertices.size());
    log_scales_.resize(vertices.size());
    touched_.assign(vertices.size(), false);
    for (const PoseGraphEdge& edge : edges) touched_[edge.i] = touched_[edge.j] = true;
    for (std::size_t v = 0; v < vertices.size(); ++v)
      if (touched_[v]) add_vertex(v, vertices[v], fixed[v]);
    for (const PoseGraphEdge& edge : edges) add_edge(edge, vertices);
  }

  PoseGraphReport solve(int iterations) {
    ceres::Solver::Options options;
    options.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
    options.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
    options.max_num_iterations = iterations;
    // Ceres' default (1e-6) stops after the first, damped step when that step already takes the
    // cost down to its minimum's level; ORB-SLAM runs all its iterations. The gradient and
    // parameter tolerances still end a converged solve early.
    options.function_tolerance = 1e-12;
    // One thread: the Jacobian's evaluation order, and so every bit of the result, is fixed.
    options.num_threads = 1;
    options.logging_type = ceres::SILENT;
    ceres::Solver::Summary summary;
    ceres::Solve(options, &problem_, &summary);
    PoseGraphReport report;
    report.initial_cost = 2.0 * summary.initial_cost;
    report.final_cost = 2.0 * summary.final_cost;
    report.iterations = summary.num_successful_steps + summary.num_unsuccessful_steps;
    report.converged = summary.termination_type == ceres::CONVERGENCE;
    return report;
  }

  // Only free vertices that some edge touches: the others keep their exact input, and so do the
  // scales when they are fixed (exp(log s) need not give back s).
  void write_back(std::vector<Sim3>& vertices, const std::vector<bool>& fixed) const {
    for (std::size_t v = 0; v < vertices.size(); ++v) {
      if (fixed[v] || !touched_[v]) continue;
      const PoseParameters& p = poses_[v];
      const double scale = fix_scale_ ? vertices[v].scale() : std::exp(log_scales_[v]);
      vertices[v] = Sim3(scale, SO3(Quat(p[3], p[0], p[1], p[2])), Vec3(p[4], p[5], p[6]));
    }
  }

 private:
  static ceres::Problem::Options problem_options() {
    ceres::Problem::Options options;
    options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    return options;
  }

  void add_vertex(std::size_t v, const Sim3& S, bool fixed) {
    const Quat& q = S.so3().quaternion();
    const Vec3& t = S.translation();
    poses_[v] = {q.x(), q.y(), q.z(), q.w(), t.x(), t.y(), t.z()};
    problem_.AddParameterBlock(poses_[v].data(), 7, &pose_manifold_);
    if (fixed) problem_.SetParameterBlockConstant(poses_[v].data());
    if (fix_scale_) return;
    log_scales_[v] = std::log(S.scale());
    problem_.AddParameterBlock(&log_scales_[v], 1);
    if (fixed) problem_.SetParameterBlockConstant(&log_scales_[v]);
  }

  void add_edge(const PoseGraphEdge& edge, const std::vector<Sim3>& vertices) {
    const Measurement m(edge);
    double* pose_i = poses_[edge.i].data();
    double* pose_j = poses_[edge.j].data();
    if (fix_scale_) {
      const double s_ij = vertices[edge.i].scale() / vertices[edge.j].scale();
      problem_.AddResidualBlock(
          new ceres::AutoDiffCostFunction<RigidEdgeCost, 6, 7, 7>(new RigidEdgeCost{m, s_ij}),
          nullptr, pose_i, pose_j);
    } else {
      problem_.AddResidualBlock(new ceres::AutoDiffCostFunction<SimilarityEdgeCost, 7, 7, 1, 7, 1>(
                                    new SimilarityEdgeCost{m}),
                                nullptr, pose_i, &log_scales_[edge.i], pose_j,
                                &log_scales_[edge.j]);
    }
  }

  bool fix_scale_;
  std::vector<PoseParameters> poses_;  // the blocks: sized once, never reallocated
  std::vector<double> log_scales_;
  std::vector<bool> touched_;
  PoseManifold3 pose_manifold_;  // declared before the problem, so it outlives it
  ceres::Problem problem_;
};

}  // namespace

PoseGraphReport optimize_pose_graph(std::vector<Sim3>& vertices, const std::vector<bool>& fixed,
                                    const std::vector<PoseGraphEdge>& edges,
                                    const PoseGraphOptions& options) {
  check_input(vertices, fixed, edges, options);
  if (edges.empty()) return PoseGraphReport{0.0, 0.0, 0, true};
  CeresPoseGraph graph(vertices, fixed, edges, options.fix_scale);
  const PoseGraphReport report = graph.solve(options.iterations);
  graph.write_back(vertices, fixed);
  return report;
}

}  // namespace sbaslam::optimize
