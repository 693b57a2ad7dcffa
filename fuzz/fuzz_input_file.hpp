#pragma once
// libFuzzer harness support: the readers under test take paths (that is how users call them), so
// each input is written to a file in a per-process scratch folder (on /dev/shm when it exists)
// and the reader opens it like any other file. kartograf::Error is the expected reaction to bad
// bytes; any other exception escapes and libFuzzer reports it as a crash.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

#include "kartograf/core/error.hpp"

namespace kartograf::fuzz {

inline std::filesystem::path scratch_dir() {
  static const std::filesystem::path dir = [] {
    const std::filesystem::path base =
        std::filesystem::exists("/dev/shm") ? "/dev/shm" : std::filesystem::temp_directory_path();
    auto d = base / ("kartograf-fuzz-" + std::to_string(::getpid()));
    std::filesystem::create_directories(d);
    return d;
  }();
  return dir;
}

inline std::filesystem::path write_input(const std::string& name, const std::uint8_t* data,
                                         std::size_t size) {
  const auto path = scratch_dir() / name;
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  return path;
}

// Runs read(path) on the input stored as `name`; swallows only kartograf::Error.
template <class Reader>
void read_as_file(const std::string& name, const std::uint8_t* data, std::size_t size,
                  Reader&& read) {
  const auto path = write_input(name, data, size);
  try {
    read(path);
  } catch (const kartograf::Error&) {
  }
}

}  // namespace kartograf::fuzz
