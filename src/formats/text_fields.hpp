#pragma once
// Lines and fields of text formats (PCD and PLY headers and ascii data, TUM lists): the next line
// of a file held in memory, its fields, and numbers read exactly, so that the parsers agree on
// what a line, a field and a number are.
#include <charconv>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

namespace kartograf::io::detail {

// The line that starts at `position` in bytes, without its '\n' (a '\r' before it is kept), or
// nothing at the end of the bytes. Moves position past the line and its '\n' and adds 1 to
// line_number.
std::optional<std::string_view> next_line(std::span<const std::uint8_t> bytes,
                                          std::size_t& position, std::size_t& line_number);

// The non-empty runs of line between the characters in `separators` (each format has its own).
std::vector<std::string_view> split_fields(std::string_view line, std::string_view separators);

// text for an error message: bytes outside printable ASCII as \xNN (a binary file's header must
// not reach a terminal raw), cut after max_chars characters with "..." so that a megabyte-long
// field stays one readable line.
std::string printable(std::string_view text, std::size_t max_chars = 40);

// token as a Number, all of it, the way std::from_chars reads it (no leading '+' or blanks; for
// floating point also "nan", "inf" and exponents); nothing when any character is not part of the
// number or the value is out of Number's range.
template <class Number>
std::optional<Number> parse_number(std::string_view token) {
  Number value{};
  const char* end = token.data() + token.size();
  const auto result = std::from_chars(token.data(), end, value);
  if (result.ec != std::errc() || result.ptr != end) return std::nullopt;
  return value;
}

}  // namespace kartograf::io::detail
