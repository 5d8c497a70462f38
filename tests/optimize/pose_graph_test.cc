#include "sbaslam/optimize/pose_graph.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "helper/expect_error.h"

namespace sbaslam::optimize {
namespace {

constexpr double kPi = 3.14159265358979323846;

struct Graph {
  std::vector<Sim3> truth;
  std::vector<Sim3> initial;
  std::vector<PoseGraphEdge> edges;
};

PoseGraphEdge edge_from(const std::vector<Sim3>& poses, std::size_t i, std::size_t j) {
  PoseGraphEdge edge;
  edge.i = i;
  edge.j = j;
  edge.S_ji = poses[j] * poses[i].inverse();
  return edge;
}

// World-to-camera pose k of n on a 10 m circle, looking along the tangent, with some height and
// pitch variation so that the problem is not planar.
Sim3 circle_pose(int k, int n) {
  const double a = 2.0 * kPi * k / n;
  const Vec3 center(10.0 * std::cos(a), 10.0 * std::sin(a), 0.5 * std::sin(3.0 * a));
  const SO3 R_wc = SO3::exp(Vec3(0.0, 0.0, a + kPi / 2)) * SO3::exp(Vec3(0.1 * std::cos(a), 0, 0));
  return Sim3(SE3(R_wc, center).inverse());
}

// Odometry edges and one loop edge (n-1 -> 0), all from the truth; the initial guess chains the
// odometry with a small systematic error per step in rotation, translation and log scale.
Graph drifted_circle(int n) {
  Graph g;
  for (int k = 0; k < n; ++k) g.truth.push_back(circle_pose(k, n));
  for (int k = 0; k + 1 < n; ++k) g.edges.push_back(edge_from(g.truth, k, k + 1));
  g.edges.push_back(edge_from(g.truth, n - 1, 0));
  g.initial.push_back(g.truth[0]);
  for (int k = 0; k + 1 < n; ++k) {
    Vec7 drift;
    drift << 0.02 * std::sin(k), 0.02 * std::cos(1.3 * k), 0.01, 0.004 * std::sin(2.0 * k),
        0.004 * std::cos(k), 0.003, 0.01;
    g.initial.push_back(Sim3::exp(drift) * g.edges[k].S_ji * g.initial.back());
  }
  return g;
}

Vec3 camera_center(const Sim3& S_cw) {
  return S_cw.inverse().translation();
}

double max_center_error(const std::vector<Sim3>& a, const std::vector<Sim3>& b) {
  double worst = 0.0;
  for (std::size_t k = 0; k < a.size(); ++k)
    worst = std::max(worst, (camera_center(a[k]) - camera_center(b[k])).norm());
  return worst;
}

void expect_bit_identical(const Sim3& a, const Sim3& b) {
  EXPECT_EQ(a.scale(), b.scale());
  for (int c = 0; c < 4; ++c)
    EXPECT_EQ(a.so3().quaternion().coeffs()[c], b.so3().quaternion().coeffs()[c]);
  for (int c = 0; c < 3; ++c) EXPECT_EQ(a.translation()[c], b.translation()[c]);
}

TEST(PoseGraph, LoopEdgeRemovesAccumulatedDrift) {
  const Graph g = drifted_circle(50);
  std::vector<Sim3> poses = g.initial;
  std::vector<bool> fixed(poses.size(), false);
  fixed[0] = true;
  const PoseGraphReport report = optimize_pose_graph(poses, fixed, g.edges, PoseGraphOptions());
  const double before = max_center_error(g.initial, g.truth);
  const double after = max_center_error(poses, g.truth);
  EXPECT_GT(before, 1.0);
  EXPECT_LT(after, before / 10.0);
  EXPECT_LT(after, 1e-4);  // consistent measurements: the truth is the optimum
  EXPECT_LT(report.final_cost, report.initial_cost);
  EXPECT_LT(report.final_cost, 1e-10);
  for (std::size_t k = 0; k < poses.size(); ++k) {
    EXPECT_NEAR(poses[k].scale(), 1.0, 1e-5) << k;
    EXPECT_LT((poses[k].so3() * g.truth[k].so3().inverse()).angle(), 1e-5) << k;
  }
}

// Vertices with large rotations and scales far from 1, edges exactly consistent with them.
std::vector<Sim3> scattered_vertices(int n) {
  std::vector<Sim3> v;
  for (int k = 0; k < n; ++k) {
    const Vec3 phi(std::sin(k), 2.0 * std::cos(0.7 * k), 0.5 * k);
    const Vec3 t(3.0 * std::sin(1.1 * k), k, -2.0 * std::cos(k));
    v.emplace_back(std::exp(0.8 * std::sin(0.3 * k)), SO3::exp(phi), t);
  }
  return v;
}

std::vector<PoseGraphEdge> chain_and_chords(const std::vector<Sim3>& v) {
  std::vector<PoseGraphEdge> edges;
  for (std::size_t k = 0; k + 1 < v.size(); ++k) edges.push_back(edge_from(v, k, k + 1));
  for (std::size_t k = 0; k + 3 < v.size(); k += 2) edges.push_back(edge_from(v, k + 3, k));
  return edges;
}

TEST(PoseGraph, ConsistentEdgesMoveNothing) {
  for (bool fix_scale : {false, true}) {
    const std::vector<Sim3> initial = scattered_vertices(12);
    std::vector<Sim3> poses = initial;
    std::vector<bool> fixed(poses.size(), false);
    fixed[0] = true;
    PoseGraphOptions options;
    options.fix_scale = fix_scale;
    const PoseGraphReport report =
        optimize_pose_graph(poses, fixed, chain_and_chords(initial), options);
    EXPECT_LT(report.initial_cost, 1e-20) << fix_scale;
    for (std::size_t k = 0; k < poses.size(); ++k)
      EXPECT_LT((poses[k].matrix() - initial[k].matrix()).cwiseAbs().maxCoeff(), 1e-9)
          << k << " fix_scale " << fix_scale;
  }
}

TEST(PoseGraph, FixScaleKeepsEveryScale) {
  Graph g = drifted_circle(30);
  // Scales unlike each other, near e, where exp(log(s)) often differs from s in the last bit.
  for (std::size_t k = 0; k < g.initial.size(); ++k)
    g.initial[k] =
        Sim3(2.7 + 0.05 * std::sin(double(k)), g.initial[k].so3(), g.initial[k].translation());
  std::vector<Sim3> poses = g.initial;
  std::vector<bool> fixed(poses.size(), false);
  fixed[0] = true;
  PoseGraphOptions options;
  options.fix_scale = true;
  const PoseGraphReport report = optimize_pose_graph(poses, fixed, g.edges, options);
  EXPECT_LT(report.final_cost, 0.5 * report.initial_cost);
  for (std::size_t k = 0; k < poses.size(); ++k) EXPECT_EQ(poses[k].scale(), g.initial[k].scale());
  EXPECT_GT((camera_center(poses[20]) - camera_center(g.initial[20])).norm(), 0.1);
}

TEST(PoseGraph, FixedVerticesStayBitIdentical) {
  for (bool fix_scale : {false, true}) {
    Graph g = drifted_circle(40);
    // A scale that exp(log(s)) does not give back: writing fixed vertices back would show.
    g.initial[13] = Sim3(2.731, g.initial[13].so3(), g.initial[13].translation());
    std::vector<Sim3> poses = g.initial;
    std::vector<bool> fixed(poses.size(), false);
    for (std::size_t k : {0, 13, 27}) fixed[k] = true;
    PoseGraphOptions options;
    options.fix_scale = fix_scale;
    optimize_pose_graph(poses, fixed, g.edges, options);
    for (std::size_t k : {0, 13, 27}) expect_bit_identical(poses[k], g.initial[k]);
    EXPECT_GT(max_center_error(poses, g.initial), 0.1);  // the free vertices did move
  }
}

// Two edges disagree on where vertex 1 is: with fixed scale the error is the translation
// difference, and the optimum is the weighted mean.
TEST(PoseGraph, WeightsPullTowardsTheHeavierEdge) {
  std::vector<Sim3> poses(2);
  const std::vector<bool> fixed = {true, false};
  std::vector<PoseGraphEdge> edges(2);
  edges[0].j = edges[1].j = 1;
  edges[0].S_ji = Sim3(1.0, SO3(), Vec3(1.0, 0.0, 0.0));
  edges[1].S_ji = Sim3(1.0, SO3(), Vec3(3.0, 0.0, 0.0));
  edges[1].weight = 3.0;
  PoseGraphOptions options;
  options.fix_scale = true;
  optimize_pose_graph(poses, fixed, edges, options);
  EXPECT_LT((poses[1].translation() - Vec3(2.5, 0.0, 0.0)).norm(), 1e-6);  // unweighted: 2
  EXPECT_LT(poses[1].so3().angle(), 1e-6);
}

// The autodiff residual against core/lie.h's logs, from tiny errors to rotations near pi and
// relative scales of e^+-3 (which take the closed-form branch of the sim(3) log).
TEST(PoseGraph, CostIsTheWeightedLogOfTheRelativeTransform) {
  const std::vector<Sim3> v = {
      Sim3(1.0, SO3(), Vec3(0.1, 0.2, 0.3)), Sim3(std::exp(3.0), SO3(), Vec3(-1.0, 0.5, 2.0)),
      Sim3(0.7, SO3::exp(Vec3(3.0, 0.2, -0.1)), Vec3(4.0, -1.0, 0.0)),
      Sim3(std::exp(-3.0), SO3::exp(Vec3(0.0, 1e-7, 0.0)), Vec3(0.0, 0.0, 1.0)),
      Sim3(1.0 + 1e-9, SO3::exp(Vec3(1e-9, 0.0, 2e-9)), Vec3(0.1, 0.2, 0.3 + 1e-9))};
  std::vector<PoseGraphEdge> edges;
  for (std::size_t i = 0; i < v.size(); ++i)
    for (std::size_t j = 0; j < v.size(); ++j)
      if (i != j) {
        PoseGraphEdge e;
        e.i = i;
        e.j = j;
        e.S_ji = Sim3(1.0 + 0.1 * i, SO3::exp(Vec3(0.3 * j, 0.0, 0.1)), Vec3(0.0, 1.0, 0.0));
        if ((i + j) % 3 == 0) e.S_ji = Sim3();
        e.weight = 0.5 + double(i) + 0.25 * double(j);
        edges.push_back(e);
      }
  for (bool fix_scale : {false, true}) {
    double expected = 0.0;
    for (const PoseGraphEdge& e : edges) {
      const Sim3 S = e.S_ji * v[e.i] * v[e.j].inverse();
      const double sq =
          fix_scale ? SE3(S.so3(), S.translation()).log().squaredNorm() : S.log().squaredNorm();
      expected += e.weight * sq;
    }
    std::vector<Sim3> poses = v;
    PoseGraphOptions options;
    options.fix_scale = fix_scale;
    options.iterations = 0;
    const PoseGraphReport report =
        optimize_pose_graph(poses, std::vector<bool>(v.size(), false), edges, options);
    EXPECT_NEAR(report.initial_cost, expected, 1e-10 * expected) << fix_scale;
  }
}

TEST(PoseGraph, InconsistentInputThrows) {
  std::vector<Sim3> poses(3);
  const std::vector<bool> fixed(3, false);
  std::vector<PoseGraphEdge> edges(1);
  edges[0].j = 3;
  test::expect_error_naming([&] { optimize_pose_graph(poses, fixed, edges, {}); }, "edge 0");
  edges[0].j = 0;
  test::expect_error_naming([&] { optimize_pose_graph(poses, fixed, edges, {}); }, "itself");
  edges[0].j = 1;
  edges[0].weight = -1.0;
  test::expect_error_naming([&] { optimize_pose_graph(poses, fixed, edges, {}); }, "weight");
  edges[0].weight = 1.0;
  test::expect_error_naming(
      [&] { optimize_pose_graph(poses, std::vector<bool>(2, false), edges, {}); }, "fixed flags");
  poses[2] = Sim3(0.0, SO3(), Vec3::Zero());
  test::expect_error_naming([&] { optimize_pose_graph(poses, fixed, edges, {}); }, "scale");
}

TEST(PoseGraph, TwoRunsAreBitIdentical) {
  const Graph g = drifted_circle(60);
  std::vector<PoseGraphEdge> edges = g.edges;
  for (std::size_t k = 0; k + 5 < g.truth.size(); k += 4) {  // slightly inconsistent extra edges
    PoseGraphEdge e = edge_from(g.truth, k, k + 5);
    e.S_ji = Sim3::exp(Vec7::Constant(0.001 * std::sin(double(k)))) * e.S_ji;
    edges.push_back(e);
  }
  std::vector<bool> fixed(g.initial.size(), false);
  fixed[0] = true;
  std::vector<Sim3> first = g.initial, second = g.initial;
  const PoseGraphReport r1 = optimize_pose_graph(first, fixed, edges, {});
  const PoseGraphReport r2 = optimize_pose_graph(second, fixed, edges, {});
  EXPECT_EQ(r1.final_cost, r2.final_cost);
  EXPECT_EQ(r1.iterations, r2.iterations);
  for (std::size_t k = 0; k < first.size(); ++k) expect_bit_identical(first[k], second[k]);
}

}  // namespace
}  // namespace sbaslam::optimize
