#pragma once
// TUM RGB-D text formats: trajectories ("timestamp tx ty tz qx qy qz qw", what evo and TUM's tools
// read), frame lists ("timestamp filename") and the association of two lists by nearest timestamp.
// Lines starting with '#' are comments anywhere; non-numeric header lines before the first data
// line are comments too (some copies of TUM's files lost the '#' of their third line). Any other
// malformed line is an Error naming the file, the line number and the problem.
#include <cstddef>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "kartograf/core/trajectory.hpp"

namespace kartograf::io {

// Quaternions are normalised; one whose norm is not within 1% of 1 is an error.
Trajectory read_tum_trajectory(const std::filesystem::path& path);
// Atomic; timestamps with microseconds, translations and quaternions with 9 significant digits.
void write_tum_trajectory(const std::filesystem::path& path, const Trajectory& trajectory);

struct TimestampedFile {
  double timestamp = 0;
  std::string file;  // as written in the list, relative to the list's folder
};
std::vector<TimestampedFile> read_tum_file_list(const std::filesystem::path& path);

// Pairs (i, j) of a[i] and b[j] whose timestamps differ by at most max_difference seconds; each
// index is used at most once, closest pairs first (as TUM's associate.py), sorted by i.
std::vector<std::pair<std::size_t, std::size_t>> associate_timestamps(const std::vector<double>& a,
                                                                      const std::vector<double>& b,
                                                                      double max_difference);

}  // namespace kartograf::io
