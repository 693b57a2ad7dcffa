#pragma once
// Text for HTML pages (the map report): escaping, numbers, base64, inline scripts.
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

namespace kartograf::io::detail {

// & < > " escaped: safe in element text and in double-quoted attributes.
std::string html_escape(std::string_view text);

// printf-style formatting of one number, e.g. format_number(0.5, "%.2f") = "0.50".
std::string format_number(double value, const char* format = "%.3f");

// A length for people: mm below 1 cm, cm below 1 m, else m ("4.2 mm", "2.36 cm", "12.4 m").
std::string format_length(double metres);

// RFC 4648 base64 with padding.
std::string base64(std::span<const std::uint8_t> bytes);

// A script's text that cannot end its <script> element early: "</script" (any case) becomes
// "<\/script" (the same string to JavaScript).
std::string inline_script(std::string_view script);

}  // namespace kartograf::io::detail
