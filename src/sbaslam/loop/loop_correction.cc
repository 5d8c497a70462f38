#include "sbaslam/loop/loop_correction.h"

#include <functional>
#include <map>
#include <set>
#include <unordered_map>
#include <unordered_set>
#include <utility>

#include "sbaslam/mapping/fusion.h"
#include "sbaslam/optimize/pose_graph.h"

namespace sbaslam::loop {
namespace {

using KeyFrameSims = std::map<map::KeyFrame*, Sim3, map::KeyFrameIdLess>;
using KeyFrameSet = std::set<map::KeyFrame*, map::KeyFrameIdLess>;

constexpr double kLoopFuseRadius = 4.0;  // ORB-SLAM's th in SearchAndFuse

// The root of kf's spanning tree. A path longer than the map has keyframes would be a cycle,
// which the tree's updates are meant never to make; such a keyframe counts as its own root.
const map::KeyFrame* root_of(const map::KeyFrame* kf, std::size_t keyframes) {
  const map::KeyFrame* node = kf;
  for (std::size_t steps = 0; node->parent(); ++steps) {
    if (steps > keyframes) return kf;
    node = node->parent();
  }
  return node;
}

SE3 rigid_part(const Sim3& S) {
  return SE3(S.so3(), S.translation() / S.scale());
}

// The keyframe's neighbourhood moved with it: each keeps its pose relative to the current one.
// Keyframes that tracking made after the current one and local mapping has not linked yet (no
// parent): they sit beside the current keyframe, so they move with it.
bool awaiting_mapping(const map::KeyFrame& kf, const map::KeyFrame& current) {
  return !kf.is_bad() && !kf.parent() && !kf.is_origin() && kf.id() > current.id();
}

KeyFrameSims corrected_neighbourhood(const DetectedLoop& loop, const map::Map& map) {
  KeyFrameSims corrected;
  const SE3 T_wc = loop.current->T_wc();
  corrected[loop.current] = loop.S_cw;
  std::vector<map::KeyFrame*> neighbours = loop.current->covisibles();
  for (map::KeyFrame* kf : map.keyframes())
    if (awaiting_mapping(*kf, *loop.current)) neighbours.push_back(kf);
  for (map::KeyFrame* kf : neighbours)
    if (!kf->is_bad()) corrected[kf] = Sim3(kf->T_cw() * T_wc) * loop.S_cw;
  return corrected;
}

// Moves the neighbourhood's points and poses; returns which keyframe moved each point.
std::unordered_map<map::MapPoint*, map::KeyFrame*> move_neighbourhood(
    const KeyFrameSims& corrected) {
  std::unordered_map<map::MapPoint*, map::KeyFrame*> moved_by;
  for (const auto& [kf, S_new] : corrected) {
    const Sim3 motion = S_new.inverse() * Sim3(kf->T_cw());
    for (map::MapPoint* mp : kf->map_points()) {
      if (!mp || mp->is_bad() || moved_by.count(mp)) continue;
      mp->set_position(motion * mp->position());
      moved_by[mp] = kf;
    }
  }
  for (const auto& [kf, S_new] : corrected) kf->set_pose(rigid_part(S_new));
  for (const auto& [mp, kf] : moved_by) mp->update_normal_and_depth();
  return moved_by;
}

std::size_t fuse_loop_points(const DetectedLoop& loop, const KeyFrameSims& corrected) {
  std::size_t fused = 0;
  map::KeyFrame* current = loop.current;
  for (std::size_t i = 0; i < loop.matched.size(); ++i) {
    map::MapPoint* loop_point = loop.matched[i];
    if (!loop_point || loop_point->is_bad()) continue;
    map::MapPoint* existing = current->map_point(i);
    if (existing == loop_point) continue;
    if (existing && !existing->is_bad()) {
      existing->replace_with(loop_point);
    } else if (!loop_point->is_in_keyframe(current)) {
      current->add_map_point(loop_point, i);
      loop_point->add_observation(current, i);
      loop_point->update_descriptor();
    }
    ++fused;
  }
  for (const auto& [kf, S] : corrected)
    fused += static_cast<std::size_t>(
        mapping::fuse_into_keyframe(kf, loop.loop_points, kLoopFuseRadius));
  return fused;
}

// Covisibility links that the fusion created across the loop, per neighbourhood keyframe.
std::map<map::KeyFrame*, KeyFrameSet, map::KeyFrameIdLess> new_links(
    const KeyFrameSims& corrected) {
  std::map<map::KeyFrame*, KeyFrameSet, map::KeyFrameIdLess> links;
  for (const auto& [kf, S] : corrected) {
    const std::vector<map::KeyFrame*> previous = kf->covisibles();
    kf->update_connections();
    KeyFrameSet added;
    for (map::KeyFrame* other : kf->covisibles()) added.insert(other);
    for (map::KeyFrame* other : previous) added.erase(other);
    for (const auto& [neighbour, S_n] : corrected) added.erase(neighbour);
    links[kf] = std::move(added);
  }
  return links;
}

class EssentialGraph {
 public:
  EssentialGraph(const std::vector<map::KeyFrame*>& keyframes, const KeyFrameSims& original,
                 const KeyFrameSims& corrected) {
    for (map::KeyFrame* kf : keyframes) {
      index_[kf] = vertices_.size();
      const auto c = corrected.find(kf);
      vertices_.push_back(c != corrected.end() ? c->second : Sim3(kf->T_cw()));
      const auto o = original.find(kf);
      original_.push_back(o != original.end() ? o->second : Sim3(kf->T_cw()));
      built_from_.push_back(kf->T_cw());
    }
    initial_ = vertices_;
  }

  bool contains(const map::KeyFrame* kf) const { return index_.count(kf) > 0; }
  std::size_t index(const map::KeyFrame* kf) const { return index_.at(kf); }
  std::size_t edge_count() const { return edges_.size(); }

  // Measured by the poses before the correction (odometry) or after it (new loop links).
  void add_edge(map::KeyFrame* a, map::KeyFrame* b, bool corrected_measurement) {
    if (!contains(a) || !contains(b) || a == b) return;
    const std::size_t i = index(a), j = index(b);
    if (!pairs_.insert({std::min(i, j), std::max(i, j)}).second) return;
    const std::vector<Sim3>& poses = corrected_measurement ? initial_ : original_;
    edges_.push_back({i, j, poses[j] * poses[i].inverse(), 1.0});
  }

  optimize::PoseGraphReport optimize(map::KeyFrame* fixed_kf, bool fix_scale) {
    std::vector<bool> fixed(vertices_.size(), false);
    fixed[index(fixed_kf)] = true;
    optimize::PoseGraphOptions options;
    options.fix_scale = fix_scale;
    return optimize::optimize_pose_graph(vertices_, fixed, edges_, options);
  }

  const Sim3& before(std::size_t i) const { return initial_[i]; }
  const Sim3& after(std::size_t i) const { return vertices_[i]; }
  const SE3& pose_at_build(std::size_t i) const { return built_from_[i]; }

 private:
  std::unordered_map<const map::KeyFrame*, std::size_t> index_;
  std::vector<SE3> built_from_;  // each keyframe's pose when the graph was built
  std::vector<Sim3> vertices_, initial_, original_;
  std::vector<optimize::PoseGraphEdge> edges_;
  std::set<std::pair<std::size_t, std::size_t>> pairs_;
};

void add_odometry_edges(EssentialGraph& graph, const std::vector<map::KeyFrame*>& keyframes) {
  for (map::KeyFrame* kf : keyframes) {
    if (kf->parent()) graph.add_edge(kf, kf->parent(), false);
    for (map::KeyFrame* other : kf->loop_edges())
      if (other->id() < kf->id()) graph.add_edge(kf, other, false);
    for (map::KeyFrame* other : kf->covisibles_with_weight_at_least(kEssentialGraphMinWeight))
      if (other->id() < kf->id() && !other->is_bad()) graph.add_edge(kf, other, false);
  }
}

// Which graph vertex's correction each keyframe takes: its own, else its nearest ancestor's in the
// spanning tree; a keyframe without a parent made after the current one (tracking made it during
// the solve, or mapping has not linked it yet) takes the current keyframe's. Keyframes of another
// map take none.
using VertexOf = std::unordered_map<const map::KeyFrame*, std::size_t>;

VertexOf vertex_sources(const map::Map& map, const EssentialGraph& graph,
                        const map::KeyFrame& current) {
  VertexOf source;
  const std::size_t current_vertex = graph.index(&current);
  for (map::KeyFrame* kf : map.keyframes()) {
    if (kf->is_bad()) continue;
    const map::KeyFrame* node = kf;
    for (std::size_t steps = 0; node && !graph.contains(node); ++steps)
      node = steps > map.keyframe_count() ? nullptr : node->parent();
    if (node) {
      source[kf] = graph.index(node);
    } else if (awaiting_mapping(*kf, current)) {
      source[kf] = current_vertex;
    }
  }
  return source;
}

// Every keyframe takes its vertex's correction. One the solve's window left as it was gets the
// solved pose itself; one that local mapping moved meanwhile keeps that move on top of it.
void move_keyframes(const map::Map& map, const EssentialGraph& graph, const VertexOf& source) {
  for (map::KeyFrame* kf : map.keyframes()) {
    const auto s = source.find(kf);
    if (s == source.end()) continue;
    const std::size_t v = s->second;
    const bool own_vertex = graph.contains(kf) && graph.index(kf) == v;
    if (own_vertex && kf->T_cw().matrix() == graph.pose_at_build(v).matrix()) {
      kf->set_pose(rigid_part(graph.after(v)));
    } else {
      kf->set_pose(rigid_part(Sim3(kf->T_cw()) * graph.before(v).inverse() * graph.after(v)));
    }
  }
}

// Every point follows the keyframe that moved it, or else its reference keyframe, or else one
// that observes it.
void move_points(map::Map& map, const EssentialGraph& graph, const VertexOf& source,
                 const std::unordered_map<map::MapPoint*, map::KeyFrame*>& moved_by) {
  for (map::MapPoint* mp : map.map_points()) {
    const auto m = moved_by.find(mp);
    const map::KeyFrame* ref = m != moved_by.end() ? m->second : mp->reference_keyframe();
    auto s = ref ? source.find(ref) : source.end();
    for (auto o = mp->observations().begin(); s == source.end() && o != mp->observations().end();
         ++o)
      s = source.find(o->first);
    if (s == source.end()) continue;
    const std::size_t i = s->second;
    mp->set_position(graph.after(i).inverse() * (graph.before(i) * mp->position()));
    mp->update_normal_and_depth();
  }
}

// Reverses the path from `moving` (a keyframe of the map that moved) to its root, so `moving`
// becomes that tree's root, then hangs the tree from `staying`: the trees join at the loop.
void join_spanning_trees(map::KeyFrame* moving, map::KeyFrame* staying, std::size_t keyframes) {
  std::vector<map::KeyFrame*> path{moving};
  while (path.back()->parent() && path.size() <= keyframes) path.push_back(path.back()->parent());
  for (std::size_t i = 1; i < path.size(); ++i) {
    path[i]->erase_child(path[i - 1]);
    path[i]->change_parent(path[i - 1]);
  }
  moving->change_parent(staying);
}

}  // namespace

bool same_map(const map::Map& map, const map::KeyFrame& a, const map::KeyFrame& b) {
  return root_of(&a, map.keyframe_count()) == root_of(&b, map.keyframe_count());
}

LoopCorrectionReport correct_loop(map::Map& map, const DetectedLoop& loop, bool fix_scale,
                                  const SolveWindow& window) {
  LoopCorrectionReport report;
  loop.current->update_connections();
  const KeyFrameSims corrected = corrected_neighbourhood(loop, map);
  KeyFrameSims original;
  for (const auto& [kf, S] : corrected) original[kf] = Sim3(kf->T_cw());
  const auto moved_by = move_neighbourhood(corrected);
  report.moved_keyframes = corrected.size();
  report.fused_points = fuse_loop_points(loop, corrected);
  const auto links = new_links(corrected);

  std::vector<map::KeyFrame*> keyframes;
  const std::size_t count = map.keyframe_count();
  const map::KeyFrame* root = root_of(loop.loop, count);
  for (map::KeyFrame* kf : map.keyframes())
    if (!kf->is_bad() && (root_of(kf, count) == root || awaiting_mapping(*kf, *loop.current)))
      keyframes.push_back(kf);
  EssentialGraph graph(keyframes, original, corrected);
  // The loop itself, then the strong links the fusion made across it.
  graph.add_edge(loop.current, loop.loop, true);
  for (const auto& [kf, others] : links)
    for (map::KeyFrame* other : others)
      if (kf->connection_weight(other) >= kEssentialGraphMinWeight) graph.add_edge(kf, other, true);
  add_odometry_edges(graph, keyframes);
  // Not in the spanning tree yet: held to the current keyframe as it was.
  for (map::KeyFrame* kf : keyframes)
    if (awaiting_mapping(*kf, *loop.current)) graph.add_edge(kf, loop.current, false);
  // The neighbourhood has moved: tracking re-places its last frame, local mapping drops a BA it
  // solved across the move.
  map.notify_big_change();
  optimize::PoseGraphReport solved;
  const auto solve = [&] { solved = graph.optimize(loop.loop, fix_scale); };
  if (window) {
    window(solve);
  } else {
    solve();
  }

  const VertexOf source = vertex_sources(map, graph, *loop.current);
  move_keyframes(map, graph, source);
  move_points(map, graph, source, moved_by);
  loop.current->add_loop_edge(loop.loop);
  loop.loop->add_loop_edge(loop.current);
  map.notify_big_change();
  report.graph_keyframes = keyframes.size();
  report.graph_edges = graph.edge_count();
  report.graph_initial_cost = solved.initial_cost;
  report.graph_final_cost = solved.final_cost;
  return report;
}

MergePlan plan_merge(const map::Map& map, const DetectedLoop& loop) {
  MergePlan plan;
  const std::size_t count = map.keyframe_count();
  const map::KeyFrame* current_root = root_of(loop.current, count);
  const map::KeyFrame* loop_root = root_of(loop.loop, count);
  // The younger map moves, so the oldest map's world, which the trajectory is written in, and its
  // scale stay.
  plan.current_moves = current_root->id() > loop_root->id();
  plan.moving_root = plan.current_moves ? current_root : loop_root;
  // The current map's world to the loop's: both place the current keyframe's camera.
  const Sim3 current_to_loop = loop.S_cw.inverse() * Sim3(loop.current->T_cw());
  plan.S = plan.current_moves ? current_to_loop : current_to_loop.inverse();
  return plan;
}

MapMergeReport merge_maps(map::Map& map, const DetectedLoop& loop) {
  MapMergeReport report;
  const std::size_t count = map.keyframe_count();
  const MergePlan plan = plan_merge(map, loop);
  const bool current_moves = plan.current_moves;
  std::vector<map::KeyFrame*> merged;
  for (map::KeyFrame* kf : map.keyframes())
    if (!kf->is_bad() && (root_of(kf, count) == plan.moving_root ||
                          (current_moves && awaiting_mapping(*kf, *loop.current))))
      merged.push_back(kf);
  const Sim3& S = plan.S;
  const Sim3 S_inverse = S.inverse();
  std::unordered_set<map::MapPoint*> moved;
  for (map::KeyFrame* kf : merged)
    for (map::MapPoint* mp : kf->map_points())
      if (mp && !mp->is_bad() && moved.insert(mp).second) mp->set_position(S * mp->position());
  for (map::KeyFrame* kf : merged) {
    kf->set_pose(rigid_part(Sim3(kf->T_cw()) * S_inverse));
    kf->set_origin(false);
  }
  for (map::MapPoint* mp : moved) mp->update_normal_and_depth();
  report.moved_keyframes = merged.size();
  report.moved_points = moved.size();

  loop.current->update_connections();
  KeyFrameSims neighbourhood;
  neighbourhood[loop.current] = Sim3(loop.current->T_cw());
  for (map::KeyFrame* kf : loop.current->covisibles())
    if (!kf->is_bad()) neighbourhood[kf] = Sim3(kf->T_cw());
  report.fused_points = fuse_loop_points(loop, neighbourhood);
  new_links(neighbourhood);
  if (current_moves) {
    join_spanning_trees(loop.current, loop.loop, count);
  } else {
    join_spanning_trees(loop.loop, loop.current, count);
  }
  loop.current->add_loop_edge(loop.loop);
  loop.loop->add_loop_edge(loop.current);
  const map::KeyFrame* staying = current_moves ? loop.loop : loop.current;
  map.move_keyframes_to_map(plan.moving_root->map_id(), staying->map_id());
  map.notify_big_change();
  return report;
}

}  // namespace sbaslam::loop
