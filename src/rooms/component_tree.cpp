#include "kartograf/rooms/component_tree.hpp"

#include <algorithm>
#include <numeric>
#include <string>

#include "kartograf/core/error.hpp"
#include "rooms/grid_neighbours.hpp"

namespace kartograf::rooms {

namespace {

std::uint32_t find(std::vector<std::uint32_t>& parent, std::uint32_t i) {
  while (parent[i] != i) i = parent[i] = parent[parent[i]];
  return i;
}

// The pixels of level > 0 by decreasing level, in scan order within a level (a counting sort).
// Throws Error for a level >= 65536.
std::vector<std::uint32_t> pixels_by_decreasing_level(const Image<std::int32_t>& levels) {
  const std::size_t n = levels.size();
  int top = 0;
  for (const std::int32_t l : levels.pixels()) {
    require(l < 65536, "component tree: a level is >= 65536");
    top = std::max(top, static_cast<int>(l));
  }
  std::vector<std::uint32_t> start(static_cast<std::size_t>(top) + 2, 0);
  for (const std::int32_t l : levels.pixels()) {
    if (l > 0) ++start[static_cast<std::size_t>(l)];
  }
  for (int l = top; l >= 1; --l) start[static_cast<std::size_t>(l) - 1] += start[l];
  // start[l] now counts pixels with level >= l; order: level top first.
  std::vector<std::uint32_t> order(start.empty() ? 0 : start[1]);
  std::vector<std::uint32_t> fill(start.size(), 0);
  for (int l = top; l >= 1; --l)
    fill[static_cast<std::size_t>(l)] = start[static_cast<std::size_t>(l) + 1];
  for (std::size_t i = 0; i < n; ++i) {
    const std::int32_t l = levels.data()[i];
    if (l > 0) order[fill[static_cast<std::size_t>(l)]++] = static_cast<std::uint32_t>(i);
  }
  return order;
}

}  // namespace

ComponentTree build_component_tree(const Image<std::int32_t>& levels) {
  const int width = levels.width(), height = levels.height();
  const std::size_t n = levels.size();
  ComponentTree tree;
  tree.width = width;
  tree.node_of.assign(n, -1);
  const std::vector<std::uint32_t> order = pixels_by_decreasing_level(levels);

  std::vector<std::uint32_t> parent(n), size(n, 0);
  std::vector<std::int32_t> node_of_root(n, -1);  // the root's current component node
  std::vector<std::uint8_t> made(n, 0);
  std::vector<std::uint32_t> touched;  // roots touched at this level
  // Per touched root: the nodes it absorbed. Entries are reused across levels (only the first
  // `used` are live) so that their storage is not allocated again at every level.
  std::vector<std::vector<std::int32_t>> children;
  std::size_t used = 0;
  std::vector<std::int32_t> slot(n, -1);  // root -> index into touched
  std::size_t k = 0;
  while (k < order.size()) {
    const std::int32_t level = levels.data()[order[k]];
    std::size_t end = k;
    while (end < order.size() && levels.data()[order[end]] == level) ++end;
    touched.clear();
    used = 0;
    const auto touch = [&](std::uint32_t root) {
      if (slot[root] >= 0) return;
      slot[root] = static_cast<std::int32_t>(touched.size());
      touched.push_back(root);
      if (used == children.size()) children.emplace_back();
      std::vector<std::int32_t>& absorbed = children[used++];
      absorbed.clear();
      if (node_of_root[root] >= 0) absorbed.push_back(node_of_root[root]);
    };
    for (std::size_t j = k; j < end; ++j) {
      const std::uint32_t p = order[j];
      parent[p] = p;
      size[p] = 1;
      made[p] = 1;
      touch(p);
    }
    for (std::size_t j = k; j < end; ++j) {
      const std::uint32_t p = order[j];
      detail::for_each_neighbour8(p, width, height, [&](std::uint32_t q) {
        if (!made[q]) return;
        std::uint32_t a = find(parent, p), b = find(parent, q);
        if (a == b) return;
        touch(a);
        touch(b);
        if (size[a] < size[b]) std::swap(a, b);
        parent[b] = a;
        size[a] += size[b];
        // b's absorbed nodes move to a.
        auto& from = children[static_cast<std::size_t>(slot[b])];
        auto& into = children[static_cast<std::size_t>(slot[a])];
        into.insert(into.end(), from.begin(), from.end());
        from.clear();
      });
    }
    // One node per component touched at this level.
    for (const std::uint32_t r : touched) {
      if (find(parent, r) != r) continue;
      const auto id = static_cast<std::int32_t>(tree.nodes.size());
      tree.nodes.push_back({level, -1, size[r]});
      for (const std::int32_t child : children[static_cast<std::size_t>(slot[r])])
        tree.nodes[static_cast<std::size_t>(child)].parent = id;
      node_of_root[r] = id;
    }
    for (std::size_t j = k; j < end; ++j) {
      tree.node_of[order[j]] = node_of_root[find(parent, order[j])];
    }
    for (const std::uint32_t r : touched) slot[r] = -1;
    k = end;
  }
  return tree;
}

std::vector<std::uint32_t> ComponentTree::pixels_of(int n) const {
  // Marks n's subtree (children come before parents, so one backward sweep finds it).
  std::vector<std::uint8_t> inside(nodes.size(), 0);
  inside[static_cast<std::size_t>(n)] = 1;
  for (int i = n - 1; i >= 0; --i) {
    const int p = nodes[static_cast<std::size_t>(i)].parent;
    if (p >= 0 && p <= n && inside[static_cast<std::size_t>(p)])
      inside[static_cast<std::size_t>(i)] = 1;
  }
  std::vector<std::uint32_t> pixels;
  for (std::size_t i = 0; i < node_of.size(); ++i) {
    if (node_of[i] >= 0 && inside[static_cast<std::size_t>(node_of[i])])
      pixels.push_back(static_cast<std::uint32_t>(i));
  }
  return pixels;
}

}  // namespace kartograf::rooms
