#include "laser_dpslam/slam/ancestry_tree.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

using namespace laser_dpslam;

namespace {
// Records what the tree asked of the map.
struct RecordingHooks : AncestryHooks {
  std::vector<int> deleted;
  std::vector<std::pair<int, int>> merged;
  void deleteNode(int id) override { deleted.push_back(id); }
  void mergeChildIntoParent(int child, int parent) override { merged.emplace_back(child, parent); }
};

StampedPose at(double t) {
  StampedPose p;
  p.stamp = t;
  p.pose = Pose2D(t, 0.0, 0.0);
  return p;
}
}  // namespace

TEST(AncestryTree, IdsAreRecycledFromAStack) {
  AncestryTree tree;
  RecordingHooks hooks;
  const int root = tree.createRoot();
  const int a = tree.createChild(root, 1), b = tree.createChild(root, 1), c = tree.createChild(root, 1);
  EXPECT_EQ(tree.size(), 4u);
  EXPECT_EQ(tree.prune(b, hooks), 1);
  EXPECT_EQ(hooks.deleted, std::vector<int>{b});
  EXPECT_EQ(tree.node(root).children, 2);
  EXPECT_EQ(tree.createChild(a, 2), b);  // the freed ID comes back first
  EXPECT_EQ(tree.createChild(a, 2), 4);  // then new ones
  EXPECT_EQ(tree.check(), "");
  (void)c;
}

TEST(AncestryTree, PruningAChildlessNodeCascadesUp) {
  AncestryTree tree;
  RecordingHooks hooks;
  const int root = tree.createRoot();
  const int a = tree.createChild(root, 1), b = tree.createChild(root, 1);
  const int a1 = tree.createChild(a, 2);
  // a1 is a's only child: pruning a1 leaves a childless, so a goes too; root keeps b.
  EXPECT_EQ(tree.prune(a1, hooks), 2);
  EXPECT_EQ(hooks.deleted, (std::vector<int>{a1, a}));
  EXPECT_FALSE(tree.valid(a));
  EXPECT_EQ(tree.node(root).children, 1);
  EXPECT_TRUE(tree.valid(b));
  EXPECT_THROW(tree.prune(root, hooks), std::logic_error);  // has a child
  EXPECT_EQ(tree.check(), "");
}

TEST(AncestryTree, CollapseKeepsTheParentIdAndMergesPathsAndChildren) {
  AncestryTree tree;
  RecordingHooks hooks;
  const int root = tree.createRoot();
  tree.node(root).path = {at(0)};
  const int a = tree.createChild(root, 1), b = tree.createChild(root, 1);
  tree.node(a).path = {at(1), at(2)};
  const int a1 = tree.createChild(a, 3), a2 = tree.createChild(a, 3);
  tree.node(a1).path = {at(3)};
  tree.prune(b, hooks);
  ASSERT_EQ(tree.node(root).children, 1);
  EXPECT_EQ(tree.collapse(root, hooks), a);
  EXPECT_EQ(hooks.merged, (std::vector<std::pair<int, int>>{{a, root}}));
  EXPECT_FALSE(tree.valid(a));
  EXPECT_EQ(tree.parent(a1), root);
  EXPECT_EQ(tree.parent(a2), root);
  EXPECT_EQ(tree.node(root).children, 2);
  const auto path = tree.fullPath(a1);
  ASSERT_EQ(path.size(), 4u);
  for (int i = 0; i < 4; ++i) EXPECT_EQ(path[i].stamp, i);
  EXPECT_EQ(tree.check(2), "");
}

TEST(AncestryTree, AdvanceReusesOnlyChildrenAndBranchesOthers) {
  AncestryTree tree;
  NoAncestryHooks hooks;
  const int root = tree.createRoot();
  // Particle 0 (at the root) has 3 descendants: three new leaves.
  std::vector<int> leaves = tree.advance({root}, {0, 0, 0}, 1, hooks);
  ASSERT_EQ(leaves.size(), 3u);
  EXPECT_EQ(tree.size(), 4u);
  // No resampling: every particle keeps its node, the tree does not grow.
  EXPECT_EQ(tree.advance(leaves, {0, 1, 2}, 2, hooks), leaves);
  EXPECT_EQ(tree.size(), 4u);
  // Particle 1 takes everything: 0 and 2 die, the root's only child (1) collapses into the root, whose
  // node then branches into three new leaves.
  const std::vector<int> next = tree.advance(leaves, {1, 1, 1}, 3, hooks);
  EXPECT_EQ(tree.size(), 4u);
  for (int n : next) EXPECT_EQ(tree.parent(n), root);
  EXPECT_EQ(tree.check(2), "");
}

// After any number of random resampling steps the tree stays minimal: ≤ 2P − 1 nodes, IDs < 2P − 1.
TEST(AncestryTree, StaysWithin2PMinus1NodesOverManyRandomSteps) {
  for (int P : {1, 2, 7, 30}) {
    AncestryTree tree;
    RecordingHooks hooks;
    std::mt19937_64 rng(42 + P);
    std::vector<int> leaves = tree.advance({tree.createRoot()}, std::vector<int>(P, 0), 1, hooks);
    std::size_t max_nodes = 0;
    for (int step = 2; step < 3000; ++step) {
      std::vector<int> parent_of(P);
      const int mode = static_cast<int>(rng() % 4);
      for (int j = 0; j < P; ++j) {
        // Mix of no resampling, mild and strong selection.
        if (mode == 0) parent_of[j] = j;
        else if (mode == 1) parent_of[j] = static_cast<int>(rng() % P);
        else parent_of[j] = static_cast<int>(rng() % std::max(1, P / 4));
      }
      for (int n : leaves) tree.node(n).path.push_back(at(step));
      leaves = tree.advance(leaves, parent_of, step, hooks);
      max_nodes = std::max(max_nodes, tree.size());
      ASSERT_LE(tree.size(), static_cast<std::size_t>(2 * P - 1)) << "P=" << P << " step " << step;
      ASSERT_EQ(tree.check(2), "") << "P=" << P << " step " << step;
      std::vector<int> sorted = leaves;
      std::sort(sorted.begin(), sorted.end());
      ASSERT_TRUE(std::adjacent_find(sorted.begin(), sorted.end()) == sorted.end()) << "two particles share a leaf";
    }
    EXPECT_LE(tree.idCapacity(), static_cast<std::size_t>(2 * P - 1)) << "IDs are recycled";
    // Every leaf's path has exactly one pose per step (merged correctly through collapses).
    for (int n : leaves) {
      const auto path = tree.fullPath(n);
      ASSERT_EQ(path.size(), 2998u);
      for (std::size_t k = 0; k < path.size(); ++k) ASSERT_EQ(path[k].stamp, 2.0 + k);
    }
    if (P > 2) {
      EXPECT_GT(max_nodes, static_cast<std::size_t>(P));
    }
  }
}
