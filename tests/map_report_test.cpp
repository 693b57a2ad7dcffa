// report.html of a map run (src/io/map_report*.cpp) and what it is built from: the per-frame
// trajectory errors of pipeline::evaluate_map, the true path in the top view, the HTML text
// helpers and the SVG plots. The page in a browser is tested by Cli.report_renders_in_chromium.
#include <algorithm>
#include <cmath>
#include <regex>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "kartograf/formats/top_view.hpp"
#include "kartograf/outputs/map_outputs.hpp"
#include "kartograf/pipeline/map_evaluation.hpp"
#include "outputs/html_text.hpp"
#include "outputs/map_report_html.hpp"
#include "outputs/report_svg.hpp"

namespace kartograf {
namespace {

using io::detail::Json;

std::vector<std::uint8_t> from_base64(const std::string& text) {
  const std::string alphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::vector<std::uint8_t> out;
  std::uint32_t bits = 0;
  int count = 0;
  for (const char c : text) {
    if (c == '=') break;
    bits = (bits << 6) | static_cast<std::uint32_t>(alphabet.find(c));
    if ((count += 6) >= 8) out.push_back(static_cast<std::uint8_t>(bits >> (count -= 8)));
  }
  return out;
}

// A run of n frames along a wavy line, 1.2 m above the floor, with a map of n x 50 points.
pipeline::MapPipelineResult small_run(int n) {
  pipeline::MapPipelineResult result;
  for (int k = 0; k < n; ++k) {
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.linear() << 1, 0, 0, 0, 0, 1, 0, -1, 0;  // looking along +y, camera -y = map +z
    pose.translation() = Eigen::Vector3d(0.1 * k, 0.3 * std::sin(0.5 * k), 1.2);
    result.poses.push_back(pose);
    for (int i = 0; i < 50; ++i) {
      result.map.points.emplace_back(0.1f * k, 1.0f + 0.02f * i, 0.03f * i);
      result.map.colors.push_back({static_cast<std::uint8_t>(5 * i), 100, 200});
    }
  }
  return result;
}

// Ground truth: the run's poses moved by a rigid motion (so the ATE's alignment is not the
// identity), one frame without a pose, one frame's position off by `outlier_m` along x.
pipeline::MapGroundTruth moved_truth(const pipeline::MapPipelineResult& run, std::size_t missing,
                                     std::size_t outlier, double outlier_m) {
  Eigen::Isometry3d motion = Eigen::Isometry3d::Identity();
  motion.linear() = Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  motion.translation() = Eigen::Vector3d(3, -1, 0.2);
  pipeline::MapGroundTruth truth;
  for (std::size_t k = 0; k < run.poses.size(); ++k) {
    Eigen::Isometry3d pose = motion * run.poses[k];
    if (k == outlier) pose.translation().x() += outlier_m;
    truth.poses.push_back(k == missing ? std::nullopt : std::optional(pose));
  }
  return truth;
}

TEST(MapEvaluation, FrameErrorsCarryTheTruePathIntoTheMapFrame) {
  const pipeline::MapPipelineResult run = small_run(20);
  const pipeline::MapEvaluation e = pipeline::evaluate_map(run, moved_truth(run, 3, 99, 0));
  ASSERT_EQ(e.frame_errors.size(), 19u);
  for (const pipeline::FrameTrajectoryError& f : e.frame_errors) {
    EXPECT_NE(f.frame, 3u);  // no ground truth there
    EXPECT_NEAR(f.error_m, 0, 1e-9);
    EXPECT_LT((f.true_position_in_map - run.poses[f.frame].translation()).norm(), 1e-9);
  }
  EXPECT_EQ(e.frame_errors[3].frame, 4u);
}

TEST(MapEvaluation, FrameErrorsAreTheAtesPerFrameErrors) {
  const pipeline::MapPipelineResult run = small_run(20);
  const pipeline::MapEvaluation e = pipeline::evaluate_map(run, moved_truth(run, 99, 7, 0.2));
  ASSERT_EQ(e.frame_errors.size(), 20u);
  const auto worst =
      std::max_element(e.frame_errors.begin(), e.frame_errors.end(),
                       [](const auto& a, const auto& b) { return a.error_m < b.error_m; });
  EXPECT_EQ(worst->frame, 7u);
  EXPECT_DOUBLE_EQ(worst->error_m, e.trajectory->ate.translation_m.max);
  double squares = 0;
  for (const pipeline::FrameTrajectoryError& f : e.frame_errors) squares += f.error_m * f.error_m;
  EXPECT_NEAR(std::sqrt(squares / 20), e.trajectory->ate.translation_m.rmse, 1e-12);
}

TEST(MapEvaluation, ScoresTheOdometryBeforeLoopClosureOnItsOwn) {
  pipeline::MapPipelineResult run = small_run(20);
  const pipeline::MapGroundTruth truth = moved_truth(run, 99, 99, 0);
  EXPECT_FALSE(pipeline::evaluate_map(run, truth).odometry_trajectory);  // no odometry poses
  // The odometry drifted: 1 cm more along x per frame than the (perfect) SLAM poses.
  run.slam.odometry.poses = run.poses;
  for (std::size_t k = 0; k < run.poses.size(); ++k)
    run.slam.odometry.poses[k].translation().x() += 0.01 * static_cast<double>(k);
  const pipeline::MapEvaluation e = pipeline::evaluate_map(run, truth);
  ASSERT_TRUE(e.trajectory && e.odometry_trajectory);
  EXPECT_NEAR(e.trajectory->ate.translation_m.rmse, 0, 1e-9);
  EXPECT_GT(e.odometry_trajectory->ate.translation_m.rmse, 0.001);
  EXPECT_EQ(e.odometry_trajectory->ate.translation_m.count, 20u);
}

TEST(MapEvaluation, ScoresTheMeasuredPosesAloneWhereTheTruthInterpolatesBetweenThem) {
  // A reference that measured every 5th pose of the run's wavy path and went straight between
  // (SUN3D's ground truth): the run follows the waves, so it is off the reference between the
  // measured poses and exact at them.
  const pipeline::MapPipelineResult run = small_run(20);
  pipeline::MapGroundTruth truth;
  for (std::size_t k = 0; k < run.poses.size(); ++k) {
    const std::size_t m = std::min<std::size_t>(5 * (k / 5), 10);  // after 15: the last run on
    const Eigen::Vector3d from = run.poses[m].translation();
    const Eigen::Vector3d step = (run.poses[m + 5].translation() - from) / 5;
    Eigen::Isometry3d pose = run.poses[m];
    pose.translation() = from + static_cast<double>(k - m) * step;
    truth.poses.push_back(pose);
  }
  const pipeline::MapEvaluation e = pipeline::evaluate_map(run, truth);
  ASSERT_TRUE(e.trajectory && e.trajectory_at_measured_poses);
  EXPECT_GT(e.trajectory->ate.translation_m.rmse, 0.01);
  EXPECT_EQ(e.trajectory_at_measured_poses->period, 5u);
  EXPECT_EQ(e.trajectory_at_measured_poses->ate.translation_m.count, 4u);  // poses 0, 5, 10, 15
  EXPECT_NEAR(e.trajectory_at_measured_poses->ate.translation_m.rmse, 0, 1e-9);
  // A reference that measured every pose: nothing more to say.
  EXPECT_FALSE(
      pipeline::evaluate_map(run, moved_truth(run, 99, 99, 0)).trajectory_at_measured_poses);
}

int yellow_pixels(const RgbImage& image) {
  int count = 0;
  for (int y = 0; y < image.height(); ++y)
    for (int x = 0; x < image.width(); ++x) count += image(x, y) == Rgb8{255, 200, 0};
  return count;
}

TEST(TopView, DrawsTheTruePathInYellowWhereGiven) {
  const pipeline::MapPipelineResult run = small_run(20);
  std::vector<Eigen::Vector3d> truth;
  for (const Eigen::Isometry3d& pose : run.poses)
    truth.push_back(pose.translation() + Eigen::Vector3d(0, 0.3, 0));
  EXPECT_EQ(yellow_pixels(io::render_top_view(run.map, run.poses)), 0);
  EXPECT_GT(yellow_pixels(io::render_top_view(run.map, run.poses, {}, truth)), 100);
}

TEST(HtmlText, Base64IsRfc4648sEncoding) {
  const auto encode = [](const std::string& s) {
    return io::detail::base64({reinterpret_cast<const std::uint8_t*>(s.data()), s.size()});
  };
  EXPECT_EQ(encode(""), "");
  EXPECT_EQ(encode("f"), "Zg==");
  EXPECT_EQ(encode("fo"), "Zm8=");
  EXPECT_EQ(encode("foo"), "Zm9v");
  EXPECT_EQ(encode("foobar"), "Zm9vYmFy");
  EXPECT_EQ(encode("\xff\xfe"), "//4=");
}

TEST(HtmlText, AnInlineScriptCannotEndItsElement) {
  EXPECT_EQ(io::detail::inline_script("a = '</script>'; b = '</SCRIPT'; c = x</y;"),
            "a = '<\\/script>'; b = '<\\/SCRIPT'; c = x</y;");
  EXPECT_EQ(io::detail::html_escape("<a href=\"x\">&</a>"),
            "&lt;a href=&quot;x&quot;&gt;&amp;&lt;/a&gt;");
  EXPECT_EQ(io::detail::format_length(0.0042), "4.2 mm");
  EXPECT_EQ(io::detail::format_length(0.0236), "2.36 cm");
  EXPECT_EQ(io::detail::format_length(12.4), "12.40 m");
}

TEST(ReportSvg, StepsAreOneTwoOrFiveTimesAPowerOfTen) {
  EXPECT_DOUBLE_EQ(io::detail::nice_step(10, 5), 2);
  EXPECT_DOUBLE_EQ(io::detail::nice_step(0.37, 5), 0.1);
  EXPECT_DOUBLE_EQ(io::detail::nice_step(1286, 8), 200);
  EXPECT_DOUBLE_EQ(io::detail::nice_step(0, 5), 1);
}

TEST(ReportSvg, ALinePlotHasEverySampleAndTheReferenceLine) {
  io::detail::PlotSeries series{"error", "#d62728", {{0, 1.0}, {1, 2.5}, {2, 0.5}, {5, 1.5}}};
  io::detail::PlotAxes axes;
  axes.x_label = "frame";
  axes.y_reference = {{1.6, "RMSE 1.60 cm"}};
  const std::string svg = io::detail::svg_line_plot({series}, axes);
  const std::smatch points = [&] {
    std::smatch m;
    std::regex_search(svg, m, std::regex("points=\"([^\"]*)\""));
    return m;
  }();
  ASSERT_FALSE(points.empty());
  EXPECT_EQ(std::count(points[1].first, points[1].second, ','), 4);
  EXPECT_NE(svg.find("RMSE 1.60 cm"), std::string::npos);
  EXPECT_NE(svg.find(">frame<"), std::string::npos);
  EXPECT_EQ(io::detail::svg_line_plot({}, axes), "<p>Nothing to plot.</p>\n");
}

// report.json as report_json writes it (the members the page reads).
Json report_of(bool with_evaluation) {
  Json r = Json::parse(R"json({"format": "kartograf-map-report", "version": 1,
    "sequence": "/data/a<b>&c", "layout": "synthetic", "backend": "cpu", "device": "cpu", "frames": 20,
    "input": {"camera": {"fx": 535.4, "fy": 539.2, "cx": 320.1, "cy": 247.6, "width": 640,
              "height": 480, "source": "preset", "description": "tum-fr3"},
              "depth_units_per_metre": 5000, "depth_scale_source": "TUM: 5000 units per metre", "frames_skipped": 2,
              "colour": false},
    "timing_s": {"total": 2.0, "stages": [{"stage": "slam", "seconds": 1.5},
                                          {"stage": "rooms", "seconds": 0.5}]},
    "slam": {"loop_candidates": 3, "loop_closures_accepted": 1, "loop_closures_pruned": 0,
             "pose_graph_converged": true, "map_points": 1000, "degenerate_frames": 7,
             "degenerate_frames_unmeasured": 4, "fallback_frames": 1,
             "degenerate_unmeasured_poses": [3, 5, 9, 12], "fallback_poses": [7],
             "frames_from_motion_prior": 19, "motion_prior_difference_median_m": 0.0004,
             "motion_prior_difference_max_m": 0.0123, "motion_prior_difference_max_deg": 0.5,
             "motion_prior_clock": {"text": "its turning matches best read at +0.040 s (+- 0.2 ms)",
                                    "agrees": false}},
    "views": {"labelled": 3, "unlabelled": 1, "first_unlabelled_reason": "no floor"},
    "planes": {"count": 3, "by_class": {"floor": 1, "wall": 2}},
    "grid": {"width": 10, "height": 20, "resolution_m": 0.05, "objects": {}},
    "rooms": {"method": "distance", "count": 2, "enclosed_cells_taken": 0}})json");
  if (with_evaluation)
    r["evaluation"] = Json::parse(R"({
      "trajectory": {"ate_rmse_m": 0.0123, "ate_max_m": 0.03, "rpe_translation_rmse_m": 0.002,
                     "rpe_rotation_rmse_deg": 0.1, "poses": 19},
      "odometry_trajectory": {"ate_rmse_m": 0.0246, "ate_max_m": 0.05,
                              "rpe_translation_rmse_m": 0.003, "rpe_rotation_rmse_deg": 0.2,
                              "poses": 19},
      "trajectory_at_measured_poses": {"ate_rmse_m": 0.0111, "poses": 4, "ground_truth_period": 5},
      "rooms": {"ground_truth_rooms": 2, "segments": 2, "recall_mean": 0.95, "recall_total": 0.96,
                "precision_mean": 0.85, "precision_total": 0.9, "mcc": 1.0},
      "classes": {"iou": {"unknown": null, "floor": 0.9, "wall": 0.3, "ceiling": null, "door": 0.81,
                          "furniture": 0.0},
                  "confusion": {"unknown": {"unknown": 0, "floor": 0, "wall": 0, "door": 0},
                                "floor": {"unknown": 20, "floor": 80, "wall": 0, "door": 0},
                                "wall": {"unknown": 1, "floor": 2, "wall": 3, "door": 4},
                                "door": {"unknown": 0, "floor": 0, "wall": 0, "door": 7}},
                  "mean_iou": 0.5, "overall_accuracy": 0.8, "cells": 117},
      "not_scored": ["nothing"]})");
  return r;
}

struct Page {
  pipeline::MapPipelineResult run = small_run(20);
  std::optional<pipeline::MapEvaluation> evaluation;
  std::string html;
  Page(bool with_evaluation, bool picture) {
    if (with_evaluation) evaluation = pipeline::evaluate_map(run, moved_truth(run, 3, 7, 0.05));
    const Json report = report_of(with_evaluation);
    html = io::detail::map_report_html({report, run, evaluation, picture});
  }
  std::size_t at(const std::string& text) const { return html.find(text); }
  // The page without its inline scripts (three.js' own text is no part of the page's markup).
  std::string markup() const {
    std::string out;
    std::size_t from = 0;
    for (std::size_t at = html.find("<script>"); at != std::string::npos;
         at = html.find("<script>", from)) {
      out += html.substr(from, at - from);
      from = html.find("</script>", at) + 9;
    }
    return out + html.substr(from);
  }
};

TEST(MapReportHtml, SummaryAndMetricsFirstThenPicturesPlotsConfusionAnd3dView) {
  const Page page(true, true);
  std::vector<std::size_t> order;
  for (const char* id :
       {"summary", "metrics", "pictures", "plots", "confusion", "view3d", "details"}) {
    order.push_back(page.at("<section id=\"" + std::string(id) + "\">"));
    ASSERT_NE(order.back(), std::string::npos) << id;
  }
  EXPECT_TRUE(std::is_sorted(order.begin(), order.end()));
  EXPECT_NE(page.at("f<sub>x</sub> 535.4"), std::string::npos);  // the camera
  EXPECT_NE(page.at("480 <span class=\"note\">(tum-fr3)</span>"), std::string::npos);
  EXPECT_NE(page.at("5000 depth units per metre (TUM)<"), std::string::npos);
  EXPECT_NE(page.at("2 unreadable frames skipped"), std::string::npos);
  EXPECT_NE(page.at("none: a depth camera alone"), std::string::npos);
  // Where the trajectory is the motion model's: degenerate views no image or feature measured.
  EXPECT_NE(page.at("7 degenerate views <span class=\"note\">(4 with no image or feature"),
            std::string::npos);
  EXPECT_NE(page.at(", poses 3, 5, 9, 12 of trajectory.txt counting from 0: there the trajectory "
                    "is the motion model's"),
            std::string::npos);  // which poses to distrust
  EXPECT_NE(page.at(", 1 fallbacks, pose 7 of trajectory.txt"), std::string::npos);
  // How far the steps taken were from the motion prior's (its slip or a wrong mount).
  EXPECT_NE(page.at(", 19 steps predicted by the motion prior (the steps taken differ from its "
                    "by median 0.4 mm, at most 1.23 cm)"),
            std::string::npos);
  EXPECT_NE(page.at("at most 1.23 cm); the prior's clock: its turning matches best read at "
                    "+0.040 s (+- 0.2 ms)"),
            std::string::npos);                                             // as the summary says
  EXPECT_NE(page.at("1.23 cm"), std::string::npos);                         // the ATE
  EXPECT_NE(page.at("class=\"value missed\">1.23 cm"), std::string::npos);  // target 1 cm
  EXPECT_NE(page.at("odometry alone: ATE RMSE"), std::string::npos);        // before loop closure
  EXPECT_NE(page.at("the back end changes the ATE by -50 %"), std::string::npos);
  EXPECT_NE(page.at("ATE RMSE at the measured poses</th><td class=\"value\">1.11 cm"),
            std::string::npos);  // the truth interpolated between every 5th pose
  EXPECT_NE(page.at("class=\"value met\">0.810"), std::string::npos);  // door IoU, target 0.8
  EXPECT_NE(page.at("Not scored: nothing"), std::string::npos);
  EXPECT_NE(page.at("<svg class=\"plot\""), std::string::npos);  // the error over time
  EXPECT_NE(page.at("<svg class=\"bars\""), std::string::npos);  // the stage times
  EXPECT_EQ(page.at("<b>"), page.at("<b>top_view.png</b>"));     // the sequence's name is escaped
  EXPECT_NE(page.at("/data/a&lt;b&gt;&amp;c"), std::string::npos);
}

TEST(MapReportHtml, ConfusionRowsAreTrueClassesShadedByTheirShare) {
  const Page page(true, false);
  const std::string confusion = page.html.substr(page.at("<section id=\"confusion\">"));
  EXPECT_EQ(confusion.find("<tr><th>unknown</th>"), std::string::npos);  // no true cell
  EXPECT_NE(confusion.find("<tr><th>floor</th><td style=\"background:rgba(200,60,50,0.25)\" "
                           "title=\"20.0 % of the row\">20<small>20 %</small></td>"
                           "<td class=\"diagonal\" style=\"background:rgba(34,139,84,0.76)\""),
            std::string::npos);
}

TEST(MapReportHtml, LinksOnlyFilesOfItsOwnFolder) {
  for (const bool picture : {false, true}) {
    const Page page(true, picture);
    std::set<std::string> files(io::map_output_files().begin(), io::map_output_files().end());
    if (picture) files.insert("evaluation.png");
    const std::string markup = page.markup();
    const std::regex link("(src|href)=\"([^\"]*)\"");
    std::set<std::string> linked;
    for (auto m = std::sregex_iterator(markup.begin(), markup.end(), link);
         m != std::sregex_iterator(); ++m)
      linked.insert((*m)[2]);
    for (const std::string& file : linked) EXPECT_TRUE(files.count(file)) << file;
    EXPECT_EQ(linked.count("evaluation.png"), picture ? 1u : 0u);
    EXPECT_TRUE(linked.count("top_view.png") && linked.count("semantic.png"));
    EXPECT_EQ(page.html.find("<script src"), std::string::npos);
  }
}

TEST(MapReportHtml, WithoutGroundTruthItSaysSoAndDrawsNoTruth) {
  const Page page(false, false);
  EXPECT_NE(page.at("has no ground truth"), std::string::npos);
  EXPECT_EQ(page.at("<section id=\"confusion\">"), std::string::npos);
  EXPECT_EQ(page.at("<svg class=\"plot\""), std::string::npos);
  EXPECT_EQ(page.at("true path"), std::string::npos);
  EXPECT_NE(page.at("\"truth\":[]"), std::string::npos);
}

Json scene_data(const std::string& html) {
  const std::string open = "<script type=\"application/json\" id=\"map-3d-data\">";
  const std::size_t from = html.find(open) + open.size();
  return Json::parse(html.substr(from, html.find("</script>", from) - from));
}

TEST(MapReportHtml, The3dViewKeepsAtMostMaxPointsWithTheirColours) {
  const Page page(true, false);
  const Json report = report_of(true);
  const Json scene =
      scene_data(io::detail::report_scene_section({report, page.run, page.evaluation, false}, 100));
  ASSERT_EQ(scene["count"], 100);
  EXPECT_EQ(scene["total"], 1000);
  const std::vector<std::uint8_t> q = from_base64(scene["positions"].get<std::string>());
  const std::vector<std::uint8_t> colours = from_base64(scene["colours"].get<std::string>());
  ASSERT_EQ(q.size(), 600u);
  ASSERT_EQ(colours.size(), 300u);
  for (std::size_t k = 0; k < 100; ++k) {
    const std::size_t i = k * 10;  // every tenth point
    for (int a = 0; a < 3; ++a) {
      const double low = scene["min"][a], high = scene["max"][a];
      const double v =
          low + (high - low) * (q[6 * k + 2 * a] | q[6 * k + 2 * a + 1] << 8) / 65535.0;
      EXPECT_NEAR(v, page.run.map.points[i][a], 1e-4) << k;
      EXPECT_EQ(colours[3 * k + a], page.run.map.colors[i][a]);
    }
  }
  EXPECT_EQ(scene["estimated"].size(), 60u);
  EXPECT_EQ(scene["truth"].size(), 57u);  // 19 frames with a true pose
  EXPECT_DOUBLE_EQ(scene["ceiling_z"].get<double>(), 1.2 + io::TopViewParams{}.ceiling_clearance);
}

}  // namespace
}  // namespace kartograf
