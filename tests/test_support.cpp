#include "test_support.hpp"

#include <cstdlib>
#include <sstream>

#include "kartograf/core/error.hpp"

namespace kartograf::testing {

std::vector<compute::BackendKind> backends_under_test() {
  const char* listed = std::getenv("KARTOGRAF_TEST_BACKENDS");
  if (!listed || !*listed) {
    return {compute::BackendKind::cpu, compute::BackendKind::vulkan, compute::BackendKind::opencl};
  }
  std::vector<compute::BackendKind> kinds;
  std::stringstream stream(listed);
  std::string name;
  while (std::getline(stream, name, ',')) {
    const auto choice = compute::parse_backend_choice(name, "KARTOGRAF_TEST_BACKENDS");
    if (choice == compute::BackendChoice::cpu) kinds.push_back(compute::BackendKind::cpu);
    if (choice == compute::BackendChoice::vulkan) kinds.push_back(compute::BackendKind::vulkan);
    if (choice == compute::BackendChoice::opencl) kinds.push_back(compute::BackendKind::opencl);
  }
  return kinds;
}

compute::Context make_context(compute::BackendKind kind) {
  compute::ContextParams options;
  options.backend = compute::choice_of(kind);
  options.vulkan_validation = true;
  return compute::Context(options);
}

std::string backend_test_name(const ::testing::TestParamInfo<compute::BackendKind>& info) {
  return std::string(compute::to_string(info.param));
}

void BackendTest::SetUp() {
  try {
    context_ = std::make_unique<compute::Context>(make_context(GetParam()));
  } catch (const Error& error) {
    FAIL() << "backend " << compute::to_string(GetParam()) << " is unavailable: " << error.what();
  }
  if (GetParam() == compute::BackendKind::vulkan && !context_->validation_active()) {
    // Optional on a developer's machine, required in CI (scripts/install-deps.sh installs it).
    const char* ci = std::getenv("CI");
    if (ci && *ci) FAIL() << "CI runs Vulkan under VK_LAYER_KHRONOS_validation, which is missing";
    std::cerr << "note: VK_LAYER_KHRONOS_validation is not installed; Vulkan runs unvalidated\n";
  }
}

void BackendTest::TearDown() {
  if (!context_) return;
  context_->finish();
  EXPECT_EQ(context_->validation_errors(), 0u) << "the Vulkan validation layer reported errors";
}

ScopedCpuThreads::ScopedCpuThreads(const char* value) {
  if (const char* old = std::getenv("KARTOGRAF_CPU_THREADS")) old_ = old;
  setenv("KARTOGRAF_CPU_THREADS", value, 1);
}

ScopedCpuThreads::~ScopedCpuThreads() {
  if (old_) {
    setenv("KARTOGRAF_CPU_THREADS", old_->c_str(), 1);
  } else {
    unsetenv("KARTOGRAF_CPU_THREADS");
  }
}

}  // namespace kartograf::testing
