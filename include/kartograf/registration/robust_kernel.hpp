#pragma once
// Robust kernels for ICP as iteratively reweighted least squares: each pair's weight is a function
// of its residual at the current estimate (point-to-plane: the signed plane distance; point-to-
// point: the distance), so pairs that do not fit (a moved object, a wrong match) pull less or not
// at all. The weight's rule is written once, in kernels/icp_sums/icp_sums.h: the ICP reductions
// apply it on every backend, and robust_weight below calls it.
#include <cstdint>

namespace kartograf::registration {

enum class RobustKernel : std::uint32_t {
  none = 0,   // w = 1
  huber = 1,  // w = 1 for |r| <= c, c / |r| beyond: quadratic near zero, linear in the tails
  tukey = 2,  // w = (1 - (r/c)^2)^2 for |r| < c, 0 beyond: pairs farther than c are ignored
};

struct RobustLoss {
  RobustKernel kernel = RobustKernel::none;
  double scale = 0.05;  // c, in metres (the residual's unit); must be > 0 unless kernel is none
};

// The weight of a pair with this residual (see RobustKernel).
double robust_weight(const RobustLoss& loss, double residual);

}  // namespace kartograf::registration
