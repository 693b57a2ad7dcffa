// kartograf_plane_peer_bench: plane segmentation of Kartograf (segmentation::PlaneExtractor, the
// M1 method), PCL (IntegralImageNormalEstimation + OrganizedMultiPlaneSegmentation with
// refinement) and Open3D (SegmentPlane, RANSAC, in a loop) on the same frames, in one run (issue
// 5, part 8; docs/benchmarks.md holds the results). Open3D 0.16 has no DetectPlanarPatches.
//
//   frames   synthetic: 24 frames spread over the robot tour of the synthetic building (seed 1,
//            640x480, Kinect noise model), exact plane ids; 7-Scenes RedKitchen frames 0, 30 ..
//            270; the 6 organized PCL mOSD table-top frames (labels 1-9: the table).
//   input    every method gets Kartograf's organized cloud of the frame (NaN where invalid) and its
//            colour; conversion to the library's types is not timed.
//   timing   per method: one untimed warm-up call on the first frame, then one call per frame;
//            the median over frames (wall clock). PCL's normal estimation is inside its time (it
//            needs them; shown separately too).
//   quality  synthetic: ground-truth planes over 1 % of the image correctly detected (SegComp,
//            overlap >= 80 % both ways; coplanar faces that touch count as one plane) and the
//            median normal error of those; mOSD: the best plane's IoU with the table; 7-Scenes:
//            planes per frame. Every method's output becomes a plane id per pixel.
// Threads: OMP_NUM_THREADS (Open3D, PCL's OpenMP parts) and KARTOGRAF_CPU_THREADS (Kartograf).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <iostream>
#include <map>
#include <memory>
#include <numeric>
#include <string>
#include <vector>

#include <open3d/geometry/PointCloud.h>
#include <pcl/features/integral_image_normal.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/segmentation/organized_multi_plane_segmentation.h>
#include <pcl/features/impl/integral_image_normal.hpp>
#include <pcl/segmentation/impl/organized_multi_plane_segmentation.hpp>

#include "kartograf/compute/context.hpp"
#include "kartograf/eval/plane_metrics.hpp"
#include "kartograf/geometry/backproject.hpp"
#include "kartograf/io/pcd.hpp"
#include "kartograf/io/sequence_detect.hpp"
#include "kartograf/segmentation/plane_extraction.hpp"
#include "kartograf/synth/render.hpp"
#include "kartograf/synth/trajectory.hpp"
#include "kartograf/synth/world.hpp"

namespace kartograf::peer {
namespace {

using Clock = std::chrono::steady_clock;
constexpr std::size_t kMinPlanePixels = 300;  // Kartograf's min_plane_pixels, for every method

struct Frame {
  std::string dataset;  // "synthetic", "7scenes", "mosd"
  PointImage points;
  RgbImage color;
  PinholeIntrinsics camera;
  LabelImage truth;                                // synthetic: plane ids; mOSD: table = 1
  std::map<Label, Eigen::Vector3d> truth_normals;  // synthetic, camera frame
};

// A method's planes: a plane id per pixel (0: none) and each plane's unit normal.
struct Segmentation {
  LabelImage labels;
  std::map<Label, Eigen::Vector3d> normals;
};

struct Method {
  std::string name;
  std::string settings;
  std::function<Segmentation(const Frame&)> run;
};

std::vector<Frame> synthetic_frames() {
  const synth::World world = synth::make_building(1);
  const std::vector<Label> surface = synth::continuous_surface_ids(world);
  const PinholeIntrinsics camera{640, 480, 525.0, 525.0, 319.5, 239.5};
  const Trajectory tour = synth::robot_tour(world, 300);
  const compute::Context cpu = compute::Context::cpu();
  std::vector<Frame> frames;
  for (int f = 0; f < 24; ++f) {
    const int index = 7 + f * 290 / 24;
    const Eigen::Isometry3d& pose = tour[index].pose;
    const synth::SyntheticFrame rendered =
        synth::render(world, camera, pose, synth::NoiseModel::kinect(), 1000 + index);
    Frame frame{"synthetic",
                geometry::backproject(cpu, rendered.depth, camera, {synth::kTumDepthUnitsPerMetre}),
                rendered.color,
                camera,
                rendered.plane_id,
                {}};
    for (std::size_t i = 0; i < frame.truth.size(); ++i) {
      Label& l = frame.truth.data()[i];
      l = rendered.depth.data()[i] == 0 ? kUnlabeled : surface[l];
    }
    for (const synth::Plane& plane : world.planes)
      frame.truth_normals[plane.id] = pose.linear().transpose() * plane.normal;
    frames.push_back(std::move(frame));
  }
  return frames;
}

std::vector<Frame> seven_scenes_frames(const std::filesystem::path& data) {
  const io::OpenedSequence opened = io::open_sequence(data / "7scenes_redkitchen");
  const compute::Context cpu = compute::Context::cpu();
  geometry::DepthRange range;
  range.units_per_metre = opened.sequence->depth_units_per_metre();
  std::vector<Frame> frames;
  for (std::size_t i = 0; i < 300; i += 30) {
    io::RgbdFrame frame = opened.sequence->frame(i);
    frames.push_back({"7scenes",
                      geometry::backproject(cpu, frame.depth, opened.sequence->intrinsics(), range),
                      std::move(frame.color),
                      opened.sequence->intrinsics(),
                      {},
                      {}});
  }
  return frames;
}

std::vector<Frame> mosd_frames(const std::filesystem::path& data) {
  std::vector<Frame> frames;
  for (const char* name : {"test0", "test16", "test24", "test31", "test55", "test57"}) {
    const io::PcdCloud cloud = io::read_pcd(data / "pcl_mosd" / (std::string(name) + ".pcd"));
    Frame frame{"mosd",
                cloud.to_point_image(),
                RgbImage(cloud.width, cloud.height),
                PinholeIntrinsics::kinect_7scenes(),
                LabelImage(cloud.width, cloud.height, 0),
                {}};
    std::copy(cloud.colors.begin(), cloud.colors.end(), frame.color.data());
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      if (cloud.labels[i] >= 1 && cloud.labels[i] <= 9 && is_valid(frame.points.data()[i]))
        frame.truth.data()[i] = 1;
    }
    frames.push_back(std::move(frame));
  }
  return frames;
}

// --- the methods ---

Method kartograf_method(const compute::Context& context) {
  auto extractors = std::make_shared<
      std::map<std::pair<int, double>, std::unique_ptr<segmentation::PlaneExtractor>>>();
  return {"kartograf PlaneExtractor (cpu)",
          "defaults: Lab 15, 16 px tiles, 2 % depth jump, merge 30 deg; " +
              std::string(std::getenv("KARTOGRAF_CPU_THREADS")
                              ? "KARTOGRAF_CPU_THREADS=" +
                                    std::string(std::getenv("KARTOGRAF_CPU_THREADS"))
                              : "1 thread"),
          [&context, extractors](const Frame& frame) {
            auto& extractor = (*extractors)[{frame.camera.width, frame.camera.fx}];
            if (!extractor)
              extractor = std::make_unique<segmentation::PlaneExtractor>(context, frame.camera);
            const segmentation::PlaneSet set = extractor->extract(frame.points, frame.color);
            Segmentation out{set.labels, {}};
            for (const segmentation::Plane& plane : set.planes)
              out.normals[plane.id] = plane.normal;
            return out;
          }};
}

pcl::PointCloud<pcl::PointXYZRGB>::Ptr to_pcl(const Frame& frame) {
  auto cloud = std::make_shared<pcl::PointCloud<pcl::PointXYZRGB>>();
  cloud->width = static_cast<std::uint32_t>(frame.points.width());
  cloud->height = static_cast<std::uint32_t>(frame.points.height());
  cloud->is_dense = false;
  cloud->points.resize(frame.points.size());
  for (std::size_t i = 0; i < frame.points.size(); ++i) {
    const Point4f& p = frame.points.data()[i];
    pcl::PointXYZRGB& q = cloud->points[i];
    const float nan = std::numeric_limits<float>::quiet_NaN();
    q.x = is_valid(p) ? p.x() : nan;
    q.y = is_valid(p) ? p.y() : nan;
    q.z = is_valid(p) ? p.z() : nan;
    q.r = frame.color.data()[i][0];
    q.g = frame.color.data()[i][1];
    q.b = frame.color.data()[i][2];
  }
  return cloud;
}

// PCL's organized segmentation as its demo (organized_segmentation_demo) sets it up.
Method pcl_method(double* normal_ms) {
  return {"pcl OrganizedMultiPlaneSegmentation + refine",
          "IntegralImageNormalEstimation COVARIANCE_MATRIX, depth change 0.02, smoothing 10; "
          "min inliers 300, angle 3 deg, distance 0.02",
          [normal_ms](const Frame& frame) {
            const pcl::PointCloud<pcl::PointXYZRGB>::Ptr cloud = to_pcl(frame);
            const Clock::time_point start = Clock::now();
            auto normals = std::make_shared<pcl::PointCloud<pcl::Normal>>();
            pcl::IntegralImageNormalEstimation<pcl::PointXYZRGB, pcl::Normal> estimation;
            estimation.setNormalEstimationMethod(estimation.COVARIANCE_MATRIX);
            estimation.setMaxDepthChangeFactor(0.02f);
            estimation.setNormalSmoothingSize(10.0f);
            estimation.setInputCloud(cloud);
            estimation.compute(*normals);
            *normal_ms = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
            pcl::OrganizedMultiPlaneSegmentation<pcl::PointXYZRGB, pcl::Normal, pcl::Label> omps;
            omps.setMinInliers(kMinPlanePixels);
            omps.setAngularThreshold(3.0 * M_PI / 180.0);
            omps.setDistanceThreshold(0.02);
            omps.setInputNormals(normals);
            omps.setInputCloud(cloud);
            std::vector<pcl::PlanarRegion<pcl::PointXYZRGB>,
                        Eigen::aligned_allocator<pcl::PlanarRegion<pcl::PointXYZRGB>>>
                regions;
            std::vector<pcl::ModelCoefficients> coefficients;
            std::vector<pcl::PointIndices> inliers, label_indices, boundaries;
            auto labels = std::make_shared<pcl::PointCloud<pcl::Label>>();
            omps.segmentAndRefine(regions, coefficients, inliers, labels, label_indices,
                                  boundaries);
            Segmentation out{LabelImage(frame.points.width(), frame.points.height(), 0), {}};
            for (std::size_t k = 0; k < inliers.size() && k < 65535; ++k) {
              const auto id = static_cast<Label>(k + 1);
              for (const int i : inliers[k].indices) out.labels.data()[i] = id;
              const auto& c = coefficients[k].values;
              out.normals[id] = Eigen::Vector3d(c[0], c[1], c[2]).normalized();
            }
            return out;
          }};
}

Method open3d_method() {
  return {"open3d SegmentPlane loop",
          "RANSAC distance 0.02, 3 points, 1000 iterations; until < 300 points remain or fit "
          "(at most 60 planes)",
          [](const Frame& frame) {
            auto cloud = std::make_shared<open3d::geometry::PointCloud>();
            std::vector<std::size_t> pixel;  // cloud point -> pixel
            for (std::size_t i = 0; i < frame.points.size(); ++i) {
              const Point4f& p = frame.points.data()[i];
              if (!is_valid(p)) continue;
              cloud->points_.emplace_back(p.x(), p.y(), p.z());
              pixel.push_back(i);
            }
            Segmentation out{LabelImage(frame.points.width(), frame.points.height(), 0), {}};
            for (Label id = 1; id <= 60 && cloud->points_.size() >= kMinPlanePixels; ++id) {
              const auto [model, inliers] = cloud->SegmentPlane(0.02, 3, 1000);
              if (inliers.size() < kMinPlanePixels) break;
              for (const std::size_t k : inliers) out.labels.data()[pixel[k]] = id;
              out.normals[id] = model.head<3>().normalized();
              std::vector<bool> taken(cloud->points_.size(), false);
              for (const std::size_t k : inliers) taken[k] = true;
              std::vector<std::size_t> remaining_pixels;
              auto remaining = std::make_shared<open3d::geometry::PointCloud>();
              for (std::size_t k = 0; k < taken.size(); ++k) {
                if (taken[k]) continue;
                remaining->points_.push_back(cloud->points_[k]);
                remaining_pixels.push_back(pixel[k]);
              }
              cloud = remaining;
              pixel = std::move(remaining_pixels);
            }
            return out;
          }};
}

// --- scoring ---

double median(std::vector<double> values) {
  if (values.empty()) return 0;
  std::sort(values.begin(), values.end());
  return values[values.size() / 2];
}

struct Scores {
  std::vector<double> ms, normal_ms;
  int large = 0, detected = 0;
  std::vector<double> normal_errors, table_iou, planes_7scenes;
};

void score(const Frame& frame, const Segmentation& out, Scores& scores) {
  if (frame.dataset == "7scenes") {
    std::map<Label, int> sizes;
    for (const Label l : out.labels.pixels())
      if (l) ++sizes[l];
    scores.planes_7scenes.push_back(static_cast<double>(sizes.size()));
    return;
  }
  if (frame.dataset == "mosd") {
    std::map<Label, std::int64_t> overlap, size;
    std::int64_t table = 0;
    for (std::size_t i = 0; i < out.labels.size(); ++i) {
      const Label l = out.labels.data()[i];
      table += frame.truth.data()[i];
      if (l == 0) continue;
      ++size[l];
      overlap[l] += frame.truth.data()[i];
    }
    double best = 0;
    for (const auto& [l, o] : overlap)
      best = std::max(best, double(o) / double(table + size[l] - o));
    scores.table_iou.push_back(best);
    return;
  }
  const eval::SegCompResult result = eval::compare_plane_segmentations(
      frame.truth, out.labels, {0.8}, frame.truth_normals, out.normals);
  std::map<Label, std::int64_t> sizes;
  for (const Label l : frame.truth.pixels())
    if (l) ++sizes[l];
  for (const auto& [label, pixels] : sizes) {
    if (pixels * 100 <= static_cast<std::int64_t>(frame.truth.size())) continue;
    ++scores.large;
    for (const auto& [truth, predicted] : result.correct_pairs) {
      if (truth != label) continue;
      ++scores.detected;
      const double cosine = std::min(
          1.0,
          std::fabs(frame.truth_normals.at(truth).normalized().dot(out.normals.at(predicted))));
      scores.normal_errors.push_back(std::acos(cosine) * 180.0 / M_PI);
    }
  }
}

int run() {
  const char* data_env = std::getenv("KARTOGRAF_DATA_DIR");
  const std::filesystem::path data = data_env ? data_env : KARTOGRAF_DEFAULT_DATA_DIR;
  std::cerr << "plane peer bench: loading frames\n";
  std::vector<Frame> frames = synthetic_frames();
  for (auto* more : {&seven_scenes_frames, &mosd_frames}) {
    std::vector<Frame> extra = (*more)(data);
    for (Frame& f : extra) frames.push_back(std::move(f));
  }
  const compute::Context cpu = compute::Context::cpu();
  double pcl_normal_ms = 0;
  const std::vector<Method> methods{kartograf_method(cpu), pcl_method(&pcl_normal_ms),
                                    open3d_method()};
  std::vector<Scores> all(methods.size());
  for (std::size_t m = 0; m < methods.size(); ++m) {
    std::cerr << "  " << methods[m].name << std::flush;
    methods[m].run(frames.front());  // warm-up
    for (const Frame& frame : frames) {
      const Clock::time_point start = Clock::now();
      const Segmentation out = methods[m].run(frame);
      all[m].ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - start).count());
      all[m].normal_ms.push_back(pcl_normal_ms);
      score(frame, out, all[m]);
    }
    std::cerr << " done\n";
  }
  const char* omp = std::getenv("OMP_NUM_THREADS");
  std::printf(
      "Plane segmentation, %zu frames 640x480 (24 synthetic, 10 7-Scenes, 6 mOSD); "
      "OMP_NUM_THREADS=%s\n\n",
      frames.size(), omp ? omp : "unset");
  std::printf(
      "| method | median ms/frame | frames/s | time / Kartograf's | synthetic planes > 1 %% "
      "detected | median normal error (deg) | mOSD table IoU mean (min) | 7-Scenes planes/frame "
      "|\n|---|---:|---:|---:|---:|---:|---:|---:|\n");
  const double reference = median(all[0].ms);
  for (std::size_t m = 0; m < methods.size(); ++m) {
    const Scores& s = all[m];
    const double ms = median(s.ms);
    std::printf("| %s | %.1f | %.0f | %.2f | %d of %d (%.1f %%) | %.2f | %.3f (%.3f) | %.0f |\n",
                methods[m].name.c_str(), ms, 1000.0 / ms, ms / reference, s.detected, s.large,
                100.0 * s.detected / std::max(1, s.large), median(s.normal_errors),
                std::accumulate(s.table_iou.begin(), s.table_iou.end(), 0.0) /
                    std::max<std::size_t>(1, s.table_iou.size()),
                *std::min_element(s.table_iou.begin(), s.table_iou.end()),
                median(s.planes_7scenes));
  }
  std::printf("\nPCL's normal estimation alone: median %.1f ms/frame (inside its time above).\n",
              median(all[1].normal_ms));
  for (const Method& m : methods) std::printf("- %s: %s\n", m.name.c_str(), m.settings.c_str());
  return 0;
}

}  // namespace
}  // namespace kartograf::peer

int main() {
  try {
    return kartograf::peer::run();
  } catch (const std::exception& e) {
    std::cerr << "kartograf_plane_peer_bench: " << e.what() << "\n";
    return 1;
  }
}
