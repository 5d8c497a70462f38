// The vocabulary on synthetic descriptors with a known cluster structure, its binary file, and
// real ORB features of the KITTI fixture.

#include "sbaslam/loop/vocabulary.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <map>
#include <numeric>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "helper/expect_error.h"
#include "helper/images.h"
#include "helper/temp_dir.h"
#include "sbaslam/feature/orb_extractor.h"

namespace sbaslam::loop {
namespace {

using Descriptor = std::array<std::uint8_t, 32>;

Descriptor random_descriptor(std::mt19937& rng) {
  Descriptor d;
  for (auto& byte : d) byte = static_cast<std::uint8_t>(rng() & 0xFF);
  return d;
}

// `d` with `n` distinct bits flipped.
Descriptor flip_bits(Descriptor d, int n, std::mt19937& rng) {
  std::set<int> bits;
  while (static_cast<int>(bits.size()) < n) bits.insert(static_cast<int>(rng() % 256));
  for (int bit : bits)
    d[static_cast<std::size_t>(bit / 8)] ^= static_cast<std::uint8_t>(1 << (bit % 8));
  return d;
}

cv::Mat to_mat(const std::vector<Descriptor>& descriptors) {
  cv::Mat m(static_cast<int>(descriptors.size()), 32, CV_8U);
  for (int r = 0; r < m.rows; ++r)
    std::copy(descriptors[static_cast<std::size_t>(r)].begin(),
              descriptors[static_cast<std::size_t>(r)].end(), m.ptr<std::uint8_t>(r));
  return m;
}

std::vector<Descriptor> random_descriptors(int n, std::mt19937& rng) {
  std::vector<Descriptor> out;
  for (int i = 0; i < n; ++i) out.push_back(random_descriptor(rng));
  return out;
}

// Two-level structure: 4 groups (random centres, ~128 bits apart), 4 sub-clusters each (12 bits
// off the group centre), members 2 bits off their sub-cluster. A k=4, L=2 tree should give one
// word per sub-cluster.
struct ClusteredData {
  std::vector<Descriptor> centres;               // the 16 sub-cluster centres
  std::vector<std::vector<Descriptor>> members;  // per sub-cluster
};

ClusteredData clustered_data(int members_per_cluster, std::mt19937& rng) {
  ClusteredData data;
  for (int g = 0; g < 4; ++g) {
    const Descriptor group = random_descriptor(rng);
    for (int s = 0; s < 4; ++s) data.centres.push_back(flip_bits(group, 12, rng));
  }
  for (const Descriptor& centre : data.centres) {
    data.members.emplace_back();
    for (int m = 0; m < members_per_cluster; ++m)
      data.members.back().push_back(flip_bits(centre, 2, rng));
  }
  return data;
}

// One training image per sub-cluster, so that every word has the same idf.
std::vector<cv::Mat> images_of(const ClusteredData& data) {
  std::vector<cv::Mat> images;
  for (const auto& members : data.members) images.push_back(to_mat(members));
  return images;
}

VocabularyTrainOptions options(int branching, int levels, std::uint64_t seed = 0) {
  VocabularyTrainOptions o;
  o.branching = branching;
  o.levels = levels;
  o.seed = seed;
  return o;
}

TEST(Vocabulary, ClustersBecomeWordsOnePerCluster) {
  for (std::uint64_t seed : {0u, 1u, 2u}) {
    std::mt19937 rng(static_cast<unsigned>(100 + seed));
    const ClusteredData data = clustered_data(25, rng);
    const Vocabulary voc = Vocabulary::train(images_of(data), options(4, 2, seed));
    EXPECT_LE(voc.word_count(), 16u);
    std::set<WordId> words;
    for (std::size_t c = 0; c < data.centres.size(); ++c) {
      const WordId word = voc.word_of(data.members[c].front().data());
      for (const Descriptor& d : data.members[c]) EXPECT_EQ(voc.word_of(d.data()), word) << c;
      // Unseen descriptors of the same cluster land there too.
      const Descriptor fresh = flip_bits(data.centres[c], 2, rng);
      EXPECT_EQ(voc.word_of(fresh.data()), word) << c;
      words.insert(word);
    }
    EXPECT_EQ(words.size(), 16u) << "seed " << seed;
    EXPECT_NEAR(voc.word_weight(*words.begin()), std::log(16.0), 1e-12);
  }
}

TEST(Vocabulary, WordCountIsBoundedByBranchingToTheLevels) {
  std::mt19937 rng(3);
  const Vocabulary voc = Vocabulary::train({to_mat(random_descriptors(2000, rng))}, options(5, 3));
  EXPECT_EQ(voc.branching(), 5);
  EXPECT_EQ(voc.levels(), 3);
  EXPECT_LE(voc.word_count(), 125u);
  EXPECT_GT(voc.word_count(), 100u);  // 2000 spread descriptors fill nearly every leaf
  for (WordId w = 0; w < voc.word_count(); ++w) EXPECT_LE(voc.node_depth(voc.node_of_word(w)), 3);
}

TEST(Vocabulary, TrainingIsDeterministicForASeed) {
  std::mt19937 rng(4);
  std::vector<cv::Mat> images;
  for (int i = 0; i < 5; ++i) images.push_back(to_mat(random_descriptors(400, rng)));
  const Vocabulary a = Vocabulary::train(images, options(6, 3, 42));
  const Vocabulary b = Vocabulary::train(images, options(6, 3, 42));
  const Vocabulary c = Vocabulary::train(images, options(6, 3, 43));
  ASSERT_EQ(a.node_count(), b.node_count());
  const std::vector<Descriptor> probes = random_descriptors(500, rng);
  int differ_from_c = 0;
  for (const Descriptor& d : probes) {
    EXPECT_EQ(a.word_of(d.data()), b.word_of(d.data()));
    differ_from_c += a.word_of(d.data()) != c.word_of(d.data());
  }
  EXPECT_GT(differ_from_c, 0);  // the seed does matter
  test::TempDir dir;
  a.save(dir.file("a.voc"));
  b.save(dir.file("b.voc"));
  EXPECT_EQ(test::read_text_file(dir.file("a.voc")), test::read_text_file(dir.file("b.voc")));
}

// 60 "places", each a random pick of 40 of 200 landmark descriptors; an image of a place shows
// each of its landmarks a few times with 3 bits of noise.
class PlaceScores : public ::testing::Test {
 protected:
  void SetUp() override {
    std::mt19937 rng(5);
    landmarks_ = random_descriptors(200, rng);
    for (int p = 0; p < 60; ++p) {
      std::vector<std::size_t> picks(landmarks_.size());
      std::iota(picks.begin(), picks.end(), 0);
      std::shuffle(picks.begin(), picks.end(), rng);
      places_.emplace_back(picks.begin(), picks.begin() + 40);
    }
    std::vector<cv::Mat> training;
    for (int p = 0; p < 40; ++p) training.push_back(image_of(places_[p], rng));
    voc_ = Vocabulary::train(training, options(8, 3));
  }

  cv::Mat image_of(const std::vector<std::size_t>& place, std::mt19937& rng) const {
    std::vector<Descriptor> d;
    for (std::size_t l : place)
      for (int k = 0; k < 3; ++k) d.push_back(flip_bits(landmarks_[l], 3, rng));
    return to_mat(d);
  }

  BowVector bow(const cv::Mat& descriptors) const {
    BowVector b;
    FeatureVector f;
    voc_.transform(descriptors, b, f, 1);
    return b;
  }

  std::vector<Descriptor> landmarks_;
  std::vector<std::vector<std::size_t>> places_;
  Vocabulary voc_;
};

TEST_F(PlaceScores, SameImageScoresOneAndOtherPlacesMuchLower) {
  std::mt19937 rng(6);
  const BowVector a = bow(image_of(places_[45], rng));
  const BowVector a_again = bow(image_of(places_[45], rng));  // same place, fresh noise
  const BowVector other_place = bow(image_of(places_[50], rng));
  const BowVector unrelated = bow(to_mat(random_descriptors(120, rng)));
  double sum = 0.0;
  for (const auto& [word, weight] : a) sum += weight;
  EXPECT_NEAR(sum, 1.0, 1e-12);
  EXPECT_NEAR(Vocabulary::score(a, a), 1.0, 1e-12);
  EXPECT_GT(Vocabulary::score(a, a_again), 0.5);
  EXPECT_LT(Vocabulary::score(a, other_place), 0.5 * Vocabulary::score(a, a_again));
  EXPECT_LT(Vocabulary::score(a, unrelated), 0.2);
  for (const BowVector* b : {&a_again, &other_place, &unrelated}) {
    const double s = Vocabulary::score(a, *b);
    EXPECT_GE(s, 0.0);
    EXPECT_LE(s, 1.0);
    EXPECT_DOUBLE_EQ(s, Vocabulary::score(*b, a));
  }
}

TEST(VocabularyScore, IsOneMinusHalfTheL1Distance) {
  const BowVector a = {{1, 0.5}, {2, 0.5}}, b = {{2, 0.25}, {3, 0.75}};
  EXPECT_NEAR(Vocabulary::score(a, b), 1.0 - 0.5 * (0.5 + 0.25 + 0.75), 1e-12);
  EXPECT_EQ(Vocabulary::score(a, {}), 0.0);
  EXPECT_EQ(Vocabulary::score({}, {}), 0.0);
}

TEST(Vocabulary, FeatureVectorFilesEveryKeypointOnceAtTheRequestedLevel) {
  std::mt19937 rng(7);
  const Vocabulary voc = Vocabulary::train({to_mat(random_descriptors(3000, rng))}, options(4, 4));
  const cv::Mat query = to_mat(random_descriptors(300, rng));
  for (int levels_up : {0, 1, 2, 4, 6}) {
    BowVector bow;
    FeatureVector features;
    voc.transform(query, bow, features, levels_up);
    std::vector<int> seen(300, 0);
    for (const auto& [node, keypoints] : features) {
      for (std::size_t i : keypoints) {
        ++seen[i];
        // The filed node is the keypoint's leaf, or its ancestor at depth L - levels_up.
        NodeId n = voc.node_of_word(voc.word_of(query.ptr<std::uint8_t>(static_cast<int>(i))));
        while (voc.node_depth(n) > std::max(0, 4 - levels_up)) n = voc.parent_of(n);
        EXPECT_EQ(node, n) << "levels_up " << levels_up;
      }
      if (levels_up >= 4) {
        EXPECT_EQ(node, Vocabulary::kRoot);
      }
    }
    for (int count : seen) EXPECT_EQ(count, 1) << "levels_up " << levels_up;
    // A single training image gives every word idf 0: no BoW weight, but keypoints still filed.
    EXPECT_TRUE(bow.empty());
  }
}

TEST(Vocabulary, RejectsBadInput) {
  std::mt19937 rng(8);
  const cv::Mat good = to_mat(random_descriptors(50, rng));
  test::expect_error_naming([&] { Vocabulary::train({cv::Mat::zeros(5, 31, CV_8U)}, {}); },
                            "image 0");
  test::expect_error_naming(
      [&] {
        Vocabulary::train({good, cv::Mat::zeros(5, 32, CV_32F)}, {});
      },
      "image 1");
  test::expect_error_naming([&] { Vocabulary::train({cv::Mat()}, {}); }, "no descriptors");
  const cv::Mat same = cv::Mat::ones(20, 32, CV_8U);
  test::expect_error_naming([&] { Vocabulary::train({same, same}, {}); }, "identical");
  test::expect_error_naming([&] { Vocabulary::train({good}, options(1, 3)); }, "branching 1");
  const Vocabulary voc = Vocabulary::train({good, good}, options(4, 2));
  BowVector bow;
  FeatureVector features;
  test::expect_error_naming([&] { voc.transform(cv::Mat::zeros(3, 16, CV_8U), bow, features, 1); },
                            "N x 32");
  EXPECT_TRUE(Vocabulary().empty());
  test::expect_error_naming([&] { Vocabulary().word_of(good.ptr<std::uint8_t>(0)); }, "empty");
}

TEST(VocabularyFile, SaveThenLoadGivesTheSameWordsAndVectors) {
  std::mt19937 rng(9);
  std::vector<cv::Mat> images;
  for (int i = 0; i < 10; ++i) images.push_back(to_mat(random_descriptors(2500, rng)));
  const Vocabulary voc = Vocabulary::train(images, options(10, 4));
  EXPECT_GT(voc.word_count(), 9000u);  // a full k=10, L=4 tree
  test::TempDir dir;
  const std::string path = dir.file("orb.voc");
  voc.save(path);
  EXPECT_LT(std::filesystem::file_size(path), 1000000u);
  const Vocabulary loaded = Vocabulary::load(path);
  EXPECT_EQ(loaded.word_count(), voc.word_count());
  EXPECT_EQ(loaded.node_count(), voc.node_count());
  EXPECT_EQ(loaded.branching(), 10);
  EXPECT_EQ(loaded.levels(), 4);
  const cv::Mat probes = to_mat(random_descriptors(2000, rng));
  for (int r = 0; r < probes.rows; ++r)
    ASSERT_EQ(loaded.word_of(probes.ptr<std::uint8_t>(r)),
              voc.word_of(probes.ptr<std::uint8_t>(r)));
  BowVector bow_a, bow_b;
  FeatureVector features_a, features_b;
  voc.transform(probes, bow_a, features_a, 2);
  loaded.transform(probes, bow_b, features_b, 2);
  EXPECT_FALSE(bow_a.empty());
  EXPECT_EQ(bow_a, bow_b);  // weights are stored exactly
  EXPECT_EQ(features_a, features_b);
}

TEST(VocabularyFile, BadFilesFailNamingTheFile) {
  std::mt19937 rng(10);
  const cv::Mat d = to_mat(random_descriptors(300, rng));
  test::TempDir dir;
  const std::string good = dir.file("good.voc");
  Vocabulary::train({d, d.rowRange(0, 100)}, options(4, 3)).save(good);
  const std::string bytes = test::read_text_file(good);

  const std::string missing = dir.file("missing.voc");
  EXPECT_NE(test::error_message([&] { Vocabulary::load(missing); }).find(missing + ": "),
            std::string::npos);
  const std::string truncated = dir.file("truncated.voc");
  test::write_text_file(truncated, bytes.substr(0, bytes.size() / 2));
  const std::string message = test::error_message([&] { Vocabulary::load(truncated); });
  EXPECT_NE(message.find(truncated + ": truncated"), std::string::npos) << message;
  test::write_text_file(truncated, bytes.substr(0, 10));
  test::expect_error_naming([&] { Vocabulary::load(truncated); }, truncated + ": truncated");
  const std::string wrong_magic = dir.file("wrong.voc");
  test::write_text_file(wrong_magic, "DBOW2VOC" + bytes.substr(8));
  test::expect_error_naming([&] { Vocabulary::load(wrong_magic); }, wrong_magic + ": not an");
  const std::string corrupt = dir.file("corrupt.voc");
  std::string flipped = bytes;
  flipped[bytes.size() / 2] ^= 0x10;
  test::write_text_file(corrupt, flipped);
  test::expect_error_naming([&] { Vocabulary::load(corrupt); }, corrupt + ": corrupt");
  test::write_text_file(corrupt, bytes + "x");
  test::expect_error_naming([&] { Vocabulary::load(corrupt); }, corrupt + ": corrupt");
  const std::string message_line = test::error_message([&] { Vocabulary::load(corrupt); });
  EXPECT_EQ(message_line.find('\n'), std::string::npos);
}

// Real ORB features of KITTI 06 (about 12 m/s): frames 0.1-0.2 s apart look more alike than
// frames 3-5 s apart. The vocabulary is trained on the even frames 2..48, so the frames compared
// are unseen.
TEST(VocabularyOnKitti, ConsecutiveFramesScoreHigherThanDistantOnes) {
  const std::string dir =
      std::string(SBASLAM_SHARED_DIR) + "/data/kitti06_first51/sequences/06/image_0/";
  feature::OrbExtractor extractor(test::orb_settings_with(1000));
  const auto descriptors = [&](int i) {
    return extractor.extract(test::read_gray(dir + fmt::format("{:06d}.png", i))).descriptors;
  };
  std::vector<cv::Mat> training;
  for (int i = 2; i <= 48; i += 2) training.push_back(descriptors(i));
  const Vocabulary voc = Vocabulary::train(training, options(10, 4));
  std::map<int, BowVector> bows;
  for (int i : {0, 1, 11, 31, 41, 47, 49}) {
    FeatureVector features;
    voc.transform(descriptors(i), bows[i], features, 2);
  }
  const auto score = [&](int a, int b) { return Vocabulary::score(bows[a], bows[b]); };
  // Measured: near 0.24 and 0.21, far 0.13-0.16. A vocabulary of 24 images is far from ORB-SLAM's
  // (a million words from thousands of images), so the margin is modest but clear.
  for (const auto& [a, b] : {std::pair{0, 1}, std::pair{47, 49}})
    for (const auto& [c, d] :
         {std::pair{0, 31}, std::pair{0, 41}, std::pair{0, 49}, std::pair{49, 11}})
      EXPECT_GT(score(a, b), 1.2 * score(c, d)) << a << "-" << b << " vs " << c << "-" << d;
}

}  // namespace
}  // namespace sbaslam::loop
