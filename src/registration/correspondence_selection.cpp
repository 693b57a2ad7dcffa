#include "kartograf/registration/correspondence_finder.hpp"
#include "kernels/correspondence/selection.h"

namespace kartograf::registration {

bool is_selected(std::uint32_t i, std::uint32_t width, std::uint32_t k) {
  return kernels::correspondence_selected(i, width, k);
}

}  // namespace kartograf::registration
