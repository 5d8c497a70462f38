#pragma once
// Place recognition's inverted index (ORB-SLAM2's KeyFrameDatabase): for each vocabulary word, the
// keyframes whose BoW holds it and their weight of it, so that a query visits only keyframes
// sharing a word with it and scores them all in that one pass (the L1 score sums over shared words
// only). The database keeps each keyframe's BoW itself; KeyFrame knows nothing of words.
//
// Thread-safety: every call takes the database's own mutex, so local mapping may add keyframes
// while the loop closer or tracking queries. The detect_* queries also read keyframes'
// covisibility, bad flags and map ids, so their callers hold the map lock.

#include <cstddef>
#include <functional>
#include <map>
#include <mutex>
#include <set>
#include <vector>

#include "sbaslam/loop/vocabulary.h"
#include "sbaslam/map/keyframe.h"

namespace sbaslam::loop {

class KeyFrameDatabase {
 public:
  // Files kf under the words of `bow`, replacing what it was filed under before.
  void add(const map::KeyFrame* kf, BowVector bow);
  void erase(const map::KeyFrame* kf);
  void clear();
  std::size_t size() const;
  // kf's BoW, or nullptr if absent. The pointer stays valid until kf is erased or re-added, or the
  // database cleared.
  const BowVector* bow_of(const map::KeyFrame* kf) const;

  // Loop candidates for kf (ORB-SLAM2's DetectLoopCandidates), queried with the BoW kf was added
  // with: kf must have been added (std::logic_error otherwise). The overload below takes the query
  // BoW instead, for a caller that files kf only after the query.
  //  1. Keyframes sharing a word with kf, other than kf, not in `excluded` and not bad.
  //  2. Those sharing more than 0.8 x the most shared words are scored (Vocabulary::score).
  //  3. Each one scoring >= min_score heads a group: itself and those of its 10 best covisibles
  //     that passed step 2 (as in ORB-SLAM2, whatever their score). The group's score is the sum of
  //     its members' scores; its best-scoring member represents it.
  //  4. Groups scoring >= 0.75 x the best group give their representatives, once each, by id.
  std::vector<map::KeyFrame*> detect_loop_candidates(const map::KeyFrame* kf,
                                                     const std::set<const map::KeyFrame*>& excluded,
                                                     double min_score) const;
  std::vector<map::KeyFrame*> detect_loop_candidates(const map::KeyFrame* kf, const BowVector& bow,
                                                     const std::set<const map::KeyFrame*>& excluded,
                                                     double min_score) const;

  // Relocalisation candidates for a frame's `bow` (ORB-SLAM3's DetectRelocalizationCandidates):
  // steps 1, 3 and 4 above with no score threshold, over the keyframes of map `map_id` only (a
  // lost frame is searched for in the map it was tracked in). Best pooled score first.
  std::vector<map::KeyFrame*> detect_relocalization_candidates(const BowVector& bow,
                                                               std::size_t map_id) const;

  // Vocabulary::score(bow, BoW of k) for each of `keyframes` (0 for one not filed or sharing no
  // word), in one pass over the index instead of one merge per keyframe.
  std::vector<double> scores(const BowVector& bow,
                             const std::vector<const map::KeyFrame*>& keyframes) const;

 private:
  struct Posting {
    const map::KeyFrame* kf;
    double weight;  // kf's tf-idf weight of the word
  };
  // What a query shares with one filed keyframe.
  struct Shared {
    const map::KeyFrame* kf = nullptr;
    int words = 0;
    double l1_sum = 0.0;  // sum over the shared words of |a| + |b| - |a - b|
  };
  using Scores = std::map<map::KeyFrame*, double, map::KeyFrameIdLess>;
  using Skip = std::function<bool(const map::KeyFrame*)>;
  // Step 3's groups: each scored keyframe's pooled score and its group's best member.
  using Groups = std::vector<std::pair<double, map::KeyFrame*>>;

  void erase_locked(const map::KeyFrame* kf);
  std::vector<map::KeyFrame*> detect_locked(const map::KeyFrame* kf, const BowVector& bow,
                                            const std::set<const map::KeyFrame*>& excluded,
                                            double min_score) const;
  // Indexed by keyframe id; the ids of the entries holding a keyframe.
  std::vector<Shared> share_words(const BowVector& bow, std::vector<std::size_t>& touched) const;
  // Steps 1 and 2: the scores of the keyframes sharing enough words with the query.
  Scores score_sharing_keyframes(const BowVector& bow, const Skip& skip) const;
  static Groups pool_over_covisibles(const Scores& scores, double min_score);

  mutable std::mutex mutex_;
  std::map<const map::KeyFrame*, BowVector, map::KeyFrameIdLess> bows_;
  std::vector<std::vector<Posting>> postings_;  // by word; unordered
  std::size_t id_bound_ = 0;                    // above every filed keyframe's id
};

}  // namespace sbaslam::loop
