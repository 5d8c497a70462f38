#pragma once
// Motion-only BA's cost: every active observation of the frame, each under its own Huber kernel,
// 1/2 sum rho(s) with s = |e|^2 and e the residual scaled by sqrt(w / sigma^2)
// (reprojection_cost.h): ORB-SLAM's objective, and the Salient BA cost of the paper.
//
// The normal equations are the Gauss-Newton ones of that objective with the kernel's own
// curvature (Triggs et al., "Bundle adjustment - a modern synthesis", robustified second-order):
// H = sum rho'(s) (J^T J + 2 s rho''(s) / rho'(s) J^T e_hat e_hat^T J), g = sum rho'(s) J^T e.
// In the kernel's linear part the cost grows only linearly with |e|, so H has no curvature along
// e there. Without that term (the iteratively reweighted approximation, or Gauss-Newton on rows of
// norm sqrt(rho)) the solver's steps fall short along e: with the saliency weights putting most
// observations in the linear part (a = 256), the rounds of a city-loop run took 12.7k iterations
// instead of 7.0k (docs/RESULTS.md, "Session 20").
//
// The 6-dof solver (pose_optimizer.cc) needs only H and g, so normal_equations() sums them per
// observation in one pass; a Ceres problem took more than half of motion-only BA's time in its
// Jacobian's checks and products (bench: 1.52 ms for 900 stereo observations over 4 rounds).

#include <Eigen/Core>
#include <vector>

#include "sbaslam/optimize/reprojection_cost.h"

namespace sbaslam::optimize {

using Mat66 = Eigen::Matrix<double, 6, 6>;

// Huber's rho(s) on a squared norm s, with threshold delta on the norm (Ceres' HuberLoss(delta)).
double huber_rho(double s, double delta);

// The normal equations of the cost at one pose (above), with J taken with respect to the pose
// tangent [dphi dt] (pose_parameter.h): the model cost + g^T dx + 1/2 dx^T H dx.
struct PoseNormalEquations {
  double cost = 0.0;
  Mat66 H = Mat66::Zero();
  Vec6 g = Vec6::Zero();
  int behind_camera = 0;  // active observations whose point is behind the camera (zero residual)
};

class PoseOnlyCost {
 public:
  // observations[i] sees points[i]; only the indices in `active` enter the cost. A threshold
  // <= 0 switches the kernel off (plain least squares). The vectors are referenced, not copied.
  PoseOnlyCost(const RectifiedCamera& cam, const std::vector<PixelObservation>& observations,
               const std::vector<Vec3>& points, std::vector<std::size_t> active, double huber_mono,
               double huber_stereo);

  // cost, H and g at the pose [qx qy qz qw tx ty tz], in one pass over the observations.
  PoseNormalEquations normal_equations(const double* pose) const;

 private:
  // The observation's residual e (n = 2 or 3 rows), its n x 7 Jacobian if asked, and its
  // kernel threshold; returns n.
  int residual(std::size_t i, const double* pose, double* e, double* jacobian, double& delta,
               int& behind) const;

  const RectifiedCamera& cam_;
  const std::vector<PixelObservation>& observations_;
  const std::vector<Vec3>& points_;
  std::vector<std::size_t> active_;
  double huber_mono_, huber_stereo_;
};

}  // namespace sbaslam::optimize
