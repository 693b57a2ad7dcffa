#include "kartograf/formats/tum.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "formats/atomic_file.hpp"
#include "formats/input_file.hpp"
#include "formats/text_fields.hpp"
#include "kartograf/core/error.hpp"

namespace kartograf::io {

namespace {

using detail::quoted;

// A finite number, all of token.
std::optional<double> finite_number(std::string_view token) {
  const auto value = detail::parse_number<double>(token);
  return value && std::isfinite(*value) ? value : std::nullopt;
}

// Calls on_line(fields, line_number) for every data line; skips comments as documented. Fields
// are separated by any white space (as the TUM tools' split() does).
template <class OnLine>
void for_each_data_line(const std::filesystem::path& path, OnLine&& on_line) {
  std::ifstream in = detail::open_text_file(path);
  std::string line;
  std::size_t line_number = 0;
  bool seen_data = false;
  while (std::getline(in, line)) {
    ++line_number;
    const std::vector<std::string_view> fields = detail::split_fields(line, " \t\v\f\r");
    if (fields.empty() || fields[0][0] == '#') continue;
    if (!seen_data && !finite_number(fields[0])) continue;  // a header line without '#'
    seen_data = true;
    on_line(fields, line_number);
  }
  require(!in.bad(), quoted(path) + ": read error");
}

std::string where(const std::filesystem::path& path, std::size_t line) {
  return quoted(path) + " line " + std::to_string(line) + ": ";
}

}  // namespace

Trajectory read_tum_trajectory(const std::filesystem::path& path) {
  Trajectory trajectory;
  for_each_data_line(path, [&](const std::vector<std::string_view>& fields, std::size_t line) {
    require(fields.size() == 8, where(path, line) +
                                    "expected 8 numbers (timestamp tx ty tz qx qy qz qw), got " +
                                    std::to_string(fields.size()) + " fields");
    double v[8];
    for (int i = 0; i < 8; ++i) {
      const auto value = finite_number(fields[i]);
      require(value.has_value(),
              where(path, line) + "'" + std::string(fields[i]) + "' is not a finite number");
      v[i] = *value;
    }
    Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);
    require(std::fabs(q.norm() - 1.0) <= 0.01,
            where(path, line) + "quaternion norm " + std::to_string(q.norm()) + " is not 1");
    q.normalize();
    StampedPose pose;
    pose.timestamp = v[0];
    pose.pose = Eigen::Translation3d(v[1], v[2], v[3]) * q;
    trajectory.push_back(pose);
  });
  return trajectory;
}

void write_tum_trajectory(const std::filesystem::path& path, const Trajectory& trajectory) {
  std::string text = "# timestamp tx ty tz qx qy qz qw\n";
  char line[256];
  for (const StampedPose& stamped : trajectory) {
    const Eigen::Vector3d t = stamped.pose.translation();
    const Eigen::Quaterniond q(stamped.pose.rotation());
    require(std::isfinite(stamped.timestamp) && t.allFinite() && q.coeffs().allFinite(),
            quoted(path) +
                ": trajectory has a non-finite pose at t = " + std::to_string(stamped.timestamp));
    std::snprintf(line, sizeof(line), "%.6f %.9g %.9g %.9g %.9g %.9g %.9g %.9g\n",
                  stamped.timestamp, t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w());
    text += line;
  }
  detail::write_file_atomically(path, text.data(), text.size());
}

std::vector<TimestampedFile> read_tum_file_list(const std::filesystem::path& path) {
  std::vector<TimestampedFile> files;
  for_each_data_line(path, [&](const std::vector<std::string_view>& fields, std::size_t line) {
    require(fields.size() == 2, where(path, line) + "expected 'timestamp filename', got " +
                                    std::to_string(fields.size()) + " fields");
    const auto timestamp = finite_number(fields[0]);
    require(timestamp.has_value(),
            where(path, line) + "'" + std::string(fields[0]) + "' is not a finite timestamp");
    TimestampedFile file;
    file.timestamp = *timestamp;
    file.file = fields[1];
    files.push_back(std::move(file));
  });
  return files;
}

std::vector<std::pair<std::size_t, std::size_t>> associate_timestamps(const std::vector<double>& a,
                                                                      const std::vector<double>& b,
                                                                      double max_difference) {
  require(max_difference >= 0, "associate_timestamps: max_difference must be >= 0");
  // Every candidate pair within the window, found through b sorted by time.
  std::vector<std::size_t> b_order(b.size());
  for (std::size_t j = 0; j < b.size(); ++j) b_order[j] = j;
  std::sort(b_order.begin(), b_order.end(),
            [&](std::size_t x, std::size_t y) { return b[x] < b[y]; });
  struct Candidate {
    double difference;
    std::size_t i, j;
  };
  std::vector<Candidate> candidates;
  for (std::size_t i = 0; i < a.size(); ++i) {
    auto first = std::lower_bound(b_order.begin(), b_order.end(), a[i] - max_difference,
                                  [&](std::size_t j, double t) { return b[j] < t; });
    for (auto it = first; it != b_order.end() && b[*it] <= a[i] + max_difference; ++it) {
      candidates.push_back({std::fabs(a[i] - b[*it]), i, *it});
    }
  }
  std::stable_sort(
      candidates.begin(), candidates.end(),
      [](const Candidate& x, const Candidate& y) { return x.difference < y.difference; });
  std::vector<bool> a_used(a.size()), b_used(b.size());
  std::vector<std::pair<std::size_t, std::size_t>> pairs;
  for (const Candidate& c : candidates) {
    if (a_used[c.i] || b_used[c.j]) continue;
    a_used[c.i] = b_used[c.j] = true;
    pairs.emplace_back(c.i, c.j);
  }
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

}  // namespace kartograf::io
