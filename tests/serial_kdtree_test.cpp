// SerialKdTree (alignment/src/serial_kdtree.hpp, private to the acquisition) against PCL's own k-d tree:
// the same neighbours and distances for k-nearest and radius searches, with points that are not finite
// in the cloud, an index subset, a cap on the neighbours, and queries it cannot answer.

#include "../alignment/src/serial_kdtree.hpp"

#include <gtest/gtest.h>
#include <pcl/point_types.h>
#include <pcl/search/kdtree.h>

#include <limits>
#include <random>

namespace projbot::alignment {
namespace {

pcl::PointCloud<pcl::PointXYZ>::Ptr random_cloud(std::size_t n, std::mt19937& rng) {
  std::uniform_real_distribution<float> u(-0.3F, 0.3F);
  auto cloud = pcl::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (std::size_t i = 0; i < n; ++i)
    cloud->push_back(i % 97 == 5 ? pcl::PointXYZ(nan, 0.0F, 0.0F) : pcl::PointXYZ(u(rng), u(rng), u(rng)));
  return cloud;
}

// Both trees answer the same query alike: same count, same indices in the same order, same distances.
void expect_same(int n_pcl, const pcl::Indices& i_pcl, const std::vector<float>& d_pcl, int n_ours, const pcl::Indices& i_ours,
                 const std::vector<float>& d_ours, const char* what) {
  ASSERT_EQ(n_pcl, n_ours) << what;
  for (int j = 0; j < n_pcl; ++j) {
    EXPECT_EQ(i_pcl[j], i_ours[j]) << what << ", neighbour " << j;
    EXPECT_FLOAT_EQ(d_pcl[j], d_ours[j]) << what << ", neighbour " << j;
  }
}

TEST(SerialKdTree, GivesPclsNeighbours) {
  std::mt19937 rng(3);
  const auto cloud = random_cloud(3000, rng);
  pcl::search::KdTree<pcl::PointXYZ> pcl_tree;
  SerialKdTree<pcl::PointXYZ> ours;
  pcl_tree.setInputCloud(cloud);
  ours.setInputCloud(cloud);
  const auto queries = random_cloud(200, rng);
  pcl::Indices ia, ib;
  std::vector<float> da, db;
  int radius_hits = 0;
  for (const auto& q : *queries) {
    if (!std::isfinite(q.x)) continue;
    for (const int k : {1, 16}) {
      const int na = pcl_tree.nearestKSearch(q, k, ia, da), nb = ours.nearestKSearch(q, k, ib, db);
      expect_same(na, ia, da, nb, ib, db, "k nearest");
      EXPECT_EQ(nb, k);
    }
    const int na = pcl_tree.radiusSearch(q, 0.05, ia, da), nb = ours.radiusSearch(q, 0.05, ib, db);
    expect_same(na, ia, da, nb, ib, db, "radius");
    radius_hits += nb;
    const int ca = pcl_tree.radiusSearch(q, 0.08, ia, da, 5), cb = ours.radiusSearch(q, 0.08, ib, db, 5);
    expect_same(ca, ia, da, cb, ib, db, "radius, at most 5");
    EXPECT_LE(cb, 5);
  }
  EXPECT_GT(radius_hits, 200);  // the radius searches found neighbours to compare
}

TEST(SerialKdTree, SearchesAnIndexSubsetAndAnswersWhatItCannotWithNothing) {
  std::mt19937 rng(4);
  const auto cloud = random_cloud(1000, rng);
  auto every_third = pcl::make_shared<pcl::Indices>();
  for (pcl::index_t i = 0; i < 1000; i += 3) every_third->push_back(i);
  pcl::search::KdTree<pcl::PointXYZ> pcl_tree;
  SerialKdTree<pcl::PointXYZ> ours;
  pcl_tree.setInputCloud(cloud, every_third);
  ours.setInputCloud(cloud, every_third);
  pcl::Indices ia, ib;
  std::vector<float> da, db;
  const pcl::PointXYZ q(0.01F, -0.02F, 0.03F);
  expect_same(pcl_tree.nearestKSearch(q, 8, ia, da), ia, da, ours.nearestKSearch(q, 8, ib, db), ib, db, "subset");
  for (const pcl::index_t i : ib) EXPECT_EQ(i % 3, 0) << "an index outside the subset";
  // A query that is not finite, and a tree without finite points, find nothing (and do not crash).
  EXPECT_EQ(ours.nearestKSearch(pcl::PointXYZ(std::numeric_limits<float>::quiet_NaN(), 0.0F, 0.0F), 4, ib, db), 0);
  EXPECT_TRUE(ib.empty());
  auto nans = pcl::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  nans->push_back(pcl::PointXYZ(std::numeric_limits<float>::infinity(), 0.0F, 0.0F));
  SerialKdTree<pcl::PointXYZ> empty;
  empty.setInputCloud(nans);
  EXPECT_EQ(empty.nearestKSearch(q, 1, ib, db), 0);
  EXPECT_EQ(empty.radiusSearch(q, 1.0, ib, db), 0);
}

}  // namespace
}  // namespace projbot::alignment
