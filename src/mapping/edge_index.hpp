#pragma once
// The vertex of a mesh edge, by the edge's key (src/mapping/tsdf_mesh.cpp and
// tsdf_mesh_device.cpp join the vertices that triangles share through it).
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace kartograf::mapping::detail {

// Vertex indices by edge key: open addressing with linear probing (a key is never 0). Against
// std::unordered_map: no allocation per entry, and a probe stays in one cache line.
class EdgeIndex {
 public:
  // The index stored for key; where key is new, `next` is stored and inserted set.
  int find_or_add(std::uint64_t key, int next, bool& inserted) {
    if ((count_ + 1) * 2 > keys_.size()) grow();
    const std::size_t mask = keys_.size() - 1;
    for (std::size_t slot = spread(key) & mask;; slot = (slot + 1) & mask) {
      if (keys_[slot] == key) {
        inserted = false;
        return values_[slot];
      }
      if (keys_[slot] == 0) {
        keys_[slot] = key;
        values_[slot] = next;
        ++count_;
        inserted = true;
        return next;
      }
    }
  }

 private:
  static std::size_t spread(std::uint64_t key) {
    return static_cast<std::size_t>((key * 0x9e3779b97f4a7c15ull) >> 17);
  }
  void grow() {
    std::vector<std::uint64_t> keys(std::max<std::size_t>(keys_.size() * 2, 1 << 16), 0);
    std::vector<int> values(keys.size());
    const std::size_t mask = keys.size() - 1;
    for (std::size_t i = 0; i < keys_.size(); ++i) {
      if (keys_[i] == 0) continue;
      std::size_t slot = spread(keys_[i]) & mask;
      while (keys[slot] != 0) slot = (slot + 1) & mask;
      keys[slot] = keys_[i];
      values[slot] = values_[i];
    }
    keys_ = std::move(keys);
    values_ = std::move(values);
  }
  std::vector<std::uint64_t> keys_;
  std::vector<int> values_;
  std::size_t count_ = 0;
};

}  // namespace kartograf::mapping::detail
