// Which source points a correspondence search considers (registration::is_selected): point i of a
// cloud whose rows are `width` points long (0: unorganized) is selected when (i + row) % k == 0, so
// an organized frame gets a diagonal lattice rather than every k-th column. One rule for every
// finder: projective association, the voxel-hash search and the k-d tree.
#ifndef KARTOGRAF_KERNELS_CORRESPONDENCE_SELECTION_H
#define KARTOGRAF_KERNELS_CORRESPONDENCE_SELECTION_H
#include "shaders/prelude.h"

KG_RULES_BEGIN

KG_INLINE bool correspondence_selected(uint i, uint width, uint k) {
  const uint row = width == 0u ? 0u : i / width;
  return (i + row) % k == 0u;
}

KG_RULES_END

#endif
