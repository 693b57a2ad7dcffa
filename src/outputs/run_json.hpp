#pragma once
// JSON pieces the documents of sequence runs share (odometry_stats.cpp, slam_stats.cpp,
// plane_run.cpp, map_run_info.cpp).
#include <vector>

#include <nlohmann/json.hpp>

#include "kartograf/formats/sequence_detect.hpp"
#include "kartograf/registration/odometry.hpp"

namespace kartograf::io::detail {

using RunJson = nlohmann::ordered_json;

RunJson input_json(const OpenedSequence& opened);
RunJson registration_report_json(const registration::RegistrationReport& report);
// The frame counts (count_odometry_frames) and every frame's reports.
RunJson frame_counts_json(const std::vector<registration::OdometryFrame>& frames);
RunJson per_frame_json(const std::vector<registration::OdometryFrame>& frames);

}  // namespace kartograf::io::detail
