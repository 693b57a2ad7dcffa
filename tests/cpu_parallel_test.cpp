// The CPU backend's chunks (src/compute/cpu_parallel.hpp): every chunk once, on helper threads
// kept between calls, with nested and concurrent calls and forked children served too.
#include "compute/cpu_parallel.hpp"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <chrono>
#include <cstdlib>
#include <stdexcept>
#include <thread>
#include <vector>

#include "test_support.hpp"

namespace kartograf {
namespace {

using compute::detail::for_each_chunk;
using compute::detail::kCpuChunks;

constexpr std::size_t kWork = 1 << 20;  // enough to be worth the helpers

// How often each index of [0, count) was visited, over one call.
std::vector<int> visits(std::size_t count) {
  std::vector<std::atomic<int>> seen(count);
  for_each_chunk(count, kWork, [&](std::size_t begin, std::size_t end, std::size_t) {
    for (std::size_t i = begin; i < end; ++i) ++seen[i];
  });
  return std::vector<int>(seen.begin(), seen.end());
}

TEST(CpuChunks, EveryIndexOnceOnAnyThreadCount) {
  for (const char* threads : {"1", "2", "3", "8", "64"}) {
    const testing::ScopedCpuThreads scoped(threads);
    for (const std::size_t count : {0, 1, 7, 8, 1000}) {
      for (int repeat = 0; repeat < 20; ++repeat)
        EXPECT_EQ(visits(count), std::vector<int>(count, 1)) << threads << " threads, " << count;
    }
  }
}

// With two threads a helper takes chunks: chunk 0 waits (up to 10 s) until another thread has
// run one.
TEST(CpuChunks, HelpersTakeChunks) {
  const testing::ScopedCpuThreads scoped("2");
  for (int repeat = 0; repeat < 5; ++repeat) {
    const std::thread::id caller = std::this_thread::get_id();
    std::atomic<bool> elsewhere{false};
    for_each_chunk(kCpuChunks, kWork, [&](std::size_t, std::size_t, std::size_t chunk) {
      if (std::this_thread::get_id() != caller) elsewhere = true;
      if (chunk != 0) return;
      const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
      while (!elsewhere && std::chrono::steady_clock::now() < deadline) std::this_thread::yield();
    });
    EXPECT_TRUE(elsewhere);
  }
}

TEST(CpuChunks, NestedAndConcurrentCallsComplete) {
  const testing::ScopedCpuThreads scoped("4");
  std::atomic<int> inner{0};
  for_each_chunk(kCpuChunks, kWork, [&](std::size_t, std::size_t, std::size_t) {
    for_each_chunk(kCpuChunks, kWork, [&](std::size_t, std::size_t, std::size_t) { ++inner; });
  });
  EXPECT_EQ(inner, static_cast<int>(kCpuChunks * kCpuChunks));
  std::array<std::vector<int>, 4> results;
  std::vector<std::thread> callers;
  for (std::size_t t = 0; t < results.size(); ++t) {
    callers.emplace_back([&results, t] {
      for (int repeat = 0; repeat < 50; ++repeat) results[t] = visits(500 + t);
    });
  }
  for (std::thread& caller : callers) caller.join();
  for (std::size_t t = 0; t < results.size(); ++t)
    EXPECT_EQ(results[t], std::vector<int>(500 + t, 1));
}

TEST(CpuChunks, AnExceptionOnTheCallersThreadReachesTheCaller) {
  const testing::ScopedCpuThreads scoped("2");
  const std::thread::id caller = std::this_thread::get_id();
  bool thrown = false;
  try {
    // Chunks on helpers wait until the caller has thrown, so that the caller runs one.
    std::atomic<bool> threw{false};
    for_each_chunk(kCpuChunks, kWork, [&](std::size_t, std::size_t, std::size_t) {
      if (std::this_thread::get_id() == caller) {
        threw = true;
        throw std::runtime_error("chunk failed");
      }
      while (!threw) std::this_thread::yield();
    });
  } catch (const std::runtime_error&) {
    thrown = true;
  }
  EXPECT_TRUE(thrown);
  EXPECT_EQ(visits(100), std::vector<int>(100, 1));  // the helpers still serve
}

// A child made by fork() has none of its parent's helper threads: it starts its own.
TEST(CpuChunks, AForkedChildGetsHelpersOfItsOwn) {
  const testing::ScopedCpuThreads scoped("2");
  ASSERT_EQ(visits(100), std::vector<int>(100, 1));  // the parent's helpers exist
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    alarm(20);  // a child waiting on helpers it does not have dies of the alarm
    _exit(visits(100) == std::vector<int>(100, 1) ? 0 : 1);
  }
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "child status " << status;
}

}  // namespace
}  // namespace kartograf
