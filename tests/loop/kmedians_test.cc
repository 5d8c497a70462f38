// One clustering step of the vocabulary on descriptors with known clusters.

#include "sbaslam/loop/kmedians.h"

#include <gtest/gtest.h>

#include <random>
#include <set>

namespace sbaslam::loop {
namespace {

BinaryDescriptor random_descriptor(std::mt19937& rng) {
  BinaryDescriptor d;
  for (auto& byte : d) byte = static_cast<std::uint8_t>(rng() & 0xFF);
  return d;
}

BinaryDescriptor flip_one_bit(BinaryDescriptor d, std::mt19937& rng) {
  const unsigned bit = rng() % 256;
  d[bit / 8] ^= static_cast<std::uint8_t>(1u << (bit % 8));
  return d;
}

std::vector<const std::uint8_t*> pointers(const std::vector<BinaryDescriptor>& descriptors) {
  std::vector<const std::uint8_t*> out;
  for (const BinaryDescriptor& d : descriptors) out.push_back(d.data());
  return out;
}

TEST(ClusterDescriptors, FindsTheClustersAndTheirCentres) {
  std::mt19937 rng(1);
  std::vector<BinaryDescriptor> centres, points;
  for (int c = 0; c < 5; ++c) centres.push_back(random_descriptor(rng));
  // 30 one-bit variants of each centre, interleaved: the majority of each cluster is its centre.
  for (int m = 0; m < 30; ++m)
    for (const BinaryDescriptor& centre : centres) points.push_back(flip_one_bit(centre, rng));
  std::mt19937_64 seeded(7);
  const DescriptorClusters clusters = cluster_descriptors(pointers(points), 5, 10, seeded);
  ASSERT_EQ(clusters.centres.size(), 5u);
  std::set<BinaryDescriptor> found(clusters.centres.begin(), clusters.centres.end());
  EXPECT_EQ(found, std::set<BinaryDescriptor>(centres.begin(), centres.end()));
  for (std::size_t c = 0; c < 5; ++c) {
    EXPECT_EQ(clusters.members[c].size(), 30u);
    for (const std::uint8_t* p : clusters.members[c])
      EXPECT_LE(match::descriptor_distance(p, clusters.centres[c].data()), 1);
  }
}

TEST(ClusterDescriptors, FewPointsBecomeOneClusterPerDistinctDescriptor) {
  std::mt19937 rng(2);
  const BinaryDescriptor a = random_descriptor(rng), b = random_descriptor(rng);
  const std::vector<BinaryDescriptor> points = {a, b, a};
  std::mt19937_64 seeded(0);
  const DescriptorClusters clusters = cluster_descriptors(pointers(points), 4, 10, seeded);
  ASSERT_EQ(clusters.centres.size(), 2u);
  EXPECT_EQ(clusters.members[0].size() + clusters.members[1].size(), 3u);
  const std::size_t of_a = clusters.centres[0] == a ? 0 : 1;
  EXPECT_EQ(clusters.centres[of_a], a);
  EXPECT_EQ(clusters.members[of_a].size(), 2u);
}

TEST(ClusterDescriptors, IdenticalPointsGiveOneCluster) {
  const BinaryDescriptor same{};
  const std::vector<BinaryDescriptor> points(20, same);
  std::mt19937_64 seeded(0);
  const DescriptorClusters clusters = cluster_descriptors(pointers(points), 4, 10, seeded);
  ASSERT_EQ(clusters.centres.size(), 1u);
  EXPECT_EQ(clusters.members[0].size(), 20u);
}

}  // namespace
}  // namespace sbaslam::loop
