#pragma once
// Random twists for the SE(3) and pose-graph tests (core only).
#include <random>

#include "kartograf/core/se3.hpp"

namespace kartograf::testing {

// Rotation and translation parts uniform in [-rotation, rotation] and [-translation, translation].
inline se3::Vector6d random_twist(std::mt19937_64& rng, double rotation, double translation) {
  std::uniform_real_distribution<double> u(-1, 1);
  se3::Vector6d xi;
  for (int k = 0; k < 3; ++k) xi(k) = rotation * u(rng);
  for (int k = 3; k < 6; ++k) xi(k) = translation * u(rng);
  return xi;
}

}  // namespace kartograf::testing
