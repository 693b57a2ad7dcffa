#include "formats/text_fields.hpp"

#include <algorithm>
#include <cstring>

namespace kartograf::io::detail {

std::optional<std::string_view> next_line(std::span<const std::uint8_t> bytes,
                                          std::size_t& position, std::size_t& line_number) {
  if (position >= bytes.size()) return std::nullopt;
  const char* begin = reinterpret_cast<const char*>(bytes.data()) + position;
  const std::size_t remaining = bytes.size() - position;
  const void* newline = std::memchr(begin, '\n', remaining);
  const std::size_t length =
      newline ? static_cast<std::size_t>(static_cast<const char*>(newline) - begin) : remaining;
  position += newline ? length + 1 : length;
  ++line_number;
  return std::string_view(begin, length);
}

std::vector<std::string_view> split_fields(std::string_view line, std::string_view separators) {
  std::vector<std::string_view> fields;
  std::size_t end = 0;
  while (true) {
    const std::size_t start = line.find_first_not_of(separators, end);
    if (start == std::string_view::npos) return fields;
    end = std::min(line.find_first_of(separators, start), line.size());
    fields.push_back(line.substr(start, end - start));
  }
}

std::string printable(std::string_view text, std::size_t max_chars) {
  static constexpr char kHex[] = "0123456789abcdef";
  std::string shown;
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (i == max_chars) return shown + "...";
    const auto byte = static_cast<unsigned char>(text[i]);
    if (byte >= 0x20 && byte < 0x7f && byte != '\\') {
      shown += static_cast<char>(byte);
    } else {
      shown += {'\\', 'x', kHex[byte >> 4], kHex[byte & 0xf]};
    }
  }
  return shown;
}

}  // namespace kartograf::io::detail
