#pragma once
// The component tree (max-tree) of an integer image: for every threshold t, the 8-connected
// components of {level >= t} are nodes, nested as t falls. Both threshold-sweep methods of the
// room segmentation survey (erosion sweeps, distance-transform sweeps) ask the same question of
// every threshold -- which components have a room's area -- and the tree answers it for all
// thresholds in one pass over the image instead of one labelling per threshold.
#include <cstdint>
#include <vector>

#include "kartograf/core/image.hpp"

namespace kartograf::rooms {

struct ComponentNode {
  int level = 0;            // the component is {level >= this} around its pixels
  int parent = -1;          // the node it merges into at a lower level (-1: a root)
  std::uint32_t cells = 0;  // pixels in the component
};

struct ComponentTree {
  std::vector<ComponentNode> nodes;   // parents come after their children
  std::vector<std::int32_t> node_of;  // per pixel: the node at the pixel's own level (-1: level 0)
  // The pixels of node n and of every node below it: the component itself.
  std::vector<std::uint32_t> pixels_of(int n) const;
  int width = 0;
};

// Pixels with level <= 0 belong to no component. Levels must be below 65536.
ComponentTree build_component_tree(const Image<std::int32_t>& levels);

}  // namespace kartograf::rooms
