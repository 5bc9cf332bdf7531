// DP-SLAM's ancestry tree: one node per particle lineage segment, small recycled integer IDs, pruning of
// childless nodes and collapsing of only-children, so that P leaves never need more than 2P−1 nodes.
// The tree knows nothing about the map: whatever a node owns (its map entries) is handled through the
// AncestryHooks the caller passes in. No ROS.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "laser_dpslam/common/trajectory_io.h"

namespace laser_dpslam {

/// What the owner of per-node data (the map) must do when the tree deletes or merges nodes.
class AncestryHooks {
 public:
  virtual ~AncestryHooks() = default;
  /// Node `id` is being deleted: free everything it owns (its ID is recycled right after).
  virtual void deleteNode(int id) = 0;
  /// Only-child `child` is collapsing into `parent`: everything `child` owns now belongs to `parent`
  /// (where both own something for the same key, the newer — the child's — wins).
  virtual void mergeChildIntoParent(int child, int parent) = 0;
};

/// Hooks that do nothing (a tree on its own, e.g. in tests).
class NoAncestryHooks : public AncestryHooks {
 public:
  void deleteNode(int) override {}
  void mergeChildIntoParent(int, int) override {}
};

class AncestryTree {
 public:
  struct Node {
    int parent = -1;                ///< -1 for the root
    int children = 0;               ///< surviving children
    int generation = 0;             ///< filter iteration at which the node was created
    bool used = false;              ///< false: the ID is free
    std::vector<StampedPose> path;  ///< poses recorded while this node was a leaf, oldest first
  };

  AncestryTree() = default;

  /// Forgets everything (all IDs free).
  void clear();

  /// A new root node (the tree must be empty). Returns its ID.
  int createRoot(int generation = 0);
  /// A new child of `parent` (its children count goes up by one). Returns the child's ID: the most
  /// recently freed one (IDs are recycled from a stack), else the next new one.
  int createChild(int parent, int generation);

  /// Deletes a childless node: hooks.deleteNode(id), ID freed, and the parent loses a child; a parent
  /// left with no children is pruned the same way (recursively). Returns how many nodes were deleted.
  int prune(int id, AncestryHooks& hooks);

  /// `parent` has exactly one child: the child is merged into it (hooks.mergeChildIntoParent, path
  /// appended to the parent's, the child's children become the parent's, the child's ID is freed).
  /// `parent` keeps its ID. Returns the former ID of the child.
  int collapse(int parent, AncestryHooks& hooks);

  /// Collapses every node that has exactly one child, until none is left. `on_merge(child, parent)` is
  /// called after each merge (so the caller can re-point whatever referenced the child's ID).
  template <class F>
  void collapseAll(AncestryHooks& hooks, F on_merge) {
    for (bool again = true; again;) {
      again = false;
      for (int id = 0; id < static_cast<int>(nodes_.size()); ++id) {
        if (nodes_[id].used && nodes_[id].children == 1) {
          const int child = collapse(id, hooks);
          on_merge(child, id);
          again = true;
        }
      }
    }
  }

  /// One filter iteration (DP-SLAM's ancestry maintenance). `leaves[i]` is the node of old particle i;
  /// new particle j descends from old particle `parent_of[j]`. Old particles with no descendant are pruned,
  /// only-children are collapsed into their parents, then an old particle with exactly one descendant
  /// hands it its node, and one with several gets a new child node for each. Returns the node of every
  /// new particle. Afterwards every internal node has ≥ 2 children, so the tree has ≤ 2P − 1 nodes.
  /// `lineage_nodes` (optional) receives, for each old particle, the node its lineage now owns alone (its
  /// old leaf, or the node that leaf collapsed into; an ancestor-or-self of exactly its descendants'
  /// nodes), or -1 if it left no descendant: what that particle saw is what that node sees.
  std::vector<int> advance(const std::vector<int>& leaves, const std::vector<int>& parent_of, int generation,
                           AncestryHooks& hooks, std::vector<int>* lineage_nodes = nullptr);

  bool valid(int id) const { return id >= 0 && id < static_cast<int>(nodes_.size()) && nodes_[id].used; }
  const Node& node(int id) const { return nodes_[id]; }
  Node& node(int id) { return nodes_[id]; }
  int parent(int id) const { return nodes_[id].parent; }

  std::size_t size() const { return live_; }               ///< nodes in use
  std::size_t idCapacity() const { return nodes_.size(); }  ///< IDs ever handed out (max ID + 1)
  int root() const { return root_; }

  /// `id`, its parent, …, the root.
  std::vector<int> lineage(int id) const;
  /// Whether `ancestor` is `id` or one of its ancestors.
  bool isAncestor(int ancestor, int id) const;
  /// The whole path of a leaf: the path segments of its lineage, root first.
  std::vector<StampedPose> fullPath(int id) const;

  /// Checks the structure: children counts match, one root, no cycles, every internal node has at least
  /// `min_children` children. Returns an empty string when consistent, else what is wrong.
  std::string check(int min_children = 1) const;

 private:
  int allocate();
  void release(int id);

  std::vector<Node> nodes_;
  std::vector<int> free_ids_;  ///< stack of free IDs
  std::size_t live_ = 0;
  int root_ = -1;
};

}  // namespace laser_dpslam
