#include "test_support.hpp"

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <sstream>

#include <unistd.h>

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

std::filesystem::path data_dir() {
  const char* configured = std::getenv("KARTOGRAF_DATA_DIR");
  const std::filesystem::path dir = configured ? configured : KARTOGRAF_DEFAULT_DATA_DIR;
  if (!std::filesystem::is_directory(dir)) {
    ADD_FAILURE() << "test data directory " << dir << " is missing (set KARTOGRAF_DATA_DIR)";
  }
  return dir;
}

std::string scientific(double value) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.3e", value);
  return text;
}

std::string backend_test_name(const ::testing::TestParamInfo<compute::BackendKind>& info) {
  return std::string(compute::to_string(info.param));
}

std::vector<std::uint8_t> read_bytes(const std::filesystem::path& path) {
  std::ifstream stream(path, std::ios::binary);
  EXPECT_TRUE(stream) << "cannot open " << path;
  return std::vector<std::uint8_t>((std::istreambuf_iterator<char>(stream)),
                                   std::istreambuf_iterator<char>());
}

std::string read_text(const std::filesystem::path& path) {
  const std::vector<std::uint8_t> bytes = read_bytes(path);
  return std::string(bytes.begin(), bytes.end());
}

void write_file(const std::filesystem::path& path, std::string_view contents) {
  std::ofstream stream(path, std::ios::binary | std::ios::trunc);
  stream.write(contents.data(), static_cast<std::streamsize>(contents.size()));
  EXPECT_TRUE(stream) << "cannot write " << path;
}

void write_file(const std::filesystem::path& path, const std::vector<std::uint8_t>& contents) {
  write_file(path,
             std::string_view(reinterpret_cast<const char*>(contents.data()), contents.size()));
}

std::string error_message(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& error) {
    return error.what();
  }
  ADD_FAILURE() << "expected a kartograf::Error, but nothing was thrown";
  return "";
}

void expect_mentions(const std::string& message, std::initializer_list<std::string_view> parts) {
  for (std::string_view part : parts) {
    EXPECT_NE(message.find(part), std::string::npos)
        << "the message does not mention \"" << part << "\":\n  " << message;
  }
}

void TempDirTest::SetUp() {
  const auto* test = ::testing::UnitTest::GetInstance()->current_test_info();
  dir_ =
      std::filesystem::temp_directory_path() / ("kartograf-test-" + std::to_string(::getpid()) +
                                                "-" + test->test_suite_name() + "-" + test->name());
  std::filesystem::create_directories(dir_);
}

void TempDirTest::TearDown() {
  std::filesystem::remove_all(dir_);
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
