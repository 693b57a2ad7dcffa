#pragma once
// An unnamed temporary file that records are appended to and read back from, for what a long run
// keeps but rarely reads (frames for a later pass, old keyframes): memory stays bounded while the
// disk takes the growth. The file disappears when the object does. Reads and appends may come from
// several threads.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <mutex>
#include <span>
#include <string>

namespace kartograf::mapping {

// The bytes of `count` contiguous values, as append() and read() take them.
template <typename T>
std::span<const std::uint8_t> bytes_of(const T* values, std::size_t count) {
  return {reinterpret_cast<const std::uint8_t*>(values), count * sizeof(T)};
}
template <typename T>
std::span<std::uint8_t> bytes_of(T* values, std::size_t count) {
  return {reinterpret_cast<std::uint8_t*>(values), count * sizeof(T)};
}

class SpillFile {
 public:
  // what: names the owner in errors ("frame store").
  explicit SpillFile(std::string what);

  // Appends the bytes; returns their offset. Error naming the owner when the file cannot be made
  // or written (disk full).
  std::size_t append(std::span<const std::uint8_t> bytes);
  // Appends several pieces as one record; returns its offset.
  std::size_t append(std::span<const std::span<const std::uint8_t>> pieces);
  // Fills `out` from `offset`; Error on a short read.
  void read(std::size_t offset, std::span<std::uint8_t> out) const;
  std::size_t size() const { return end_; }

 private:
  std::string what_;
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> file_{nullptr, &std::fclose};
  std::size_t end_ = 0;
  mutable std::mutex mutex_;
};

}  // namespace kartograf::mapping
