#pragma once
// A bag-of-binary-words vocabulary for place recognition (DBoW2's scheme): a tree of ORB
// descriptors built by hierarchical k-medians, whose leaves are the words. An image becomes a
// sparse tf-idf vector over the words (its BoW), and two images' BoWs are compared by DBoW2's L1
// score. The feature vector files each keypoint under a node a few levels above its leaf, so that
// matching two keyframes only compares keypoints under the same node.
//
// The vocabulary is immutable once trained or loaded: const methods may run on any thread at once.

#include <array>
#include <cstddef>
#include <cstdint>
#include <map>
#include <opencv2/core.hpp>
#include <random>
#include <string>
#include <vector>

namespace sbaslam::loop {

using WordId = std::uint32_t;
using NodeId = std::uint32_t;
// Word -> tf-idf weight, L1-normalised to sum 1 (empty when no keypoint has a weighted word).
using BowVector = std::map<WordId, double>;
// Vocabulary node -> indices of the keypoints filed under it, ascending.
using FeatureVector = std::map<NodeId, std::vector<std::size_t>>;

struct VocabularyTrainOptions {
  int branching = 10;  // k: children per node
  int levels = 4;      // L: depth of the tree below the root
  int kmeans_iterations = 10;
  std::uint64_t seed = 0;
};

class Vocabulary {
 public:
  static constexpr NodeId kRoot = 0;

  // An empty vocabulary (a root without words): transform() gives an empty BoW and files every
  // keypoint under the root; word_of() throws.
  Vocabulary() = default;

  // Hierarchical k-medians over 256-bit ORB descriptors (loop/kmedians.h): greedy k-means++
  // seeding drawn from a std::mt19937_64 seeded with options.seed (so training is deterministic),
  // Hamming distance and the bitwise majority as the centre. A node holding one distinct
  // descriptor is not split further, so leaves may sit above level L. idf(word) =
  // log(N / N_word) over the N training images (one N_i x 32 CV_8U matrix each; empty ones count
  // as images). Throws sbaslam::Error for invalid options, badly shaped matrices, or fewer than
  // two distinct descriptors.
  static Vocabulary train(const std::vector<cv::Mat>& descriptor_sets,
                          const VocabularyTrainOptions& options);

  // Binary, little-endian, with a magic string, a version and a checksum. Failures (missing,
  // truncated, corrupt, not a vocabulary) throw a one-line sbaslam::Error naming the file.
  static Vocabulary load(const std::string& path);
  void save(const std::string& path) const;

  std::size_t word_count() const { return word_nodes_.size(); }
  std::size_t node_count() const { return nodes_.size(); }
  int branching() const { return branching_; }
  int levels() const { return levels_; }
  bool empty() const { return word_nodes_.empty(); }

  // The leaf reached by descending from the root to the nearest child (Hamming) at each level;
  // ties go to the first child. `descriptor` points at 32 bytes. The vocabulary must not be empty.
  WordId word_of(const std::uint8_t* descriptor) const;

  // The BoW of one image (tf-idf, L1-normalised; words of idf 0, i.e. present in every training
  // image, carry no weight and are left out, as in DBoW2) and its feature vector: every keypoint,
  // weighted word or not, is filed once, under the node at depth levels() - levels_up on its path
  // (the root when levels_up >= levels(); the leaf itself when the leaf is shallower).
  void transform(const cv::Mat& descriptors, BowVector& bow, FeatureVector& features,
                 int levels_up) const;

  // DBoW2's L1 score of two L1-normalised vectors, in [0, 1]: 1 - 0.5 * sum_w |a_w - b_w|, computed
  // as 0.5 * sum over the shared words of (|a_w| + |b_w| - |a_w - b_w|). 0 when either is empty.
  static double score(const BowVector& a, const BowVector& b);

  // The tree, for tests and diagnostics. Node ids are dense; the root is at depth 0.
  int node_depth(NodeId node) const { return nodes_.at(node).depth; }
  NodeId parent_of(NodeId node) const { return nodes_.at(node).parent; }
  NodeId node_of_word(WordId word) const { return word_nodes_.at(word); }
  double word_weight(WordId word) const { return weights_.at(word); }

 private:
  using Descriptor = std::array<std::uint8_t, 32>;
  static constexpr WordId kNoWord = ~WordId{0};

  struct Node {
    Descriptor descriptor{};  // the cluster centre (unused at the root)
    NodeId parent = kRoot;
    NodeId first_child = 0;  // a node's children have consecutive ids
    std::uint32_t child_count = 0;
    int depth = 0;
    WordId word = kNoWord;  // set on leaves only
  };

  void grow(NodeId node, std::vector<const std::uint8_t*> points,
            const VocabularyTrainOptions& options, std::mt19937_64& rng);
  NodeId add_children(NodeId parent, const std::vector<Descriptor>& centres);
  void number_words();
  void compute_idf(const std::vector<cv::Mat>& descriptor_sets);
  // The leaf of `descriptor`; also the node at `stop_depth` on its path into `at_depth`.
  NodeId descend(const std::uint8_t* descriptor, int stop_depth, NodeId* at_depth) const;
  void parse(const std::string& bytes, const std::string& path);
  // Appends a loaded node (ids in file order) under its parent; the problem if it cannot be.
  const char* link_child(Node node, NodeId id);

  std::vector<Node> nodes_{Node{}};  // nodes_[kRoot] is the root
  std::vector<NodeId> word_nodes_;   // word -> its leaf
  std::vector<double> weights_;      // word -> idf
  int branching_ = 0;
  int levels_ = 0;
};

}  // namespace sbaslam::loop
