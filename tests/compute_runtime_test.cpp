// The compute runtime itself: contexts, buffers, kernel builds, backend selection and errors.
#include <cstdlib>
#include <filesystem>
#include <fstream>
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

TEST_P(ComputeRuntimeTest, HostViewReadsTheValuesWithoutCopyingHostMemory) {
  const std::vector<float> values = {1.5f, -2.0f, 3.25f, 7.0f};
  const auto buffer = compute::Buffer<float>::from_host(context(), values);
  const compute::HostView<float> view = compute::read_on_host(buffer);
  EXPECT_EQ(std::vector<float>(view.begin(), view.end()), values);
  ASSERT_EQ(view.size(), values.size());
  EXPECT_EQ(view[2], 3.25f);
  // Free where the buffer is host memory: the view is the storage itself.
  if (buffer.raw().on_host()) {
    EXPECT_EQ(view.data(), buffer.host_span().data());
  }
  EXPECT_TRUE(compute::read_on_host(compute::Buffer<float>{}).empty());
}

TEST_P(ComputeRuntimeTest, HostWriteViewUploadsOnCommitAndDestruction) {
  auto buffer =
      compute::Buffer<std::uint32_t>::from_host(context(), std::vector<std::uint32_t>{1, 2, 3});
  {
    compute::HostWriteView<std::uint32_t> view = compute::write_on_host(buffer);
    EXPECT_EQ(view[1], 2u);  // starts from the current values
    view[1] = 20;
  }
  EXPECT_EQ(buffer.to_vector(), (std::vector<std::uint32_t>{1, 20, 3}));
  {
    auto view = compute::write_on_host(buffer, compute::HostWriteStart::overwrite_all);
    for (std::size_t i = 0; i < view.size(); ++i) view[i] = static_cast<std::uint32_t>(10 * i);
    view.commit();
    EXPECT_EQ(buffer.to_vector(), (std::vector<std::uint32_t>{0, 10, 20}));
  }
  EXPECT_EQ(buffer.to_vector(), (std::vector<std::uint32_t>{0, 10, 20}));
}

TEST_P(ComputeRuntimeTest, HostWriteViewDoesNotUploadWhileAnErrorUnwinds) {
  auto buffer = compute::Buffer<std::uint32_t>::from_host(context(), std::vector<std::uint32_t>{5});
  try {
    auto view = compute::write_on_host(buffer);
    view[0] = 6;
    throw Error("step failed");
  } catch (const Error&) {
  }
  // Host memory is written in place; a device buffer keeps its values.
  EXPECT_EQ(buffer.to_vector()[0], buffer.raw().on_host() ? 6u : 5u);
}

TEST_P(ComputeRuntimeTest, UnknownKernelsAndWrongParameterBlocksAreErrors) {
  // Every backend, the CPU included, dispatches by name: an unknown one is a clear error.
  const std::uint32_t params[1] = {0};
  EXPECT_ERROR_MENTIONS(
      compute::dispatch(context(), compute::KernelSpec{"no_such_kernel", 64}, {}, params, {1, 1}),
      "no_such_kernel");
  if (GetParam() == compute::BackendKind::cpu) {
    // The CPU wrapper checks the block against the rule's struct (5 words for backproject).
    EXPECT_ERROR_MENTIONS(compute::dispatch(context(), compute::KernelSpec{"backproject", 16, 16},
                                            {}, params, {1, 1}),
                          "backproject", "parameter block of 4 bytes");
  }
}

TEST_P(ComputeRuntimeTest, ReferOrUploadHoldsTheValuesAndCopiesNothingOnTheHost) {
  std::vector<std::uint32_t> values = {4, 8, 15, 16, 23};
  compute::Buffer<std::uint32_t> buffer(context(), 2);
  buffer.refer_or_upload(context(), values);
  ASSERT_EQ(buffer.size(), values.size());
  EXPECT_EQ(buffer.to_vector(), values);
  if (GetParam() == compute::BackendKind::cpu) {
    // A view of the caller's memory: later changes show, nothing was copied.
    EXPECT_EQ(buffer.host_span().data(), values.data());
    values[0] = 42;
    EXPECT_EQ(buffer.to_vector()[0], 42u);
  } else {
    EXPECT_FALSE(buffer.raw().on_host());
  }
  // Another call replaces the values (a new view, or an upload at the new size).
  const std::vector<std::uint32_t> again = {1, 2, 3};
  buffer.refer_or_upload(context(), again);
  EXPECT_EQ(buffer.to_vector(), again);
}

TEST_P(ComputeRuntimeTest, OpenclSourceDirReplacesAnEmbeddedKernelFile) {
  if (GetParam() != compute::BackendKind::opencl) GTEST_SKIP() << "an OpenCL build option";
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "kartograf-cl-variant";
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "reduce_rows.cl") << "this is not OpenCL C\n";
  compute::ContextParams params;
  params.backend = compute::BackendChoice::opencl;
  setenv("KARTOGRAF_OPENCL_SOURCE_DIR", dir.c_str(), 1);
  EXPECT_ERROR_MENTIONS(compute::Context(params).build_all_kernels(), "OpenCL", "failed");
  unsetenv("KARTOGRAF_OPENCL_SOURCE_DIR");
  std::filesystem::remove_all(dir);
  EXPECT_NO_THROW(compute::Context(params).build_all_kernels());
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
  EXPECT_THROW(compute::ContextParams::from_environment(), Error);
  unsetenv("KARTOGRAF_DEVICE");
}

TEST(BackendSelection, AutomaticTakesAGpuOrTheCpu) {
  // CPU-hosted drivers (lavapipe, PoCL) are never chosen automatically.
  const compute::Context context{compute::ContextParams{}};
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
