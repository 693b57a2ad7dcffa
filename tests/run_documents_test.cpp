// The documents the CLI writes, built by the outputs layer: odometry's stats.json
// (outputs/odometry_stats.hpp), the frame counts line, slam's loop closure counts
// (outputs/slam_stats.hpp), planes' run record (outputs/plane_run.hpp) and an eval report
// (outputs/eval_report.hpp).
#include <gtest/gtest.h>

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "kartograf/outputs/eval_report.hpp"
#include "kartograf/outputs/odometry_stats.hpp"
#include "kartograf/outputs/plane_run.hpp"
#include "kartograf/outputs/slam_stats.hpp"

namespace kartograf {
namespace {

// A sequence that only knows its camera and depth scale: the documents read nothing else.
class CameraOnlySequence : public io::Sequence {
 public:
  std::size_t size() const override { return 2; }
  io::RgbdFrame frame(std::size_t) const override { return {}; }
  PinholeIntrinsics intrinsics() const override { return {640, 480, 525, 525, 319.5, 239.5}; }
  double depth_units_per_metre() const override { return 5000; }
};

io::OpenedSequence two_frame_sequence() {
  io::OpenedSequence opened;
  opened.detected = {io::SequenceLayout::tum, true};
  opened.sequence = std::make_unique<CameraOnlySequence>();
  opened.camera = {opened.sequence->intrinsics(), "default", "TUM default"};
  opened.depth_scale_source = "TUM default";
  opened.skipped.push_back({7, "depth unreadable"});
  return opened;
}

// Frame 0 (no registration) and frame 1: a keyframe whose registration was rejected (fallback).
mapping::OdometryRun two_frame_run() {
  mapping::OdometryRun run;
  run.poses.resize(2, Eigen::Isometry3d::Identity());
  run.timestamps = {0.0, 0.5};
  run.frames.resize(2);
  run.frames[0].keyframe = true;
  run.frames[1].index = 1;
  run.frames[1].fallback = true;
  run.frames[1].previous = registration::RegistrationReport{};
  run.frames[1].previous->fitness = 0.25;
  run.timing.wall_seconds = 0.5;
  run.compute_seconds = 0.25;
  return run;
}

TEST(RunDocuments, OdometryStatsOfATwoFrameRun) {
  const io::OpenedSequence opened = two_frame_sequence();
  const mapping::OdometryRun run = two_frame_run();
  registration::OdometryParams params;
  params.reestimate_interval = 3;
  eval::AteResult ate;
  ate.translation_m.rmse = 0.125;
  const std::string text =
      io::odometry_stats_json({"seq", "p2plane", "cpu", "host"}, opened, params, run, ate);
  ASSERT_FALSE(text.empty());
  EXPECT_EQ(text.back(), '\n');
  const nlohmann::ordered_json json = nlohmann::ordered_json::parse(text);
  std::vector<std::string> keys;
  for (const auto& item : json.items()) keys.push_back(item.key());
  EXPECT_EQ(keys, (std::vector<std::string>{"sequence", "layout", "input", "method", "backend",
                                            "device", "reestimate_interval", "frames_per_s_with_io",
                                            "frames_per_s_without_io", "wall_seconds",
                                            "load_seconds", "ate_rmse_m", "summary", "per_frame"}));
  EXPECT_EQ(json["sequence"], "seq");
  EXPECT_EQ(json["layout"], "tum");
  EXPECT_EQ(json["method"], "p2plane");
  EXPECT_EQ(json["reestimate_interval"], 3);
  EXPECT_DOUBLE_EQ(json["frames_per_s_with_io"].get<double>(), 4.0);
  EXPECT_DOUBLE_EQ(json["frames_per_s_without_io"].get<double>(), 8.0);
  EXPECT_DOUBLE_EQ(json["ate_rmse_m"].get<double>(), 0.125);
  EXPECT_EQ(json["input"]["camera"]["fx"], 525.0);
  EXPECT_EQ(json["input"]["depth_units_per_metre"], 5000.0);
  EXPECT_EQ(json["input"]["frames_skipped"], 1);
  EXPECT_EQ(json["input"]["skipped_frames"][0]["frame"], 7);
  EXPECT_EQ(json["summary"]["frames"], 2);
  EXPECT_EQ(json["summary"]["keyframes"], 1);
  EXPECT_EQ(json["summary"]["fallbacks"], 1);
  ASSERT_EQ(json["per_frame"].size(), 2u);
  EXPECT_TRUE(json["per_frame"][0]["previous"].is_null());
  EXPECT_EQ(json["per_frame"][1]["frame"], 1);
  EXPECT_DOUBLE_EQ(json["per_frame"][1]["previous"]["fitness"].get<double>(), 0.25);

  const std::string without_ate =
      io::odometry_stats_json({"seq", "p2plane", "cpu", "host"}, opened, params, run, {});
  EXPECT_TRUE(nlohmann::json::parse(without_ate)["ate_rmse_m"].is_null());
}

TEST(RunDocuments, FrameCountsLine) {
  const io::OdometryFrameCounts counts = io::count_odometry_frames(two_frame_run().frames);
  EXPECT_EQ(counts.frames, 2u);
  EXPECT_EQ(io::frame_counts_line(counts),
            "keyframes 1, fallbacks 1, re-estimates 0 (rejected 0), degenerate frames 0 (0 "
            "measured by image intensity, 0 held to the heading)");
}

TEST(RunDocuments, FrameCountsSayWhetherTheColourIsRegistered) {
  mapping::OdometryRun run = two_frame_run();
  for (registration::OdometryFrame& frame : run.frames) {
    frame.colour_registration = registration::ColourRegistration::registered;
    frame.colour_edge_contrast = 1.836;
  }
  run.frames[1].deep_photometric = true;
  const io::OdometryFrameCounts counts = io::count_odometry_frames(run.frames);
  EXPECT_EQ(counts.deep_photometric_frames, 1u);
  const std::string line = io::frame_counts_line(counts);
  EXPECT_NE(line.find("held to the heading); colour registered to depth (edge contrast 1.84), deep "
                      "views measured with the images 1"),
            std::string::npos)
      << line;
  const nlohmann::json json = nlohmann::json::parse(io::odometry_stats_json(
      {"seq", "p2plane", "cpu", "host"}, two_frame_sequence(), {}, run, {}));
  EXPECT_EQ(json["summary"]["colour_registration"], "registered");
  EXPECT_DOUBLE_EQ(json["summary"]["colour_edge_contrast"].get<double>(), 1.836);
  EXPECT_EQ(json["summary"]["deep_photometric_frames"], 1);
  EXPECT_TRUE(json["per_frame"][1]["deep_photometric"].get<bool>());
  EXPECT_FALSE(json["per_frame"][0]["deep_photometric"].get<bool>());
}

TEST(RunDocuments, LoopClosureCounts) {
  mapping::SlamResult result;
  result.loop_closures.resize(3);
  result.loop_closures[0].closure.report.verdict = registration::RegistrationVerdict::accepted;
  result.loop_closures[0].pruned = true;
  result.loop_closures[1].closure.report.verdict = registration::RegistrationVerdict::accepted;
  result.loop_closures[2].closure.report.verdict = registration::RegistrationVerdict::low_fitness;
  const io::LoopClosureCounts counts = io::count_loop_closures(result);
  EXPECT_EQ(counts.accepted, 2u);
  EXPECT_EQ(counts.pruned, 1u);
}

TEST(RunDocuments, PlaneRunIsOneLine) {
  const std::string text =
      io::plane_run_json({"cells", 15, 30, 300, "pixel", "tls", "cpu", "host"});
  EXPECT_EQ(text, R"({"mode":"cells","lab_threshold":15.0,"normal_angle_deg":30.0,)"
                  R"("min_plane_pixels":300,"neighbours":"pixel","fit":"tls","backend":"cpu",)"
                  R"("device":"host"})");
}

TEST(RunDocuments, EvalReportAsTableAndJson) {
  eval::SegCompResult result;
  result.ground_truth_regions = 2;
  result.correct = 2;
  const io::MetricReport report = io::plane_report(result, "gt.png", "p.png", 0.8);
  const std::string table = report.table();
  EXPECT_NE(table.find("overlap threshold 0.8\n  ground truth gt.png, prediction p.png\n"),
            std::string::npos);
  EXPECT_NE(table.find("correct                           2   correct detections\n"),
            std::string::npos);
  const nlohmann::ordered_json json = nlohmann::ordered_json::parse(report.json());
  EXPECT_EQ(json["correct"], 2);
  EXPECT_EQ(json["threshold"], 0.8);
  EXPECT_EQ(json.begin().key(), "ground_truth_regions");
}

}  // namespace
}  // namespace kartograf
