// The compute runtime itself: contexts, buffers, kernel builds, backend selection and errors.
#include <cstdlib>
#include <numeric>
#include <string>

#include "kartograf/compute/backend.hpp"
#include "kartograf/compute/buffer.hpp"
#include "kartograf/compute/kernel.hpp"
#include "kartograf/core/error.hpp"
#include "test_support.hpp"

namespace kartograf {
namespace {

using testing::BackendTest;

class ComputeRuntimeTest : public BackendTest {};

TEST_P(ComputeRuntimeTest, ReportsItsBackendAndDevice) {
  EXPECT_EQ(context().backend(), GetParam());
  const compute::DeviceInfo& info = context().device_info();
  EXPECT_FALSE(info.name.empty());
  EXPECT_FALSE(info.api_version.empty());
  EXPECT_TRUE(info.usable);
  std::cout << compute::to_string(GetParam()) << ": " << info.name << " (" << info.api_version
            << ", " << compute::to_string(info.type) << ")\n";
}

TEST_P(ComputeRuntimeTest, BuildsEveryShaderPipelineAndOpenclKernel) {
  // No kernel is first compiled in a user's hands: every embedded one must build here.
  EXPECT_NO_THROW(context().build_all_kernels());
}

TEST_P(ComputeRuntimeTest, BufferRoundTripsWithOffsetsAndOddSizes) {
  for (std::size_t count : {std::size_t{1}, std::size_t{3}, std::size_t{1001}, std::size_t{1} << 20}) {
    std::vector<std::uint16_t> values(count);
    std::iota(values.begin(), values.end(), std::uint16_t{7});
    auto buffer = compute::Buffer<std::uint16_t>::from_host(context(), values);
    EXPECT_EQ(buffer.to_vector(), values);
    const std::uint16_t patch[2] = {0xffff, 0xfffe};
    if (count >= 3) {
      buffer.upload(patch, 1);
      std::uint16_t back[2] = {};
      buffer.download(back, 1);
      EXPECT_EQ(back[0], 0xffff);
      EXPECT_EQ(back[1], 0xfffe);
    }
    buffer.fill_zero();
    EXPECT_EQ(buffer.to_vector(), std::vector<std::uint16_t>(count, 0));
  }
}

TEST_P(ComputeRuntimeTest, OutOfRangeAccessIsAnError) {
  compute::Buffer<float> buffer(context(), 4);
  std::vector<float> five(5);
  EXPECT_THROW(buffer.upload(five), Error);
  EXPECT_THROW(buffer.download(five), Error);
  std::vector<float> one(1);
  EXPECT_THROW(buffer.download(one, 4), Error);
}

TEST_P(ComputeRuntimeTest, DispatchNeedsADevice) {
  if (GetParam() != compute::BackendKind::cpu) {
    // An unknown kernel name is a clear error, not a crash.
    const std::uint32_t params[1] = {0};
    EXPECT_THROW(compute::dispatch(context(), compute::KernelSpec{"no_such_kernel", 64}, {}, params, {1, 1}),
                 Error);
  } else {
    const std::uint32_t params[1] = {0};
    EXPECT_THROW(compute::dispatch(context(), compute::KernelSpec{"backproject", 16, 16}, {}, params, {1, 1}),
                 Error);
  }
}

KARTOGRAF_INSTANTIATE_BACKEND_TESTS(ComputeRuntimeTest);

TEST(BackendSelection, ParsesChoicesAndRejectsUnknownNames) {
  EXPECT_EQ(compute::parse_backend_choice("auto", "test"), compute::BackendChoice::automatic);
  EXPECT_EQ(compute::parse_backend_choice("vulkan", "test"), compute::BackendChoice::vulkan);
  EXPECT_ERROR_MENTIONS(compute::parse_backend_choice("cuda", "KARTOGRAF_BACKEND"),
                        "KARTOGRAF_BACKEND", "cuda");
}

TEST(BackendSelection, EnvironmentPicksTheBackend) {
  setenv("KARTOGRAF_BACKEND", "cpu", 1);
  EXPECT_EQ(compute::Context::from_environment().backend(), compute::BackendKind::cpu);
  setenv("KARTOGRAF_BACKEND", "bogus", 1);
  EXPECT_THROW(compute::Context::from_environment(), Error);
  unsetenv("KARTOGRAF_BACKEND");
  setenv("KARTOGRAF_DEVICE", "x", 1);
  EXPECT_THROW(compute::ContextOptions::from_environment(), Error);
  unsetenv("KARTOGRAF_DEVICE");
}

TEST(BackendSelection, AutomaticTakesAGpuOrTheCpu) {
  // CPU-hosted drivers (lavapipe, PoCL) are never chosen automatically.
  const compute::Context context{compute::ContextOptions{}};
  if (context.backend() == compute::BackendKind::cpu) {
    for (const auto& status : compute::probe_backends()) {
      for (const auto& device : status.devices) {
        EXPECT_FALSE(device.usable && device.is_gpu());
      }
    }
  } else {
    EXPECT_TRUE(context.device_info().is_gpu());
  }
}

TEST(BackendSelection, ProbeListsEveryBackend) {
  const auto statuses = compute::probe_backends();
  ASSERT_EQ(statuses.size(), 3u);
  EXPECT_EQ(statuses[0].backend, compute::BackendKind::cpu);
  EXPECT_TRUE(statuses[0].available);
  for (const auto& status : statuses) {
    EXPECT_TRUE(status.available || !status.reason.empty()) << compute::to_string(status.backend);
    if (status.available) {
      EXPECT_FALSE(status.devices.empty());
    }
  }
}

}  // namespace
}  // namespace kartograf
