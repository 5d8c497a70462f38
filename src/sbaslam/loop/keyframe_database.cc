#include "sbaslam/loop/keyframe_database.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace sbaslam::loop {
namespace {

// ORB-SLAM2's constants: the share of the most shared words a candidate needs, the covisibles
// that pool their scores with it, and the share of the best pooled score a group needs.
constexpr double kMinSharedWordsRatio = 0.8;
constexpr std::size_t kGroupCovisibles = 10;
constexpr double kMinGroupScoreRatio = 0.75;

}  // namespace

void KeyFrameDatabase::add(const map::KeyFrame* kf, BowVector bow) {
  std::lock_guard<std::mutex> lock(mutex_);
  erase_locked(kf);
  for (const auto& [word, weight] : bow) {
    if (word >= postings_.size()) postings_.resize(word + 1);
    postings_[word].push_back({kf, weight});
  }
  id_bound_ = std::max(id_bound_, kf->id() + 1);
  bows_.emplace(kf, std::move(bow));
}

void KeyFrameDatabase::erase(const map::KeyFrame* kf) {
  std::lock_guard<std::mutex> lock(mutex_);
  erase_locked(kf);
}

void KeyFrameDatabase::erase_locked(const map::KeyFrame* kf) {
  const auto it = bows_.find(kf);
  if (it == bows_.end()) return;
  for (const auto& [word, weight] : it->second) {
    std::vector<Posting>& posting = postings_[word];
    posting.erase(std::find_if(posting.begin(), posting.end(),
                               [kf](const Posting& p) { return p.kf == kf; }));
  }
  bows_.erase(it);
}

void KeyFrameDatabase::clear() {
  std::lock_guard<std::mutex> lock(mutex_);
  bows_.clear();
  postings_.clear();
  id_bound_ = 0;
}

std::size_t KeyFrameDatabase::size() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return bows_.size();
}

const BowVector* KeyFrameDatabase::bow_of(const map::KeyFrame* kf) const {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = bows_.find(kf);
  return it == bows_.end() ? nullptr : &it->second;
}

std::vector<map::KeyFrame*> KeyFrameDatabase::detect_loop_candidates(
    const map::KeyFrame* kf, const std::set<const map::KeyFrame*>& excluded,
    double min_score) const {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = bows_.find(kf);
  // An absent query would silently find nothing, which looks like "no loop": fail loudly.
  if (it == bows_.end())
    throw std::logic_error("KeyFrameDatabase: keyframe " + std::to_string(kf->id()) +
                           " queried before it was added");
  return detect_locked(kf, it->second, excluded, min_score);
}

std::vector<KeyFrameDatabase::Shared> KeyFrameDatabase::share_words(
    const BowVector& bow, std::vector<std::size_t>& touched) const {
  std::vector<Shared> shared(id_bound_);
  // The query's words ascend, so each keyframe's sum adds its terms in the order
  // Vocabulary::score's merge does: the same value to the last bit.
  for (const auto& [word, a] : bow) {
    if (word >= postings_.size()) continue;
    for (const Posting& p : postings_[word]) {
      Shared& s = shared[p.kf->id()];
      if (s.words++ == 0) {
        s.kf = p.kf;
        touched.push_back(p.kf->id());
      }
      s.l1_sum += std::abs(a) + std::abs(p.weight) - std::abs(a - p.weight);
    }
  }
  return shared;
}

namespace {

double l1_score(double l1_sum) {
  return std::clamp(0.5 * l1_sum, 0.0, 1.0);
}

}  // namespace

std::vector<double> KeyFrameDatabase::scores(
    const BowVector& bow, const std::vector<const map::KeyFrame*>& keyframes) const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<std::size_t> touched;
  const std::vector<Shared> shared = share_words(bow, touched);
  std::vector<double> result;
  result.reserve(keyframes.size());
  for (const map::KeyFrame* kf : keyframes) {
    const bool filed = kf->id() < shared.size() && shared[kf->id()].kf == kf;
    result.push_back(filed ? l1_score(shared[kf->id()].l1_sum) : 0.0);
  }
  return result;
}

KeyFrameDatabase::Scores KeyFrameDatabase::score_sharing_keyframes(const BowVector& bow,
                                                                   const Skip& skip) const {
  std::vector<std::size_t> touched;
  const std::vector<Shared> shared = share_words(bow, touched);
  std::vector<const Shared*> kept;
  int most_shared = 0;
  for (const std::size_t id : touched) {
    const Shared& s = shared[id];
    if (s.kf->is_bad() || skip(s.kf)) continue;
    most_shared = std::max(most_shared, s.words);
    kept.push_back(&s);
  }
  Scores scores;
  for (const Shared* s : kept)
    if (s->words > kMinSharedWordsRatio * most_shared)
      scores[const_cast<map::KeyFrame*>(s->kf)] = l1_score(s->l1_sum);
  return scores;
}

KeyFrameDatabase::Groups KeyFrameDatabase::pool_over_covisibles(const Scores& scores,
                                                                double min_score) {
  // Pooling over covisibles favours a place seen by several keyframes over one lucky match.
  Groups groups;
  for (const auto& [candidate, score] : scores) {
    if (score < min_score) continue;
    double pooled = score, best_score = score;
    map::KeyFrame* best = candidate;
    for (map::KeyFrame* covisible : candidate->best_covisibles(kGroupCovisibles)) {
      const auto it = scores.find(covisible);
      if (it == scores.end()) continue;
      pooled += it->second;
      if (it->second > best_score) {
        best_score = it->second;
        best = covisible;
      }
    }
    groups.emplace_back(pooled, best);
  }
  return groups;
}

std::vector<map::KeyFrame*> KeyFrameDatabase::detect_loop_candidates(
    const map::KeyFrame* kf, const BowVector& bow, const std::set<const map::KeyFrame*>& excluded,
    double min_score) const {
  std::lock_guard<std::mutex> lock(mutex_);
  return detect_locked(kf, bow, excluded, min_score);
}

std::vector<map::KeyFrame*> KeyFrameDatabase::detect_locked(
    const map::KeyFrame* kf, const BowVector& bow, const std::set<const map::KeyFrame*>& excluded,
    double min_score) const {
  const Scores scores = score_sharing_keyframes(
      bow, [&](const map::KeyFrame* other) { return other == kf || excluded.count(other) > 0; });
  const Groups groups = pool_over_covisibles(scores, min_score);
  double best_group = 0.0;
  for (const auto& group : groups) best_group = std::max(best_group, group.first);
  std::set<map::KeyFrame*, map::KeyFrameIdLess> kept;
  for (const auto& [pooled, best] : groups)
    if (pooled >= kMinGroupScoreRatio * best_group) kept.insert(best);
  return {kept.begin(), kept.end()};
}

std::vector<map::KeyFrame*> KeyFrameDatabase::detect_relocalization_candidates(
    const BowVector& bow, std::size_t map_id) const {
  std::lock_guard<std::mutex> lock(mutex_);
  const Scores scores = score_sharing_keyframes(
      bow, [map_id](const map::KeyFrame* other) { return other->map_id() != map_id; });
  Groups groups = pool_over_covisibles(scores, 0.0);
  // Best first; ties by id, so the order is deterministic.
  std::sort(groups.begin(), groups.end(), [](const auto& a, const auto& b) {
    return a.first != b.first ? a.first > b.first : a.second->id() < b.second->id();
  });
  std::vector<map::KeyFrame*> candidates;
  for (const auto& [pooled, best] : groups) {
    if (pooled < kMinGroupScoreRatio * groups.front().first) break;
    if (std::find(candidates.begin(), candidates.end(), best) == candidates.end())
      candidates.push_back(best);
  }
  return candidates;
}

}  // namespace sbaslam::loop
