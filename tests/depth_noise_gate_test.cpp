// ICP's finest gate from the depth noise (registration/depth_noise_gate.hpp): the median depth of
// a frame, the gate it gives against the fixed one, the engine taking it, and bad parameters.
#include "kartograf/registration/depth_noise_gate.hpp"

#include <gtest/gtest.h>

#include "kartograf/compute/context.hpp"
#include "kartograf/core/error.hpp"
#include "kartograf/registration/icp.hpp"

namespace kartograf::registration {
namespace {

TEST(DepthNoiseGate, TheMedianOfTheValidSampledPixels) {
  DepthImage depth(8, 4);
  for (std::size_t i = 0; i < depth.size(); ++i)
    depth.pixels()[i] = static_cast<std::uint16_t>(i % 4 == 3 ? 0 : 1000 + 100 * (i % 4));
  // Valid: 1000, 1100, 1200 (mm) in turn, a hole every 4th pixel: the median 1.1 m.
  EXPECT_DOUBLE_EQ(median_depth_m(depth, 1000.0, 1), 1.1);
  EXPECT_DOUBLE_EQ(median_depth_m(depth, 1000.0, 2), 1.2);  // pixels 0, 2, 4, ...: 1000 and 1200
  EXPECT_DOUBLE_EQ(median_depth_m(DepthImage(4, 4), 1000.0, 1), 0.0);  // no valid pixel
}

TEST(DepthNoiseGate, WidensTheFixedGateOnlyForDeepFrames) {
  const DepthNoiseGateParams params;
  // Nguyen et al.'s Kinect: 1.5 mm at 1 m, 18 mm at 3.4 m; three of them against 3 cm.
  EXPECT_NEAR(params.sigma_at(1.0), 0.0012 + 0.0019 * 0.36, 1e-12);
  EXPECT_DOUBLE_EQ(depth_noise_gate(0.03, 1.8, params), 0.03);
  EXPECT_DOUBLE_EQ(depth_noise_gate(0.03, 2.4, params), 0.03);
  EXPECT_NEAR(depth_noise_gate(0.03, 3.4, params), 3 * (0.0012 + 0.0019 * 9), 1e-12);
  EXPECT_GT(depth_noise_gate(0.03, 3.4, params), 0.05);
  EXPECT_DOUBLE_EQ(depth_noise_gate(0.03, 0.0, params), 0.03);  // no median
  DepthNoiseGateParams off;
  off.sigmas = 0;
  EXPECT_DOUBLE_EQ(depth_noise_gate(0.03, 3.4, off), 0.03);
}

TEST(DepthNoiseGate, BadParametersAndGatesAreErrors) {
  DepthNoiseGateParams params;
  params.stride = 0;
  EXPECT_THROW(params.validate(), Error);
  params = {};
  params.b = -1;
  EXPECT_THROW(params.validate(), Error);
  compute::ContextParams cpu;
  cpu.backend = compute::BackendChoice::cpu;
  const compute::Context context(cpu);
  IcpEngine engine(context);
  engine.set_max_distance(0, 0.05);
  EXPECT_DOUBLE_EQ(engine.params().levels[0].max_distance, 0.05);
  EXPECT_THROW(engine.set_max_distance(engine.params().levels.size(), 0.05), Error);
  EXPECT_THROW(engine.set_max_distance(0, 0.0), Error);
}

}  // namespace
}  // namespace kartograf::registration
