// Device-side copies, recycled device buffers, device limits and the device timings that
// kartograf_gpu_check reports (ContextParams::profile), on every backend.
#include <algorithm>
#include <numeric>
#include <set>
#include <string>
#include <vector>

#include "kartograf/compute/backend.hpp"
#include "kartograf/compute/buffer.hpp"
#include "kartograf/core/error.hpp"
#include "kartograf/geometry/backproject.hpp"
#include "test_support.hpp"

namespace kartograf {
namespace {

using testing::BackendTest;

class DeviceRuntimeTest : public BackendTest {
 protected:
  std::vector<std::uint32_t> random_words(std::size_t count) {
    std::vector<std::uint32_t> words(count);
    std::uniform_int_distribution<std::uint32_t> any;
    for (std::uint32_t& word : words) word = any(rng);
    return words;
  }
};

TEST_P(DeviceRuntimeTest, CopiesBetweenBuffersWithoutTheHost) {
  const std::vector<std::uint32_t> words = random_words(100003);
  auto source = compute::Buffer<std::uint32_t>::from_host(context(), words);
  compute::Buffer<std::uint32_t> target(context(), words.size() + 5);
  target.fill_zero();
  target.raw().copy_from(source.raw(), 4 * 1001);  // a prefix: the rest stays zero
  std::vector<std::uint32_t> back = target.to_vector();
  EXPECT_TRUE(std::equal(words.begin(), words.begin() + 1001, back.begin()));
  EXPECT_TRUE(std::all_of(back.begin() + 1001, back.end(), [](std::uint32_t w) { return w == 0; }));
  target.raw().copy_from(source.raw(), source.raw().size_bytes());
  back = target.to_vector();
  EXPECT_TRUE(std::equal(words.begin(), words.end(), back.begin()));

  EXPECT_ERROR_MENTIONS(source.raw().copy_from(target.raw(), target.raw().size_bytes()),
                        "copy target", "outside");
  compute::Buffer<std::uint32_t> small(context(), 10);
  EXPECT_ERROR_MENTIONS(target.raw().copy_from(small.raw(), 44), "copy source", "outside");
  const compute::Context cpu = compute::Context::cpu();
  compute::RawBuffer elsewhere(cpu, 64);
  if (!context().is_cpu()) {
    EXPECT_ERROR_MENTIONS(target.raw().copy_from(elsewhere, 64), "another context");
  }
}

TEST_P(DeviceRuntimeTest, ARecycledBufferHoldsWhatIsWrittenToIt) {
  // Vulkan keeps freed buffers for reuse by the next buffer of the same size (discrete GPUs pay
  // ~1 ms per allocation): the reused one must behave like a new one, staged or mapped.
  for (int round = 0; round < 3; ++round) {
    const std::vector<std::uint32_t> words = random_words(65536);
    compute::Buffer<std::uint32_t> buffer(context(), words.size());
    buffer.upload(words);
    EXPECT_EQ(buffer.to_vector(), words) << "round " << round;
  }
}

TEST_P(DeviceRuntimeTest, ReportsLimitsItsKernelsNeed) {
  const compute::DeviceLimits& limits = context().device_info().limits;
  EXPECT_TRUE(limits.fp64);
  EXPECT_TRUE(limits.int64_atomics);
  if (!context().is_cpu()) {
    EXPECT_GE(limits.max_workgroup_invocations, 256u);  // the 16x16 and 256-wide kernels
    EXPECT_GE(limits.shared_memory_bytes, 16u * 1024u);
    EXPECT_TRUE(limits.device_timestamps);
  }
  const std::string line = compute::describe(limits);
  EXPECT_NE(line.find("fp64 yes"), std::string::npos) << line;
}

TEST_P(DeviceRuntimeTest, ProfilingTimesEveryCommandOnTheDevice) {
  compute::ContextParams options;
  options.backend = compute::choice_of(GetParam());
  options.vulkan_validation = true;
  options.profile = true;
  const compute::Context profiled(options);
  const PinholeIntrinsics camera{64, 48, 60.0, 60.0, 31.5, 23.5};
  DepthImage depth(camera.width, camera.height);
  std::uniform_int_distribution<int> millimetres(500, 4000);
  for (std::size_t i = 0; i < depth.size(); ++i)
    depth.data()[i] = static_cast<std::uint16_t>(millimetres(rng));
  const geometry::DepthBackprojector projector(profiled, camera, geometry::DepthRange{});
  auto device_depth = compute::DeviceImage<std::uint16_t>::from_host(profiled, depth);
  compute::DeviceImage<Point4f> points(profiled, camera.width, camera.height),
      copy(profiled, camera.width, camera.height);
  profiled.take_device_timings();  // the set-up's
  projector.run(device_depth, points);
  copy.buffer().raw().copy_from(points.buffer().raw(), points.buffer().raw().size_bytes());
  copy.buffer().fill_zero();
  const std::vector<compute::DeviceTiming> timings = profiled.take_device_timings();
  if (profiled.is_cpu()) {
    EXPECT_TRUE(timings.empty());  // the CPU runs operations on the host: nothing to time there
    return;
  }
  std::vector<std::string> commands;
  for (const compute::DeviceTiming& timing : timings) {
    commands.push_back(timing.command);
    EXPECT_GE(timing.milliseconds, 0.0) << timing.command;
    EXPECT_LT(timing.milliseconds, 10000.0) << timing.command;
  }
  EXPECT_EQ(commands, (std::vector<std::string>{"backproject", "copy", "fill"}));
  EXPECT_TRUE(profiled.take_device_timings().empty());  // each command is reported once
  EXPECT_EQ(profiled.validation_errors(), 0u);
  // Without profiling nothing is recorded.
  EXPECT_TRUE(context().take_device_timings().empty());
}

KARTOGRAF_INSTANTIATE_BACKEND_TESTS(DeviceRuntimeTest);

}  // namespace
}  // namespace kartograf
