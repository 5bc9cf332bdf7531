#include "laser_dpslam/slam/ancestry_tree.h"

#include <algorithm>
#include <stdexcept>

namespace laser_dpslam {

void AncestryTree::clear() {
  nodes_.clear();
  free_ids_.clear();
  live_ = 0;
  root_ = -1;
}

int AncestryTree::allocate() {
  int id;
  if (!free_ids_.empty()) {
    id = free_ids_.back();
    free_ids_.pop_back();
  } else {
    id = static_cast<int>(nodes_.size());
    nodes_.emplace_back();
  }
  Node& n = nodes_[id];
  n = Node();
  n.used = true;
  ++live_;
  return id;
}

void AncestryTree::release(int id) {
  Node& n = nodes_[id];
  n.used = false;
  n.parent = -1;
  n.children = 0;
  std::vector<StampedPose>().swap(n.path);  // free the storage
  free_ids_.push_back(id);
  --live_;
  if (root_ == id) root_ = -1;
}

int AncestryTree::createRoot(int generation) {
  if (live_ != 0) throw std::logic_error("AncestryTree::createRoot: the tree is not empty");
  root_ = allocate();
  nodes_[root_].generation = generation;
  return root_;
}

int AncestryTree::createChild(int parent, int generation) {
  if (!valid(parent)) throw std::logic_error("AncestryTree::createChild: invalid parent");
  const int id = allocate();
  nodes_[id].parent = parent;
  nodes_[id].generation = generation;
  ++nodes_[parent].children;
  return id;
}

int AncestryTree::prune(int id, AncestryHooks& hooks) {
  int deleted = 0;
  while (id >= 0) {
    if (!valid(id) || nodes_[id].children != 0) throw std::logic_error("AncestryTree::prune: node has children");
    const int parent = nodes_[id].parent;
    hooks.deleteNode(id);
    release(id);
    ++deleted;
    if (parent < 0) break;
    id = --nodes_[parent].children == 0 ? parent : -1;
  }
  return deleted;
}

int AncestryTree::collapse(int parent, AncestryHooks& hooks) {
  if (!valid(parent) || nodes_[parent].children != 1) throw std::logic_error("AncestryTree::collapse: not an only child");
  int child = -1;
  for (int i = 0; i < static_cast<int>(nodes_.size()); ++i) {
    if (nodes_[i].used && nodes_[i].parent == parent) {
      child = i;
      break;
    }
  }
  if (child < 0) throw std::logic_error("AncestryTree::collapse: child not found");
  hooks.mergeChildIntoParent(child, parent);
  Node& p = nodes_[parent];
  Node& c = nodes_[child];
  p.path.insert(p.path.end(), c.path.begin(), c.path.end());
  p.children = c.children;
  for (Node& n : nodes_) {
    if (n.used && n.parent == child) n.parent = parent;
  }
  c.children = 0;
  release(child);
  return child;
}

std::vector<int> AncestryTree::advance(const std::vector<int>& leaves, const std::vector<int>& parent_of,
                                       int generation, AncestryHooks& hooks, std::vector<int>* lineage_nodes) {
  std::vector<int> counts(leaves.size(), 0);
  for (int p : parent_of) {
    if (p < 0 || p >= static_cast<int>(leaves.size())) throw std::out_of_range("AncestryTree::advance: bad parent index");
    ++counts[p];
  }
  for (std::size_t i = 0; i < leaves.size(); ++i) {
    if (!valid(leaves[i]) || nodes_[leaves[i]].children != 0) throw std::logic_error("AncestryTree::advance: not a leaf");
  }
  // 1. Prune lineages that died (recursively up).
  for (std::size_t i = 0; i < leaves.size(); ++i) {
    if (counts[i] == 0) prune(leaves[i], hooks);
  }
  // 2. Collapse only-children; a surviving leaf merged into its parent now lives in the parent's node.
  std::vector<int> now = leaves;
  collapseAll(hooks, [&](int child, int parent) {
    for (std::size_t i = 0; i < now.size(); ++i) {
      if (counts[i] > 0 && now[i] == child) now[i] = parent;
    }
  });
  // 3. The new generation.
  std::vector<int> out(parent_of.size());
  for (std::size_t j = 0; j < parent_of.size(); ++j) {
    const int i = parent_of[j];
    out[j] = counts[i] == 1 ? now[i] : createChild(now[i], generation);
  }
  if (lineage_nodes) {
    lineage_nodes->assign(leaves.size(), -1);
    for (std::size_t i = 0; i < leaves.size(); ++i) {
      if (counts[i] > 0) (*lineage_nodes)[i] = now[i];
    }
  }
  return out;
}

std::vector<int> AncestryTree::lineage(int id) const {
  std::vector<int> out;
  for (; id >= 0; id = nodes_[id].parent) out.push_back(id);
  return out;
}

bool AncestryTree::isAncestor(int ancestor, int id) const {
  for (; id >= 0; id = nodes_[id].parent) {
    if (id == ancestor) return true;
  }
  return false;
}

std::vector<StampedPose> AncestryTree::fullPath(int id) const {
  std::vector<int> line = lineage(id);
  std::size_t total = 0;
  for (int n : line) total += nodes_[n].path.size();
  std::vector<StampedPose> out;
  out.reserve(total);
  for (auto it = line.rbegin(); it != line.rend(); ++it) {
    const auto& p = nodes_[*it].path;
    out.insert(out.end(), p.begin(), p.end());
  }
  return out;
}

std::string AncestryTree::check(int min_children) const {
  std::vector<int> counted(nodes_.size(), 0);
  int roots = 0;
  std::size_t live = 0;
  for (std::size_t i = 0; i < nodes_.size(); ++i) {
    const Node& n = nodes_[i];
    if (!n.used) continue;
    ++live;
    if (n.parent < 0) {
      ++roots;
      if (static_cast<int>(i) != root_) return "node " + std::to_string(i) + " is a root but not the root";
    } else if (!valid(n.parent)) {
      return "node " + std::to_string(i) + " has a freed parent";
    } else {
      ++counted[n.parent];
    }
    // No cycles: the walk to the root is shorter than the number of nodes.
    std::size_t steps = 0;
    for (int a = static_cast<int>(i); a >= 0; a = nodes_[a].parent) {
      if (++steps > nodes_.size()) return "cycle through node " + std::to_string(i);
    }
  }
  if (live != live_) return "live count mismatch";
  if (live > 0 && roots != 1) return std::to_string(roots) + " roots";
  for (std::size_t i = 0; i < nodes_.size(); ++i) {
    if (!nodes_[i].used) continue;
    if (counted[i] != nodes_[i].children) {
      return "node " + std::to_string(i) + " counts " + std::to_string(nodes_[i].children) + " children, has " +
             std::to_string(counted[i]);
    }
    if (counted[i] > 0 && counted[i] < min_children) {
      return "node " + std::to_string(i) + " has only " + std::to_string(counted[i]) + " child(ren)";
    }
  }
  if (free_ids_.size() + live_ != nodes_.size()) return "free ID stack inconsistent";
  return std::string();
}

}  // namespace laser_dpslam
