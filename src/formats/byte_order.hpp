#pragma once
// Binary numbers in a file's byte order whatever the host's: PCD and PLY data are little-endian
// (PLY may also be big-endian), and a reader or writer must not depend on the machine it runs on.
#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <cstring>
#include <vector>

namespace kartograf::io::detail {

// The T stored at bytes (no alignment needed) in the given byte order.
template <class T>
T load(const std::uint8_t* bytes, std::endian order = std::endian::little) {
  std::array<std::uint8_t, sizeof(T)> raw;
  std::memcpy(raw.data(), bytes, sizeof(T));
  if (order != std::endian::native) std::reverse(raw.begin(), raw.end());
  return std::bit_cast<T>(raw);
}

// Appends value's bytes to out, least significant first.
template <class T>
void append_little_endian(std::vector<std::uint8_t>& out, T value) {
  const auto raw = std::bit_cast<std::array<std::uint8_t, sizeof(T)>>(value);
  if constexpr (std::endian::native == std::endian::little) {
    out.insert(out.end(), raw.begin(), raw.end());
  } else {
    out.insert(out.end(), raw.rbegin(), raw.rend());
  }
}

}  // namespace kartograf::io::detail
