#include "kartograf/registration/robust_kernel.hpp"

#include "kernels/icp_sums/icp_sums.h"

namespace kartograf::registration {

static_assert(static_cast<std::uint32_t>(RobustKernel::none) == KG_ROBUST_NONE &&
                  static_cast<std::uint32_t>(RobustKernel::huber) == KG_ROBUST_HUBER &&
                  static_cast<std::uint32_t>(RobustKernel::tukey) == KG_ROBUST_TUKEY,
              "RobustKernel's values are the kernels' KG_ROBUST_*");

double robust_weight(const RobustLoss& loss, double residual) {
  return kernels::robust_kernel_weight(static_cast<std::uint32_t>(loss.kernel), loss.scale,
                                       residual);
}

}  // namespace kartograf::registration
