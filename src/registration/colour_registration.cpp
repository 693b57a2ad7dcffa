#include "kartograf/registration/colour_registration.hpp"

#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include "kartograf/core/error.hpp"
#include "photometric_images.hpp"

namespace kartograf::registration {

const char* to_string(ColourRegistration verdict) {
  switch (verdict) {
    case ColourRegistration::registered:
      return "registered";
    case ColourRegistration::not_registered:
      return "not registered";
    case ColourRegistration::undecided:
      break;
  }
  return "undecided";
}

void ColourRegistrationParams::validate() const {
  require(std::isfinite(depth_step) && depth_step > 0,
          "colour registration: depth_step must be finite and > 0");
  require(std::isfinite(registered_contrast) && std::isfinite(unregistered_contrast) &&
              unregistered_contrast <= registered_contrast,
          "colour registration: the contrasts must be finite, unregistered <= registered");
  require(min_steps >= 1 && max_frames >= 1,
          "colour registration: min_steps and max_frames must be >= 1");
}

namespace {

// The grey level's gradient magnitude, as the photometric refinement sees it (zero at the border).
std::vector<float> gradient_magnitude(const RgbImage& colour) {
  const detail::Textured grey(detail::grey_of(colour));
  const auto dx = grey.dx.pixels(), dy = grey.dy.pixels();
  std::vector<float> magnitude(dx.size());
  for (std::size_t i = 0; i < magnitude.size(); ++i)
    magnitude[i] = std::sqrt(dx[i] * dx[i] + dy[i] * dy[i]);
  return magnitude;
}

bool is_step(std::uint16_t a, std::uint16_t b, double depth_step) {
  if (a == 0 || b == 0) return false;
  return std::abs(int(a) - int(b)) > depth_step * std::min(a, b);
}

}  // namespace

void ColourEdgeProfile::add(const DepthImage& depth, const RgbImage& colour, double depth_step) {
  require(depth.width() == colour.width() && depth.height() == colour.height(),
          "colour registration: the depth is " + std::to_string(depth.width()) + "x" +
              std::to_string(depth.height()) + " but the colour " + std::to_string(colour.width()) +
              "x" + std::to_string(colour.height()));
  const int width = depth.width(), height = depth.height();
  if (width <= 2 * kReach + 2 || height <= 2 * kReach + 2) return;
  const std::vector<float> magnitude = gradient_magnitude(colour);
  const auto at = [&](int x, int y) { return magnitude[static_cast<std::size_t>(y) * width + x]; };
  const std::uint16_t* d = depth.data();
  // A step between (x, y) and its right or lower neighbour: both pixels' profiles along its axis.
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const std::uint16_t here = d[static_cast<std::size_t>(y) * width + x];
      if (x >= kReach && x + 1 + kReach < width &&
          is_step(here, d[y * width + x + 1], depth_step)) {
        for (int s = -kReach; s <= kReach; ++s)
          sums_[s + kReach] += at(x + s, y) + at(x + 1 + s, y);
        ++steps_;
      }
      if (y >= kReach && y + 1 + kReach < height &&
          is_step(here, d[(y + 1) * width + x], depth_step)) {
        for (int s = -kReach; s <= kReach; ++s)
          sums_[s + kReach] += at(x, y + s) + at(x, y + 1 + s);
        ++steps_;
      }
    }
  }
}

double ColourEdgeProfile::contrast() const {
  double far = 0;
  int count = 0;
  for (int s = 4; s <= kReach; ++s) {
    far += sums_[kReach + s] + sums_[kReach - s];
    count += 2;
  }
  far /= count;
  return steps_ == 0 || far <= 0 ? 0.0 : sums_[kReach] / far;
}

ColourRegistrationCheck::ColourRegistrationCheck(ColourRegistrationParams params)
    : params_(params) {
  params_.validate();
}

void ColourRegistrationCheck::add(const DepthImage& depth, const RgbImage& colour) {
  if (done()) return;
  ++frames_;
  profile_.add(depth, colour, params_.depth_step);
  if (profile_.steps() < params_.min_steps) return;
  const double contrast = profile_.contrast();
  if (contrast >= params_.registered_contrast) verdict_ = ColourRegistration::registered;
  if (contrast < params_.unregistered_contrast) verdict_ = ColourRegistration::not_registered;
}

}  // namespace kartograf::registration
