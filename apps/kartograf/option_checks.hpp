#pragma once
// Checks of numeric options. CLI11's Range and PositiveNumber let "nan" through (every comparison
// with NaN is false) and accept "inf": a value given on the command line must be a finite number
// in its range, or the command stops with an error naming the option and the value. Options whose
// defaults mean "not given" (e.g. 0 or -1) are checked only when given, so no default is ever
// mistaken for a value, and no bad value for a default.
#include <charconv>
#include <cmath>
#include <cstdint>
#include <optional>
#include <sstream>
#include <string>
#include <system_error>

#include <CLI/CLI.hpp>

namespace kartograf::cli {

// The number `input` reads as where it is one and finite.
inline std::optional<double> finite_value(const std::string& input) {
  double value = 0;
  if (!CLI::detail::lexical_cast(input, value) || !std::isfinite(value)) return std::nullopt;
  return value;
}

// min <= value <= max, finite; `description` is what the help shows.
inline CLI::Validator finite_in(double min, double max, std::string description = "") {
  std::ostringstream range;
  range << "[" << min << ", " << max << "]";
  if (description.empty()) description = "NUMBER in " + range.str();
  return CLI::Validator(
      [min, max, range = range.str()](std::string& input) -> std::string {
        const std::optional<double> value = finite_value(input);
        if (!value || *value < min || *value > max) {
          return "'" + input + "' is not a finite number in " + range;
        }
        return {};
      },
      description);
}

// 0 < value, finite.
inline CLI::Validator finite_positive() {
  return CLI::Validator(
      [](std::string& input) -> std::string {
        const std::optional<double> value = finite_value(input);
        if (!value || !(*value > 0)) {
          return "'" + input + "' is not a finite number > 0";
        }
        return {};
      },
      "NUMBER > 0");
}

// Any finite value.
inline CLI::Validator finite_number() {
  return CLI::Validator(
      [](std::string& input) -> std::string {
        if (!finite_value(input)) return "'" + input + "' is not a finite number";
        return {};
      },
      "finite NUMBER");
}

// Any finite value, or the word `word` (e.g. "auto").
inline CLI::Validator finite_number_or(const std::string& word) {
  return CLI::Validator(
      [word](std::string& input) -> std::string {
        if (input == word || finite_value(input)) return {};
        return "'" + input + "' is neither a finite number nor '" + word + "'";
      },
      "finite NUMBER or " + word);
}

// 0 <= value <= max, an integer written with digits only: CLI11 reads "-5" into an unsigned
// option as 2^64 - 5, which no range check on the value can tell from a large number.
inline CLI::Validator whole_number(std::uint64_t max) {
  return CLI::Validator(
      [max](std::string& input) -> std::string {
        std::uint64_t value = 0;
        const char* end = input.data() + input.size();
        const auto [ptr, error] = std::from_chars(input.data(), end, value);
        if (input.empty() || error != std::errc() || ptr != end || value > max) {
          return "'" + input + "' is not a whole number in [0, " + std::to_string(max) + "]";
        }
        return {};
      },
      "INTEGER in [0, " + std::to_string(max) + "]");
}

}  // namespace kartograf::cli
