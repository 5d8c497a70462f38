#include "sbaslam/loop/keyframe_database.h"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <unordered_map>

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
  for (const auto& [word, weight] : bow) keyframes_with_word_[word].insert(kf);
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
    const auto posting = keyframes_with_word_.find(word);
    if (posting == keyframes_with_word_.end()) continue;
    posting->second.erase(kf);
    if (posting->second.empty()) keyframes_with_word_.erase(posting);
  }
  bows_.erase(it);
}

void KeyFrameDatabase::clear() {
  std::lock_guard<std::mutex> lock(mutex_);
  bows_.clear();
  keyframes_with_word_.clear();
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

KeyFrameDatabase::Scores KeyFrameDatabase::score_sharing_keyframes(
    const map::KeyFrame* kf, const BowVector& bow,
    const std::set<const map::KeyFrame*>& excluded) const {
  // Counting first and filtering after tests each keyframe once, not once per shared word.
  std::unordered_map<const map::KeyFrame*, int> shared;
  for (const auto& [word, weight] : bow) {
    const auto posting = keyframes_with_word_.find(word);
    if (posting == keyframes_with_word_.end()) continue;
    for (const map::KeyFrame* other : posting->second) ++shared[other];
  }
  int most_shared = 0;
  for (auto it = shared.begin(); it != shared.end();) {
    const map::KeyFrame* other = it->first;
    if (other == kf || excluded.count(other) || other->is_bad()) {
      it = shared.erase(it);
    } else {
      most_shared = std::max(most_shared, it->second);
      ++it;
    }
  }
  Scores scores;
  for (const auto& [other, count] : shared)
    if (count > kMinSharedWordsRatio * most_shared)
      scores[const_cast<map::KeyFrame*>(other)] = Vocabulary::score(bow, bows_.at(other));
  return scores;
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
  const Scores scores = score_sharing_keyframes(kf, bow, excluded);
  // Pooling over covisibles favours a place seen by several keyframes over one lucky match.
  std::vector<std::pair<double, map::KeyFrame*>> groups;
  double best_group = 0.0;
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
    best_group = std::max(best_group, pooled);
  }
  std::set<map::KeyFrame*, map::KeyFrameIdLess> kept;
  for (const auto& [pooled, best] : groups)
    if (pooled >= kMinGroupScoreRatio * best_group) kept.insert(best);
  return {kept.begin(), kept.end()};
}

}  // namespace sbaslam::loop
