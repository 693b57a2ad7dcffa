#include "kartograf/registration/speed_bound.hpp"

#include <algorithm>
#include <cmath>

namespace kartograf::registration {

void SpeedBound::learn(std::size_t frame, double step_m) {
  // Only consecutive frames tell how much the speed can change in one frame.
  if (has_last_ && frame == last_frame_ + 1) {
    largest_change_m_ = std::max(largest_change_m_, std::abs(step_m - last_step_m_));
  }
  has_last_ = true;
  last_frame_ = frame;
  last_step_m_ = step_m;
}

bool SpeedBound::ready() const {
  return margin_ > 0 && largest_change_m_ > least_change_m_;
}

bool SpeedBound::admits(std::size_t frame, double step_m) const {
  if (!ready() || frame <= last_frame_) return true;
  const auto [low, high] = admitted(frame);
  return step_m >= low && step_m <= high;
}

std::pair<double, double> SpeedBound::admitted(std::size_t frame) const {
  const auto frames = static_cast<double>(frame > last_frame_ ? frame - last_frame_ : 1);
  const double change = margin_ * largest_change_m_ * frames;
  return {std::max(0.0, last_step_m_ - change), last_step_m_ + change};
}

}  // namespace kartograf::registration
