#pragma once
// Robust kernels for ICP as iteratively reweighted least squares: each pair's weight is a function
// of its residual at the current estimate (point-to-plane: the signed plane distance; point-to-
// point: the distance), so pairs that do not fit (a moved object, a wrong match) pull less or not
// at all. The ICP reductions apply this weight on the device (shaders/icp_pairs.glsl,
// kernels/icp_sums.cl); this is the reference they follow.
#include <cmath>
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

inline double robust_weight(const RobustLoss& loss, double residual) {
  const double r = std::fabs(residual);
  switch (loss.kernel) {
    case RobustKernel::huber:
      return r <= loss.scale ? 1.0 : loss.scale / r;
    case RobustKernel::tukey: {
      if (!(r < loss.scale)) return 0.0;
      const double u = r / loss.scale;
      const double s = 1.0 - u * u;
      return s * s;
    }
    case RobustKernel::none:
      break;
  }
  return 1.0;
}

}  // namespace kartograf::registration
