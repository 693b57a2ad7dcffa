#pragma once
// Hand-drawn label images for the eval tests: axis-aligned rectangles of one label each, so a
// test states its regions (and the pixel counts its expected scores follow from) in one line.
#include <initializer_list>

#include "kartograf/core/label_image.hpp"

namespace kartograf::testing {

// The pixels [x0, x1) x [y0, y1), all given `label`.
struct LabelRect {
  int x0, y0, x1, y1;
  Label label;
};

// Paints the rectangles over `image` in order (a later one wins where they overlap).
inline void paint(LabelImage& image, std::initializer_list<LabelRect> rects) {
  for (const LabelRect& r : rects) {
    for (int y = r.y0; y < r.y1; ++y) {
      for (int x = r.x0; x < r.x1; ++x) image(x, y) = r.label;
    }
  }
}

// A width x height image of kUnlabeled with the rectangles painted in order.
inline LabelImage label_rectangles(int width, int height, std::initializer_list<LabelRect> rects) {
  LabelImage image(width, height, kUnlabeled);
  paint(image, rects);
  return image;
}

}  // namespace kartograf::testing
