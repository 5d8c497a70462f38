// Loop candidates from the inverted index on hand-made BoWs: a trip through places A, B, C that
// comes back to A. Word ids stand for what the keyframes see; covisibility is set by hand.

#include "sbaslam/loop/keyframe_database.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

#include "helper/camera_rig.h"
#include "sbaslam/map/map.h"

namespace sbaslam::loop {
namespace {

using map::KeyFrame;
using Result = std::vector<KeyFrame*>;

// Equal weights on words [first, last) and the extra words, L1-normalised.
BowVector words(WordId first, WordId last, std::vector<WordId> extra = {}) {
  for (WordId w = first; w < last; ++w) extra.push_back(w);
  BowVector bow;
  for (WordId w : extra) bow[w] = 1.0 / static_cast<double>(extra.size());
  return bow;
}

class KeyFrameDatabaseTest : public ::testing::Test {
 protected:
  void SetUp() override {
    // Place A seen by three covisible keyframes, kf1 best of all; then B and C.
    kf_ = {add(words(0, 25, {200, 201, 202, 203, 204})),
           add(words(0, 30)),
           add(words(5, 30, {210, 211, 212, 213, 214, 215, 216, 217, 218, 219, 220, 221})),
           add(words(100, 130)),
           add(words(105, 135)),
           add(words(300, 330)),
           add(words(305, 335))};
    connect(kf_[0], kf_[1], 50);
    connect(kf_[1], kf_[2], 40);
    connect(kf_[0], kf_[2], 30);
    connect(kf_[3], kf_[4], 50);
    connect(kf_[5], kf_[6], 50);
    // Back at A, coming from C.
    query_ = add(words(0, 30, {330, 331, 332, 333, 334}));
    connect(query_, kf_[6], 20);
  }

  KeyFrame* add(BowVector bow, bool file = true) {
    KeyFrame* kf = map_.create_keyframe(frame_id_, 0.1 * static_cast<double>(frame_id_), SE3(),
                                        std::make_shared<map::Measurements>(), &rig_);
    ++frame_id_;
    if (file) db_.add(kf, std::move(bow));
    return kf;
  }

  // Three keyframes seeing one place, connected as kf0-kf2 are; returns the middle one.
  KeyFrame* add_covisible_visit(BowVector first, BowVector middle, BowVector last) {
    KeyFrame* a = add(std::move(first));
    KeyFrame* b = add(std::move(middle));
    KeyFrame* c = add(std::move(last));
    connect(a, b, 50);
    connect(b, c, 40);
    connect(a, c, 30);
    return b;
  }

  static void connect(KeyFrame* a, KeyFrame* b, int weight) {
    a->add_connection(b, weight);
    b->add_connection(a, weight);
  }

  Result detect(std::set<const KeyFrame*> also_excluded = {}, double min_score = 0.0) const {
    also_excluded.insert(query_);
    also_excluded.insert(kf_[6]);  // the query's connected keyframe
    return db_.detect_loop_candidates(query_, also_excluded, min_score);
  }

  double score_with_query(const KeyFrame* kf) const {
    return Vocabulary::score(*db_.bow_of(query_), *db_.bow_of(kf));
  }

  map::CameraRig rig_ = test::vga_mono_rig();
  map::Map map_;
  std::size_t frame_id_ = 0;
  KeyFrameDatabase db_;
  std::vector<KeyFrame*> kf_;
  KeyFrame* query_ = nullptr;
};

TEST_F(KeyFrameDatabaseTest, FindsTheRevisitedPlaceThroughItsBestKeyframe) {
  EXPECT_EQ(db_.size(), 8u);
  EXPECT_EQ(detect(), Result{kf_[1]});
  EXPECT_GT(score_with_query(kf_[1]), score_with_query(kf_[0]));
  EXPECT_GT(score_with_query(kf_[0]), 0.5);
  EXPECT_EQ(score_with_query(kf_[3]), 0.0);
}

TEST_F(KeyFrameDatabaseTest, LeavesOutExcludedAndBadKeyframes) {
  const Result without_kf1 = detect({kf_[1]});
  ASSERT_FALSE(without_kf1.empty());
  for (KeyFrame* kf : without_kf1) EXPECT_TRUE(kf == kf_[0] || kf == kf_[2]) << kf->id();
  // The query's connected keyframe kf6 shares words with it but is never a candidate.
  EXPECT_TRUE(db_.detect_loop_candidates(query_, {query_}, 0.0) == Result{kf_[1]});

  kf_[1]->set_bad();
  ASSERT_TRUE(kf_[1]->is_bad());
  EXPECT_EQ(detect(), without_kf1);
  kf_[0]->set_bad();
  kf_[2]->set_bad();
  EXPECT_TRUE(detect().empty());
}

TEST_F(KeyFrameDatabaseTest, KeepsOnlyKeyframesScoringAtLeastTheMinimum) {
  const double best = score_with_query(kf_[1]);
  EXPECT_EQ(detect({}, best), Result{kf_[1]});
  EXPECT_TRUE(detect({}, std::nextafter(best, 2.0)).empty());
  // Without kf1, kf0 and kf2 score alike; a minimum between the two keeps only the better one.
  const double s0 = score_with_query(kf_[0]), s2 = score_with_query(kf_[2]);
  ASSERT_NE(s0, s2);
  const Result one = detect({kf_[1]}, 0.5 * (s0 + s2));
  EXPECT_EQ(one, Result{s0 > s2 ? kf_[0] : kf_[2]});
}

TEST_F(KeyFrameDatabaseTest, ALoneLookalikeLosesToACovisibleGroup) {
  // As similar to the query as kf0 (25/35), but no neighbour backs it up: 0.71 is under
  // 0.75 x 2.25, the pooled score of kf0, kf1 and kf2.
  KeyFrame* lone = add(words(0, 25, {400, 401, 402, 403, 404}));
  EXPECT_NEAR(score_with_query(lone), score_with_query(kf_[0]), 1e-12);
  EXPECT_EQ(detect(), Result{kf_[1]});
  // A second visit of A as strong as the first is kept too, both by id.
  KeyFrame* b = add_covisible_visit(words(0, 25, {500}), words(0, 30), words(5, 30, {501}));
  EXPECT_EQ(detect(), (Result{kf_[1], b}));
}

// A lost frame that sees place A. Relocalisation searches the map the frame was tracked in, and
// tries the best-pooled place first (loop detection returns its candidates by id).
TEST_F(KeyFrameDatabaseTest, RelocalisationSearchesOnlyTheTrackedMapBestFirst) {
  const BowVector seen = words(0, 30);
  KeyFrame* other_map =
      map_.create_keyframe(99, 9.9, SE3(), std::make_shared<map::Measurements>(), &rig_, 1);
  db_.add(other_map, seen);  // A exactly as the frame sees it, but in a map of its own
  EXPECT_EQ(db_.detect_relocalization_candidates(seen, 0), Result{kf_[1]});
  EXPECT_EQ(db_.detect_relocalization_candidates(seen, 1), Result{other_map});
  EXPECT_TRUE(db_.detect_relocalization_candidates(words(600, 630), 0).empty());

  // A later visit of A that looks more like the frame than the first visit does.
  KeyFrame* b = add_covisible_visit(words(0, 30, {500}), words(0, 30), words(0, 30, {501}));
  EXPECT_EQ(db_.detect_relocalization_candidates(seen, 0), (Result{b, kf_[1]}));
  // Loop detection returns its candidates by id.
  const Result loop = detect();
  EXPECT_TRUE(std::is_sorted(loop.begin(), loop.end(), map::KeyFrameIdLess()));
  EXPECT_EQ(std::count(loop.begin(), loop.end(), b), 1);
}

TEST_F(KeyFrameDatabaseTest, SharingFewWordsIsNotEnough) {
  // Four covisible keyframes sharing 20 of the query's words (not more than 0.8 x 30): each would
  // score 20/35 and pool 2.29, enough to be kept, had they shared enough words to be scored.
  std::vector<KeyFrame*> partial;
  for (WordId extra = 600; extra < 604; ++extra) partial.push_back(add(words(0, 20, {extra})));
  for (std::size_t i = 0; i < partial.size(); ++i)
    for (std::size_t j = i + 1; j < partial.size(); ++j) connect(partial[i], partial[j], 30);
  EXPECT_NEAR(score_with_query(partial[0]), 20.0 / 35.0, 1e-12);
  EXPECT_EQ(detect(), Result{kf_[1]});
}

TEST_F(KeyFrameDatabaseTest, EraseAndReAddChangeWhatIsFound) {
  db_.erase(kf_[1]);
  EXPECT_EQ(db_.size(), 7u);
  EXPECT_EQ(db_.bow_of(kf_[1]), nullptr);
  Result found = detect();
  ASSERT_FALSE(found.empty());
  for (KeyFrame* kf : found) EXPECT_NE(kf, kf_[1]);

  db_.add(kf_[1], words(100, 130));  // now filed under B's words only
  EXPECT_EQ(db_.size(), 8u);
  EXPECT_EQ(db_.bow_of(kf_[1])->count(0), 0u);
  for (KeyFrame* kf : detect()) EXPECT_NE(kf, kf_[1]);

  db_.clear();
  EXPECT_EQ(db_.size(), 0u);
  EXPECT_THROW(detect(), std::logic_error);
}

TEST_F(KeyFrameDatabaseTest, QueriesWithAGivenBowBeforeFiling) {
  const BowVector bow = words(0, 30);
  KeyFrame* unfiled = add(bow, false);
  EXPECT_THROW(db_.detect_loop_candidates(unfiled, {unfiled}, 0.0), std::logic_error);
  EXPECT_EQ(db_.detect_loop_candidates(unfiled, bow, {unfiled, query_}, 0.0), Result{kf_[1]});
}

TEST_F(KeyFrameDatabaseTest, ScoresEqualTheVocabularysScoreToTheLastBit) {
  // Uneven weights, so that a different order of summation would show in the last bits.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> weight(0.1, 1.0);
  std::uniform_int_distribution<WordId> word(0, 60);
  const auto random_bow = [&] {
    BowVector bow;
    for (int i = 0; i < 40; ++i) bow[word(rng)] = weight(rng);
    double sum = 0.0;
    for (const auto& [w, x] : bow) sum += x;
    for (auto& [w, x] : bow) x /= sum;
    return bow;
  };
  std::vector<const KeyFrame*> keyframes;
  for (int i = 0; i < 20; ++i) keyframes.push_back(add(random_bow()));
  keyframes.push_back(add(words(500, 510)));      // filed, sharing no word
  keyframes.push_back(add(words(0, 30), false));  // not filed
  const BowVector query = random_bow();
  const std::vector<double> scores = db_.scores(query, keyframes);
  ASSERT_EQ(scores.size(), keyframes.size());
  for (std::size_t i = 0; i < 20; ++i) {
    EXPECT_EQ(scores[i], Vocabulary::score(query, *db_.bow_of(keyframes[i]))) << i;
    EXPECT_GT(scores[i], 0.0) << i;
  }
  EXPECT_EQ(scores[20], 0.0);
  EXPECT_EQ(scores[21], 0.0);
}

}  // namespace
}  // namespace sbaslam::loop
