#pragma once
// ORB-SLAM's Optimizer::OptimizeEssentialGraph as a pure optimisation over Sim(3) poses: after a
// loop is found, the loop closer builds the essential graph (spanning tree, strong covisibility
// edges, loop edges) from the map and hands vertices and edges to optimize_pose_graph; this module
// knows nothing of keyframes or locks.
//
// Every edge is trusted (no robust kernel), as in ORB-SLAM: the graph only holds edges the map
// already accepted, and the loop edge, which carries the whole correction, must not be
// down-weighted.

#include <cstddef>
#include <vector>

#include "sbaslam/core/lie.h"

namespace sbaslam::optimize {

struct PoseGraphEdge {
  std::size_t i = 0, j = 0;  // vertex indices
  Sim3 S_ji;                 // measured relative transform: S_jw * S_iw^-1 (world-to-camera poses)
  double weight =
      1.0;  // multiplies the residual's information (ORB-SLAM uses identity information)
};

struct PoseGraphOptions {
  int iterations = 20;  // Levenberg-Marquardt iterations at most
  // Stereo / RGB-D: the scale is observable, every vertex keeps its initial scale and the edge
  // error is the 6-dof se(3) log of the relative transform's rotation and translation.
  bool fix_scale = false;
};

// Costs are sum over edges of weight * |e|^2 (not Ceres' half of it).
struct PoseGraphReport {
  double initial_cost = 0, final_cost = 0;
  int iterations = 0;      // Levenberg-Marquardt steps taken, accepted or not
  bool converged = false;  // a Ceres tolerance was met before the iteration limit
};

// vertices: world-to-camera similarities S_iw; fixed[i] keeps vertex i constant (ORB-SLAM fixes
// the loop keyframe / the origin).
// Minimises sum over edges of weight * |e|^2 with e = log(S_ji * S_iw * S_jw^-1), the sim(3)
// 7-vector [rho, phi, sigma] of core/lie.h; with fix_scale, e is the se(3) 6-vector [rho, phi] of
// the relative transform's rotation and translation and every vertex's scale stays at its initial
// value. Writes the optimised poses into `vertices`: fixed vertices, and vertices no edge touches,
// are left bit-identical, and so are all scales with fix_scale. Single-threaded: identical input
// gives bit-identical output.
// Throws sbaslam::Error on inconsistent input: fixed.size() != vertices.size(), an edge index out
// of range or an edge from a vertex to itself, a negative or non-finite weight, a non-positive
// scale, or a negative iteration count.
PoseGraphReport optimize_pose_graph(std::vector<Sim3>& vertices, const std::vector<bool>& fixed,
                                    const std::vector<PoseGraphEdge>& edges,
                                    const PoseGraphOptions& options);

}  // namespace sbaslam::optimize
