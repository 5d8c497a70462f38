#include "sbaslam/loop/vocabulary.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "sbaslam/core/error.h"
#include "sbaslam/core/output_file.h"
#include "sbaslam/loop/kmedians.h"
#include "sbaslam/match/hamming.h"

namespace sbaslam::loop {
namespace {

constexpr char kMagic[8] = {'S', 'B', 'A', 'V', 'O', 'C', 'A', 'B'};
constexpr std::uint32_t kVersion = 1;
// Magic, then version, branching, levels, node count and word count as u32.
constexpr std::size_t kHeaderBytes = sizeof(kMagic) + 5 * 4;
// A node's parent (u32) and descriptor; the root has no record.
constexpr std::size_t kNodeBytes = 4 + match::kDescriptorBytes;

void check_descriptors(const cv::Mat& d, const std::string& what) {
  if (d.empty() || (d.type() == CV_8UC1 && d.cols == match::kDescriptorBytes)) return;
  fail("{}: descriptors must be N x {} CV_8U, got {} x {} of type {}", what,
       match::kDescriptorBytes, d.rows, d.cols, d.type());
}

void check_options(const VocabularyTrainOptions& o) {
  if (o.branching < 2 || o.branching > 65535 || o.levels < 1 || o.levels > 64 ||
      o.kmeans_iterations < 1)
    fail("vocabulary training: invalid options (branching {}, levels {}, k-means iterations {})",
         o.branching, o.levels, o.kmeans_iterations);
}

// 64-bit FNV-1a over the file's bytes before the checksum.
std::uint64_t checksum(const std::string& bytes, std::size_t n) {
  std::uint64_t h = 14695981039346656037ull;
  for (std::size_t i = 0; i < n; ++i) {
    h ^= static_cast<unsigned char>(bytes[i]);
    h *= 1099511628211ull;
  }
  return h;
}

class ByteWriter {
 public:
  void raw(const void* data, std::size_t n) { bytes_.append(static_cast<const char*>(data), n); }
  void u32(std::uint32_t v) { little_endian(v, 4); }
  void u64(std::uint64_t v) { little_endian(v, 8); }
  void f64(double v) {
    std::uint64_t bits;
    std::memcpy(&bits, &v, sizeof(bits));
    u64(bits);
  }
  const std::string& bytes() const { return bytes_; }

 private:
  void little_endian(std::uint64_t v, int n) {
    for (int i = 0; i < n; ++i) bytes_.push_back(static_cast<char>((v >> (8 * i)) & 0xFF));
  }
  std::string bytes_;
};

// Reads little-endian values; the caller has checked the size, so reads never run past the end.
class ByteReader {
 public:
  explicit ByteReader(const std::string& bytes) : bytes_(bytes) {}
  void raw(void* out, std::size_t n) {
    std::memcpy(out, bytes_.data() + pos_, n);
    pos_ += n;
  }
  std::uint64_t uint(int n) {
    std::uint64_t v = 0;
    for (int i = 0; i < n; ++i)
      v |= static_cast<std::uint64_t>(static_cast<unsigned char>(bytes_[pos_++])) << (8 * i);
    return v;
  }
  std::uint32_t u32() { return static_cast<std::uint32_t>(uint(4)); }
  double f64() {
    const std::uint64_t bits = uint(8);
    double v;
    std::memcpy(&v, &bits, sizeof(v));
    return v;
  }

 private:
  const std::string& bytes_;
  std::size_t pos_ = 0;
};

}  // namespace

Vocabulary Vocabulary::train(const std::vector<cv::Mat>& descriptor_sets,
                             const VocabularyTrainOptions& options) {
  check_options(options);
  std::vector<const std::uint8_t*> points;
  for (std::size_t i = 0; i < descriptor_sets.size(); ++i) {
    check_descriptors(descriptor_sets[i], fmt::format("vocabulary training, image {}", i));
    for (int r = 0; r < descriptor_sets[i].rows; ++r)
      points.push_back(descriptor_sets[i].ptr<std::uint8_t>(r));
  }
  if (points.empty())
    fail("vocabulary training: no descriptors in {} image(s)", descriptor_sets.size());
  Vocabulary v;
  v.branching_ = options.branching;
  v.levels_ = options.levels;
  std::mt19937_64 rng(options.seed);
  const std::size_t count = points.size();
  v.grow(kRoot, std::move(points), options, rng);
  if (v.nodes_.size() == 1) fail("vocabulary training: all {} descriptors are identical", count);
  v.number_words();
  v.compute_idf(descriptor_sets);
  return v;
}

void Vocabulary::grow(NodeId node, std::vector<const std::uint8_t*> points,
                      const VocabularyTrainOptions& options, std::mt19937_64& rng) {
  if (nodes_[node].depth >= options.levels || points.size() < 2) return;
  // The points move into the clusters, so a level's copy is freed before the next level's.
  DescriptorClusters clusters =
      cluster_descriptors(std::move(points), static_cast<std::size_t>(options.branching),
                          options.kmeans_iterations, rng);
  if (clusters.centres.size() < 2) return;  // one distinct descriptor: nothing to tell apart
  const NodeId first = add_children(node, clusters.centres);
  for (std::size_t c = 0; c < clusters.members.size(); ++c)
    grow(first + static_cast<NodeId>(c), std::move(clusters.members[c]), options, rng);
}

NodeId Vocabulary::add_children(NodeId parent, const std::vector<BinaryDescriptor>& centres) {
  const auto first = static_cast<NodeId>(nodes_.size());
  for (const BinaryDescriptor& centre : centres) {
    Node child;
    child.descriptor = centre;
    child.parent = parent;
    child.depth = nodes_[parent].depth + 1;
    nodes_.push_back(child);
  }
  nodes_[parent].first_child = first;
  nodes_[parent].child_count = static_cast<std::uint32_t>(centres.size());
  return first;
}

void Vocabulary::number_words() {
  word_nodes_.clear();
  for (NodeId id = 1; id < nodes_.size(); ++id) {
    if (nodes_[id].child_count > 0) continue;
    nodes_[id].word = static_cast<WordId>(word_nodes_.size());
    word_nodes_.push_back(id);
  }
}

void Vocabulary::compute_idf(const std::vector<cv::Mat>& descriptor_sets) {
  const std::size_t none = descriptor_sets.size();
  std::vector<std::size_t> images_with(word_count(), 0), last_image(word_count(), none);
  for (std::size_t i = 0; i < descriptor_sets.size(); ++i) {
    for (int r = 0; r < descriptor_sets[i].rows; ++r) {
      const WordId w = word_of(descriptor_sets[i].ptr<std::uint8_t>(r));
      if (last_image[w] == i) continue;
      last_image[w] = i;
      ++images_with[w];
    }
  }
  // Every leaf holds a training descriptor, which descends to it; max(1, .) is only a guard.
  const auto n = static_cast<double>(descriptor_sets.size());
  weights_.resize(word_count());
  for (std::size_t w = 0; w < word_count(); ++w)
    weights_[w] = std::log(n / static_cast<double>(std::max<std::size_t>(1, images_with[w])));
}

NodeId Vocabulary::descend(const std::uint8_t* descriptor, int stop_depth, NodeId* at_depth) const {
  NodeId id = kRoot;
  if (at_depth) *at_depth = kRoot;
  while (nodes_[id].child_count > 0) {
    const Node& node = nodes_[id];
    int best_distance = match::kMaxDescriptorDistance + 1;
    for (NodeId c = node.first_child; c < node.first_child + node.child_count; ++c) {
      const int d = match::descriptor_distance(descriptor, nodes_[c].descriptor.data());
      if (d < best_distance) {
        best_distance = d;
        id = c;
      }
    }
    if (at_depth && nodes_[id].depth <= stop_depth) *at_depth = id;
  }
  return id;
}

WordId Vocabulary::word_of(const std::uint8_t* descriptor) const {
  if (empty()) fail("vocabulary: word_of() on an empty vocabulary");
  return nodes_[descend(descriptor, 0, nullptr)].word;
}

void Vocabulary::transform(const cv::Mat& descriptors, BowVector& bow, FeatureVector& features,
                           int levels_up) const {
  check_descriptors(descriptors, "vocabulary transform");
  bow.clear();
  features.clear();
  const int stop_depth = levels_ - levels_up;
  for (int r = 0; r < descriptors.rows; ++r) {
    NodeId at_depth = kRoot;
    const WordId word =
        nodes_[descend(descriptors.ptr<std::uint8_t>(r), stop_depth, &at_depth)].word;
    features[at_depth].push_back(static_cast<std::size_t>(r));
    if (word != kNoWord && weights_[word] > 0.0) bow[word] += weights_[word];
  }
  double sum = 0.0;
  for (const auto& [word, weight] : bow) sum += weight;
  for (auto& [word, weight] : bow) weight /= sum;
}

double Vocabulary::score(const BowVector& a, const BowVector& b) {
  double sum = 0.0;
  auto ia = a.begin(), ib = b.begin();
  while (ia != a.end() && ib != b.end()) {
    if (ia->first < ib->first) {
      ++ia;
    } else if (ib->first < ia->first) {
      ++ib;
    } else {
      const double x = ia->second, y = ib->second;
      sum += std::abs(x) + std::abs(y) - std::abs(x - y);
      ++ia;
      ++ib;
    }
  }
  return std::clamp(0.5 * sum, 0.0, 1.0);
}

void Vocabulary::save(const std::string& path) const {
  ByteWriter w;
  w.raw(kMagic, sizeof(kMagic));
  w.u32(kVersion);
  w.u32(static_cast<std::uint32_t>(branching_));
  w.u32(static_cast<std::uint32_t>(levels_));
  w.u32(static_cast<std::uint32_t>(nodes_.size()));
  w.u32(static_cast<std::uint32_t>(word_nodes_.size()));
  for (NodeId id = 1; id < nodes_.size(); ++id) {
    w.u32(nodes_[id].parent);
    w.raw(nodes_[id].descriptor.data(), nodes_[id].descriptor.size());
  }
  for (const double weight : weights_) w.f64(weight);
  w.u64(checksum(w.bytes(), w.bytes().size()));
  write_output_file(path, w.bytes());
}

Vocabulary Vocabulary::load(const std::string& path) {
  if (!std::filesystem::is_regular_file(path)) fail("{}: vocabulary file not found", path);
  std::ifstream in(path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (!in && !in.eof()) fail("{}: cannot read the vocabulary file", path);
  Vocabulary v;
  v.parse(bytes, path);
  return v;
}

void Vocabulary::parse(const std::string& bytes, const std::string& path) {
  if (bytes.size() >= sizeof(kMagic) && bytes.compare(0, sizeof(kMagic), kMagic, sizeof(kMagic)))
    fail("{}: not an sba-slam vocabulary (wrong magic)", path);
  if (bytes.size() < kHeaderBytes)
    fail("{}: truncated vocabulary file ({} bytes)", path, bytes.size());
  const auto corrupt = [&](const char* what) {
    fail("{}: corrupt vocabulary file ({})", path, what);
  };
  ByteReader r(bytes);
  r.uint(sizeof(kMagic));
  const std::uint32_t version = r.u32();
  if (version != kVersion) fail("{}: vocabulary version {} is not supported", path, version);
  branching_ = static_cast<int>(r.u32());
  levels_ = static_cast<int>(r.u32());
  const std::uint64_t node_count = r.u32(), word_count = r.u32();
  if (node_count == 0) corrupt("no root node");
  // Sizes are checked before anything is allocated, so a damaged count cannot exhaust memory.
  const std::uint64_t expected = kHeaderBytes + (node_count - 1) * kNodeBytes + word_count * 8 + 8;
  if (bytes.size() < expected)
    fail("{}: truncated vocabulary file ({} bytes, expected {})", path, bytes.size(), expected);
  if (bytes.size() > expected)
    fail("{}: corrupt vocabulary file ({} bytes, expected {})", path, bytes.size(), expected);
  if (ByteReader(bytes.substr(expected - 8)).uint(8) != checksum(bytes, expected - 8))
    corrupt("checksum mismatch");
  if (branching_ < 2 || levels_ < 1 || levels_ > 64) corrupt("bad branching or levels");
  nodes_.assign(1, Node{});
  for (NodeId id = 1; id < node_count; ++id) {
    Node node;
    node.parent = r.u32();
    r.raw(node.descriptor.data(), node.descriptor.size());
    if (const char* problem = link_child(node, id)) corrupt(problem);
  }
  number_words();
  if (word_nodes_.size() != word_count) corrupt("word count differs from the leaves");
  weights_.resize(word_count);
  for (double& weight : weights_)
    if (weight = r.f64(); !std::isfinite(weight) || weight < 0.0) corrupt("bad word weight");
}

const char* Vocabulary::link_child(Node node, NodeId id) {
  if (node.parent >= id) return "a node before its parent";
  Node& parent = nodes_[node.parent];
  if (parent.child_count > 0 && parent.first_child + parent.child_count != id)
    return "children not consecutive";
  if (parent.child_count == 0) parent.first_child = id;
  if (++parent.child_count > static_cast<std::uint32_t>(branching_)) return "too many children";
  node.depth = parent.depth + 1;
  if (node.depth > levels_) return "tree deeper than its levels";
  nodes_.push_back(node);
  return nullptr;
}

}  // namespace sbaslam::loop
