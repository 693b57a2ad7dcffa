// Plane fits from segment moments, merging, and the plane extraction pipeline (docs/methods.md M1
// steps 2-4): exact synthetic planes, hand-built merges, acceptance on rendered synthetic frames
// with exact plane ids, determinism, and bad input (the PCL mOSD table-top frames, read through
// kartograf_io: plane_extraction_mosd_test.cpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <map>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include "compute/cpu/wide_lanes.hpp"
#include "kartograf/eval/plane_metrics.hpp"
#include "kartograf/geometry/backproject.hpp"
#include "kartograf/segmentation/plane_extraction.hpp"
#include "kartograf/synth/render.hpp"
#include "kartograf/synth/trajectory.hpp"
#include "test_support.hpp"

namespace kartograf {
namespace {

using segmentation::PlaneFitMethod;
using segmentation::SegmentPlane;
using testing::BackendTest;

double angle_deg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::acos(std::clamp(std::fabs(a.normalized().dot(b.normalized())), 0.0, 1.0)) * 180.0 /
         M_PI;
}

// A point grid on the plane through `centre` spanned by u and v, as an organized image.
PointImage plane_patch(const Eigen::Vector3d& centre, const Eigen::Vector3d& u,
                       const Eigen::Vector3d& v, int width, int height) {
  PointImage points(width, height);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const Eigen::Vector3d p = centre + (x - width / 2) * 0.01 * u + (y - height / 2) * 0.01 * v;
      points(x, y) = Point4f(float(p.x()), float(p.y()), float(p.z()), 1.0f);
    }
  }
  return points;
}

geometry::SegmentMomentSet moments_of(const compute::Context& context, const PointImage& points,
                                      const std::vector<std::uint32_t>& labels,
                                      std::uint32_t count) {
  segmentation::SegmentPlaneFitter fitter(context);
  const auto buffer = compute::Buffer<Point4f>::from_host(context, points.pixels());
  return fitter.moments(buffer, labels, count, Eigen::Vector3f(0, 0, 2), 8.0f);
}

class PlaneFitTest : public BackendTest {};

TEST_P(PlaneFitTest, TotalLeastSquaresFitsHorizontalAndVerticalPlanesExactly) {
  // Camera frame: y down. A floor-like plane (normal ~ y) and a wall seen edge-on in x (normal x,
  // vertical: z = A x + B y + C has no solution).
  const PointImage floor = plane_patch({0.1, 0.8, 2.0}, Eigen::Vector3d(1, 0.05, 0).normalized(),
                                       Eigen::Vector3d(0, 0.1, 1).normalized(), 40, 30);
  const PointImage wall =
      plane_patch({-0.7, 0.0, 2.5}, Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(0, 1, 0), 40, 30);
  for (const auto& [name, points] : {std::pair{"floor", &floor}, std::pair{"wall", &wall}}) {
    SCOPED_TRACE(name);
    const std::vector<std::uint32_t> labels(points->size(), 0);
    const geometry::SegmentMomentSet moments = moments_of(context(), *points, labels, 1);
    ASSERT_EQ(moments.segments.size(), 1u);
    EXPECT_EQ(moments.segments[0].count, points->size());
    const Eigen::Vector3d p0 = (*points)(0, 0).head<3>().cast<double>();
    const Eigen::Vector3d p1 = (*points)(39, 0).head<3>().cast<double>();
    const Eigen::Vector3d p2 = (*points)(0, 29).head<3>().cast<double>();
    const Eigen::Vector3d truth = (p1 - p0).cross(p2 - p0).normalized();

    const SegmentPlane tls = segmentation::fit_plane(moments.segments[0], moments.origin);
    ASSERT_TRUE(tls.valid);
    EXPECT_LT(angle_deg(tls.normal, truth), 1e-3);
    EXPECT_LT(tls.rms_error, 1e-5);
    EXPECT_LT(tls.normal.dot(tls.centroid), 0.0);  // towards the camera
    EXPECT_NEAR(tls.normal.dot(p0) + tls.offset, 0.0, 1e-5);
    EXPECT_NEAR(tls.normal.dot(tls.major_axis), 0.0, 1e-9);
    EXPECT_NEAR(tls.normal.cross(tls.major_axis).dot(tls.minor_axis), 1.0, 1e-9);

    segmentation::PlaneFitParams paper;
    paper.method = PlaneFitMethod::paper_eq6;
    const SegmentPlane eq6 = segmentation::fit_plane(moments.segments[0], moments.origin, paper);
    if (points == &wall) {
      EXPECT_FALSE(eq6.valid) << "eq. 6 cannot represent a plane parallel to z";
    } else {
      ASSERT_TRUE(eq6.valid);
      EXPECT_LT(angle_deg(eq6.normal, truth), 1e-3);
    }
  }
}

TEST_P(PlaneFitTest, DropsTinyAndCollinearSegments) {
  PointImage points =
      plane_patch({0, 0, 2}, Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(), 10, 3);
  std::vector<std::uint32_t> labels(points.size(), geometry::kNoLabel);
  for (int x = 0; x < 10; ++x) labels[x] = 0;  // one row: collinear
  labels[10] = labels[11] = 1;                 // two points
  const geometry::SegmentMomentSet moments = moments_of(context(), points, labels, 2);
  EXPECT_FALSE(segmentation::fit_plane(moments.segments[0], moments.origin).valid);
  EXPECT_FALSE(segmentation::fit_plane(moments.segments[1], moments.origin).valid);
  EXPECT_EQ(moments.segments[0].count, 10u);
}

KARTOGRAF_INSTANTIATE_BACKEND_TESTS(PlaneFitTest);

// Hand-built merge cases: a plane image split into 4 vertical strips (segments 0..3).
struct StripScene {
  PointImage points;
  segmentation::SegmentLabelImage labels;
};

StripScene strips(const std::vector<double>& strip_depths, const std::vector<double>& strip_tilts) {
  StripScene scene{PointImage(40, 20), segmentation::SegmentLabelImage(40, 20)};
  for (int y = 0; y < 20; ++y) {
    for (int x = 0; x < 40; ++x) {
      const int s = x / 10;
      const double px = (x - 20) * 0.01, py = (y - 10) * 0.01;
      const double z = strip_depths[s] + strip_tilts[s] * (px - ((s * 10 + 5) - 20) * 0.01);
      scene.points(x, y) = Point4f(float(px * z / 2.0), float(py * z / 2.0), float(z), 1.0f);
      scene.labels(x, y) = static_cast<std::uint32_t>(s);
    }
  }
  return scene;
}

std::vector<std::uint32_t> merge_strips(const StripScene& scene,
                                        const segmentation::PlaneMergeParams& params) {
  const compute::Context context = compute::Context::cpu();
  const std::vector<std::uint32_t> labels(scene.labels.pixels().begin(),
                                          scene.labels.pixels().end());
  const geometry::SegmentMomentSet moments = moments_of(context, scene.points, labels, 4);
  return segmentation::merge_segments(scene.labels, moments, params).segment_plane;
}

TEST(PlaneMerge, JoinsCoplanarNeighboursAndKeepsOffsetAndTiltedOnesApart) {
  segmentation::PlaneMergeParams params;
  params.min_seed_pixels = 50;
  params.min_pixels_for_angle = 50;
  // Four coplanar strips: one plane.
  EXPECT_EQ(merge_strips(strips({2, 2, 2, 2}, {0, 0, 0, 0}), params),
            (std::vector<std::uint32_t>{0, 0, 0, 0}));
  // Strip 2 ten centimetres behind (parallel, offset): it and strip 3 beyond it form a second
  // plane; joining across the gap (join_apart) reunites 0-1 with 3 only if it is off.
  params.join_apart = false;
  EXPECT_EQ(merge_strips(strips({2, 2, 2.1, 2}, {0, 0, 0, 0}), params),
            (std::vector<std::uint32_t>{0, 0, 1, 2}));
  params.join_apart = true;
  EXPECT_EQ(merge_strips(strips({2, 2, 2.1, 2}, {0, 0, 0, 0}), params),
            (std::vector<std::uint32_t>{0, 0, 1, 0}));
  // Strip 3 tilted by 45 degrees: its own plane.
  const std::vector<std::uint32_t> tilted =
      merge_strips(strips({2, 2, 2, 2}, {0, 0, 0, 1}), params);
  EXPECT_EQ(tilted[0], tilted[1]);
  EXPECT_EQ(tilted[1], tilted[2]);
  EXPECT_NE(tilted[2], tilted[3]);
}

// What a caller may hand merging instead of having it recomputed (the cells mode does): the
// segments' graph, fits and pixel sums.
struct GivenMergeInputs {
  std::vector<segmentation::SegmentPlane> fits;
  std::vector<Eigen::Vector3d> pixel_sums;
  segmentation::SegmentGraph graph;
};

GivenMergeInputs given_merge_inputs(const StripScene& scene,
                                    const geometry::SegmentMomentSet& moments,
                                    const segmentation::PlaneMergeParams& params) {
  GivenMergeInputs given;
  given.pixel_sums.assign(moments.segments.size(), Eigen::Vector3d::Zero());
  for (const geometry::SegmentMoments& m : moments.segments)
    given.fits.push_back(segmentation::fit_plane(m, moments.origin, params.fit));
  for (int y = 0; y < scene.labels.height(); ++y) {
    for (int x = 0; x < scene.labels.width(); ++x)
      given.pixel_sums[scene.labels(x, y)] += Eigen::Vector3d(x, y, 1.0);
  }
  given.graph = segmentation::pixel_adjacency_graph(
      scene.labels, static_cast<std::uint32_t>(moments.segments.size()));
  return given;
}

geometry::SegmentMomentSet strip_moments(const StripScene& scene) {
  const compute::Context context = compute::Context::cpu();
  const std::vector<std::uint32_t> labels(scene.labels.pixels().begin(),
                                          scene.labels.pixels().end());
  return moments_of(context, scene.points, labels, 4);
}

// The given graph, fits and pixel sums give the same planes as merging finds them itself; inputs
// of the wrong size are refused.
TEST(PlaneMerge, GivenGraphFitsAndPixelSumsChangeNothing) {
  segmentation::PlaneMergeParams params;
  params.min_seed_pixels = 50;
  params.min_pixels_for_angle = 50;
  const StripScene scene = strips({2, 2, 2.1, 2}, {0, 0, 0, 0.2});
  const geometry::SegmentMomentSet moments = strip_moments(scene);
  const segmentation::MergedPlanes own =
      segmentation::merge_segments(scene.labels, moments, params, {{}, &scene.points});
  const GivenMergeInputs in = given_merge_inputs(scene, moments, params);
  const segmentation::MergedPlanes given = segmentation::merge_segments(
      scene.labels, moments, params, {{}, &scene.points, &in.graph, in.fits, in.pixel_sums});
  EXPECT_EQ(given.segment_plane, own.segment_plane);
  ASSERT_EQ(given.planes.size(), own.planes.size());
  for (std::size_t p = 0; p < own.planes.size(); ++p) {
    EXPECT_EQ(given.planes[p].normal, own.planes[p].normal);
    EXPECT_EQ(given.planes[p].offset, own.planes[p].offset);
  }
  const std::vector<segmentation::SegmentPlane> three(in.fits.begin(), in.fits.begin() + 3);
  EXPECT_ERROR_MENTIONS(
      segmentation::merge_segments(scene.labels, moments, params, {{}, nullptr, nullptr, three}),
      "not one per segment");
}

// A caller that knows each pixel's segment without a label image (the cells mode) hands merging a
// lookup and an empty image: the same planes. The see-through test reads the lookup: strip 2,
// 10 cm behind the others, is seen through between strips 1 and 3, so they stay apart, unless
// the lookup gives its pixels to strip 0.
TEST(PlaneMerge, ASegmentLookupStandsInForTheLabelImage) {
  segmentation::PlaneMergeParams params;
  params.min_seed_pixels = 50;
  params.min_pixels_for_angle = 50;
  params.join_apart = true;
  const StripScene scene = strips({2, 2, 2.1, 2}, {0, 0, 0, 0});
  const geometry::SegmentMomentSet moments = strip_moments(scene);
  const GivenMergeInputs in = given_merge_inputs(scene, moments, params);
  const auto merge = [&](const segmentation::SegmentLabelImage& labels,
                         std::function<std::uint32_t(int, int)> segment_at) {
    return segmentation::merge_segments(
               labels, moments, params,
               {{}, &scene.points, &in.graph, in.fits, in.pixel_sums, std::move(segment_at)})
        .segment_plane;
  };
  EXPECT_EQ(merge(scene.labels, {}), (std::vector<std::uint32_t>{0, 0, 1, 2}));
  EXPECT_EQ(merge({}, [&](int x, int y) { return scene.labels(x, y); }),
            (std::vector<std::uint32_t>{0, 0, 1, 2}));
  EXPECT_EQ(merge({}, [](int, int) { return 0u; }), (std::vector<std::uint32_t>{0, 0, 1, 0}));
  EXPECT_ERROR_MENTIONS(merge({}, {}), "without a label image");
  // No segments: no pixel sums to give, and no planes.
  segmentation::SegmentGraph no_graph;
  no_graph.offsets = {0};
  const segmentation::MergedPlanes none = segmentation::merge_segments(
      {}, geometry::SegmentMomentSet{}, params,
      {{}, &scene.points, &no_graph, {}, {}, [](int, int) { return geometry::kNoLabel; }});
  EXPECT_TRUE(none.planes.empty());
}

TEST(PlaneMerge, AdjacencyGraphsKnownAnswers) {
  // 0 0 1
  // 2 . 1      (. = no label)
  // 2 3 3
  segmentation::SegmentLabelImage labels(3, 3);
  const std::uint32_t n = geometry::kNoLabel;
  const std::uint32_t values[9] = {0, 0, 1, 2, n, 1, 2, 3, 3};
  std::copy(values, values + 9, labels.data());
  const segmentation::SegmentGraph pixels = segmentation::pixel_adjacency_graph(labels, 4);
  EXPECT_EQ(pixels.offsets, (std::vector<std::uint32_t>{0, 2, 4, 6, 8}));
  EXPECT_EQ(pixels.neighbours, (std::vector<std::uint32_t>{1, 2, 0, 3, 0, 3, 1, 2}));
  // The paper's bounding rectangles: here they give the same pairs ...
  const segmentation::SegmentGraph boxes = segmentation::bounding_box_graph(labels, 4);
  EXPECT_EQ(boxes.offsets, pixels.offsets);
  EXPECT_EQ(boxes.neighbours, pixels.neighbours);
  // ... but an L-shaped segment's rectangle covers a segment it never touches:
  // 0 0 0
  // 0 . .
  // 0 . 1
  segmentation::SegmentLabelImage corner(3, 3, n);
  for (int i = 0; i < 3; ++i) corner(i, 0) = corner(0, i) = 0;
  corner(2, 2) = 1;
  EXPECT_TRUE(segmentation::pixel_adjacency_graph(corner, 2).neighbours.empty());
  EXPECT_EQ(segmentation::bounding_box_graph(corner, 2).neighbours,
            (std::vector<std::uint32_t>{1, 0}));
  EXPECT_ERROR_MENTIONS(segmentation::pixel_adjacency_graph(labels, 3), "label 3",
                        "segment count 3");
}

// --- the pipeline ---

struct SyntheticScore {
  int large_planes = 0;  // ground-truth planes over 1 % of the image (pixels with depth)
  int detected = 0;      // of those, correctly detected (SegComp, overlap >= 80 %, mutual)
  std::vector<double> normal_errors_deg;
  std::vector<double> extract_ms;
};

SyntheticScore score_synthetic_tour(
    int frame_count,
    segmentation::PlaneExtractionMode mode = segmentation::PlaneExtractionMode::regions) {
  static const synth::World world = synth::make_building(1);
  const PinholeIntrinsics camera{640, 480, 525.0, 525.0, 319.5, 239.5};
  const Trajectory tour = synth::robot_tour(world, 300);
  const compute::Context context = compute::Context::cpu();
  segmentation::PlaneExtractionParams params;
  params.mode = mode;
  segmentation::PlaneExtractor extractor(context, camera, params);
  geometry::DepthRange range;
  range.units_per_metre = synth::kTumDepthUnitsPerMetre;
  SyntheticScore score;
  for (int f = 0; f < frame_count; ++f) {
    const int index = 7 + f * 290 / frame_count;  // frames 7 .. 294
    const Eigen::Isometry3d& pose = tour[index].pose;
    const synth::SyntheticFrame frame =
        synth::render(world, camera, pose, synth::NoiseModel::kinect(), 1000 + index);
    const PointImage points = geometry::backproject(context, frame.depth, camera, range);
    const segmentation::PlaneSet set = extractor.extract(points, frame.color);
    score.extract_ms.push_back(set.timings.total());
    // What the sensor saw, with faces that form one continuous planar surface as one plane.
    static const std::vector<Label> surface = synth::continuous_surface_ids(world);
    LabelImage truth = frame.plane_id;
    for (std::size_t i = 0; i < truth.size(); ++i) {
      Label& l = truth.data()[i];
      l = frame.depth.data()[i] == 0 ? kUnlabeled : surface[l];
    }
    eval::PlaneNormals truth_normals, predicted_normals;
    for (const synth::Plane& plane : world.planes)
      truth_normals[plane.id] = pose.linear().transpose() * plane.normal;
    for (const segmentation::Plane& plane : set.planes) predicted_normals[plane.id] = plane.normal;
    const eval::SegCompResult result = eval::compare_plane_segmentations(
        truth, set.labels, {0.8}, truth_normals, predicted_normals);
    std::map<Label, std::int64_t> sizes;
    for (const Label l : truth.pixels()) {
      if (l != kUnlabeled) ++sizes[l];
    }
    for (const auto& [label, pixels] : sizes) {
      if (pixels * 100 <= static_cast<std::int64_t>(truth.size())) continue;
      ++score.large_planes;
      for (const auto& [truth_label, predicted_label] : result.correct_pairs) {
        if (truth_label != label) continue;
        ++score.detected;
        score.normal_errors_deg.push_back(
            angle_deg(truth_normals[label], predicted_normals[predicted_label]));
      }
    }
  }
  return score;
}

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  return values.empty() ? 0.0 : values[values.size() / 2];
}

void expect_detected(const SyntheticScore& score, double min_fraction) {
  const double fraction = double(score.detected) / score.large_planes;
  const double normal_error = median(score.normal_errors_deg);
  std::printf(
      "synthetic tour, 100 frames 640x480, Kinect noise: %d of %d planes > 1 %% detected "
      "(%.1f %%), median normal error %.3f deg, median extract %.1f ms\n",
      score.detected, score.large_planes, 100.0 * fraction, normal_error, median(score.extract_ms));
  ::testing::Test::RecordProperty("detected_fraction", std::to_string(fraction));
  ::testing::Test::RecordProperty("median_normal_error_deg", std::to_string(normal_error));
  EXPECT_GE(score.large_planes, 400);
  EXPECT_GE(fraction, min_fraction);
  EXPECT_LT(normal_error, 1.0);
}

TEST(PlaneExtraction, DetectsTheLargeGroundTruthPlanesOfSyntheticKinectFrames) {
  // Issue 5: >= 95 % of the ground-truth planes larger than 1 % of the image correctly detected
  // (SegComp, overlap >= 80 % both ways), median normal error < 1 degree; 100 frames spread over
  // the robot tour through every room.
  expect_detected(score_synthetic_tour(100), 0.95);
}

TEST(PlaneExtraction, CellsModeDetectsTheLargeGroundTruthPlanesOfSyntheticKinectFrames) {
  expect_detected(score_synthetic_tour(100, segmentation::PlaneExtractionMode::cells), 0.95);
}

// Frame `frame_index` of the robot tour through synthetic world 1 (Kinect noise), back-projected
// on the CPU: its points and colours.
struct SyntheticView {
  PointImage points;
  RgbImage color;
};

SyntheticView synthetic_view(const PinholeIntrinsics& camera, int frame_index) {
  static const synth::World world = synth::make_building(1);
  const Trajectory tour = synth::robot_tour(world, 300);
  synth::SyntheticFrame frame =
      synth::render(world, camera, tour[frame_index].pose, synth::NoiseModel::kinect(), 77);
  geometry::DepthRange range;
  range.units_per_metre = synth::kTumDepthUnitsPerMetre;
  return {geometry::backproject(compute::Context::cpu(), frame.depth, camera, range),
          std::move(frame.color)};
}

segmentation::PlaneSet extract_synthetic(const compute::Context& context,
                                         const PinholeIntrinsics& camera, int frame_index) {
  const SyntheticView view = synthetic_view(camera, frame_index);
  segmentation::PlaneExtractor extractor(context, camera);
  return extractor.extract(view.points, view.color);
}

void expect_same_planes(const segmentation::PlaneSet& a, const segmentation::PlaneSet& b,
                        double tolerance) {
  ASSERT_EQ(a.planes.size(), b.planes.size());
  EXPECT_TRUE(
      std::equal(a.labels.pixels().begin(), a.labels.pixels().end(), b.labels.pixels().begin()));
  for (std::size_t i = 0; i < a.planes.size(); ++i) {
    EXPECT_EQ(a.planes[i].inlier_count, b.planes[i].inlier_count);
    EXPECT_LE((a.planes[i].normal - b.planes[i].normal).norm(), tolerance);
    EXPECT_NEAR(a.planes[i].offset, b.planes[i].offset, tolerance);
  }
}

class PlaneExtractionBackendTest : public BackendTest {};

TEST_P(PlaneExtractionBackendTest, IsDeterministicAndAgreesWithTheCpuBackend) {
  const PinholeIntrinsics camera{320, 240, 262.5, 262.5, 159.5, 119.5};
  const segmentation::PlaneSet first = extract_synthetic(context(), camera, 40);
  ASSERT_GE(first.planes.size(), 2u);
  for (const segmentation::Plane& plane : first.planes) {
    EXPECT_EQ(plane.id, &plane - first.planes.data() + 1);
    EXPECT_NEAR(plane.normal.norm(), 1.0, 1e-9);
    EXPECT_LT(plane.normal.dot(plane.centroid), 0.0);
    EXPECT_TRUE((plane.extent_min.array() <= plane.extent_max.array()).all());
    if (&plane != first.planes.data()) {
      EXPECT_LE(plane.inlier_count, (&plane - 1)->inlier_count);
    }
  }
  // Run to run on one backend: identical. Against the CPU backend: the same labels (the growing
  // is exact on every backend), plane parameters within rounding (the CPU sums moments in double
  // as segments grow, devices reduce them in fixed point).
  expect_same_planes(first, extract_synthetic(context(), camera, 40), 0.0);
  expect_same_planes(first, extract_synthetic(compute::Context::cpu(), camera, 40), 1e-9);
}

// The cells mode's pass over the frame runs on the context (kernels/cell_blocks), the rest on the
// host: the same planes as on the CPU backend (the block sums are floats summed in the same
// order; a device may fuse multiply-adds, hence the tolerance).
TEST_P(PlaneExtractionBackendTest, CellsModeAgreesWithTheCpuBackend) {
  const PinholeIntrinsics camera{320, 240, 262.5, 262.5, 159.5, 119.5};
  segmentation::PlaneExtractionParams params;
  params.mode = segmentation::PlaneExtractionMode::cells;
  const compute::Context cpu_context = compute::Context::cpu();
  for (const int frame : {40, 130}) {
    const SyntheticView view = synthetic_view(camera, frame);
    segmentation::PlaneExtractor mine(context(), camera, params);
    segmentation::PlaneExtractor cpu(cpu_context, camera, params);
    const segmentation::PlaneSet set = mine.extract(view.points, view.color);
    EXPECT_GE(set.planes.size(), 2u) << frame;
    expect_same_planes(set, cpu.extract(view.points, view.color), 1e-6);
    expect_same_planes(set, mine.extract(view.points, view.color), 0.0);
    // Without colour (a depth camera alone).
    expect_same_planes(mine.extract(view.points, RgbImage()), cpu.extract(view.points, RgbImage()),
                       1e-6);
  }
}

KARTOGRAF_INSTANTIATE_BACKEND_TESTS(PlaneExtractionBackendTest);

// The CPU's two forms of the cells mode's loops over pixels, AVX2's eight lanes (where the
// processor has it) and four lanes: the same planes (the block sums differ by rounding only, the
// pixels' scores not at all).
TEST(PlaneExtraction, CellsModeWideAndFourLaneCodeAgree) {
  RecordProperty("wide_code", compute::detail::wide_lanes_enabled() ? "AVX2" : "not available");
  const PinholeIntrinsics camera{320, 240, 262.5, 262.5, 159.5, 119.5};
  const compute::Context context = compute::Context::cpu();
  // 16: the default (blocks of 8, the wide block pass); 40: rows of 40 and 20 pixels scored in
  // groups of eight (the block pass in four lanes); 64: the widest rows, 64 bits of a row's mask.
  for (const int cell_size : {16, 40, 64}) {
    segmentation::PlaneExtractionParams params;
    params.mode = segmentation::PlaneExtractionMode::cells;
    params.cells.cell_size = cell_size;
    segmentation::PlaneExtractor extractor(context, camera, params);
    for (const int frame : {40, 130}) {
      const SyntheticView view = synthetic_view(camera, frame);
      compute::detail::allow_wide_lanes(false);
      const segmentation::PlaneSet four = extractor.extract(view.points, view.color);
      compute::detail::allow_wide_lanes(true);
      EXPECT_GE(four.planes.size(), 2u) << cell_size << " px cells, frame " << frame;
      expect_same_planes(four, extractor.extract(view.points, view.color), 1e-6);
    }
  }
}

// The cells mode on the CPU: deterministic, planes by decreasing size with their records filled,
// labelled pixels within their plane's distance allowance (planar cells and blocks with no other
// plane next to them are taken whole, untested: noisy ones may lie beyond, at most 2.5 %), extents
// from the outline's pixels that match those of all the plane's pixels; empty and tiny frames give
// no plane.
TEST(PlaneExtraction, CellsModeGivesConsistentPlanes) {
  const compute::Context context = compute::Context::cpu();
  const PinholeIntrinsics camera{320, 240, 262.5, 262.5, 159.5, 119.5};
  const SyntheticView view = synthetic_view(camera, 40);
  const PointImage& points = view.points;
  segmentation::PlaneExtractionParams params;
  params.mode = segmentation::PlaneExtractionMode::cells;
  segmentation::PlaneExtractor extractor(context, camera, params);
  const segmentation::PlaneSet set = extractor.extract(points, view.color);
  ASSERT_GE(set.planes.size(), 2u);
  expect_same_planes(set, extractor.extract(points, view.color), 0.0);
  std::vector<std::uint64_t> counted(set.planes.size() + 1, 0);
  std::uint64_t labelled = 0, beyond = 0;
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<Eigen::Vector4d> extents(set.planes.size() + 1, {inf, inf, -inf, -inf});
  for (std::size_t i = 0; i < set.labels.size(); ++i) {
    const Label l = set.labels.data()[i];
    if (l == kUnlabeled) continue;
    ++counted[l], ++labelled;
    const segmentation::Plane& plane = set.planes[l - 1];
    const Eigen::Vector3d p = points.data()[i].head<3>().cast<double>();
    const Eigen::Vector2d uv((p - plane.centroid).dot(plane.major_axis),
                             (p - plane.centroid).dot(plane.minor_axis));
    extents[l].head<2>() = extents[l].head<2>().cwiseMin(uv);
    extents[l].tail<2>() = extents[l].tail<2>().cwiseMax(uv);
    beyond += std::fabs(plane.normal.dot(p) + plane.offset) >
              segmentation::distance_allowance(params.merge, p, plane.normal);
  }
  std::printf("cells mode: %zu planes, %llu pixels labelled, %llu beyond the allowance\n",
              set.planes.size(), static_cast<unsigned long long>(labelled),
              static_cast<unsigned long long>(beyond));
  EXPECT_GT(labelled, points.size() / 2);
  EXPECT_LE(beyond * 40, labelled);  // 2.0 % here (1 420 of 70 072 pixels)
  for (const segmentation::Plane& plane : set.planes) {
    EXPECT_EQ(counted[plane.id], plane.inlier_count);
    // Within the extent of all its pixels, and short of it by no more than depth noise (the
    // outline argument holds for points exactly on the plane).
    const Eigen::Vector4d all = extents[plane.id];
    const Eigen::Vector4d got(plane.extent_min.x(), plane.extent_min.y(), plane.extent_max.x(),
                              plane.extent_max.y());
    EXPECT_TRUE((got.head<2>().array() >= all.head<2>().array() - 1e-5).all());
    EXPECT_TRUE((got.tail<2>().array() <= all.tail<2>().array() + 1e-5).all());
    EXPECT_LT((got - all).cwiseAbs().maxCoeff(), 0.01) << "plane " << plane.id;
    EXPECT_GE(plane.inlier_count, params.min_plane_pixels);
    EXPECT_NEAR(plane.normal.norm(), 1.0, 1e-9);
    EXPECT_TRUE((plane.extent_min.array() <= plane.extent_max.array()).all());
    EXPECT_LE(plane.rms_error,
              segmentation::distance_allowance(params.merge, plane.centroid, plane.normal));
    if (plane.id > 1) {
      EXPECT_LE(plane.inlier_count, set.planes[plane.id - 2].inlier_count);
    }
  }
  EXPECT_TRUE(extractor.extract(PointImage(320, 240, invalid_point()), view.color).planes.empty());
  const PinholeIntrinsics tiny{6, 4, 5, 5, 3, 2};
  PointImage flat(6, 4);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 6; ++x) flat(x, y) = Point4f(0.1f * x, 0.1f * y, 1.0f, 1.0f);
  segmentation::PlaneExtractor small(context, tiny, params);
  EXPECT_TRUE(small.extract(flat, RgbImage(6, 4)).planes.empty());  // fewer than 300 pixels
}

// The share of a synthetic view's valid pixels that the extraction puts on planes, and its plane
// count (frame 40 of the robot tour, fx = 210 at any size).
std::pair<double, std::size_t> view_coverage(int width, int height,
                                             segmentation::PlaneExtractionMode mode) {
  const compute::Context context = compute::Context::cpu();
  const PinholeIntrinsics camera{
      width, height, 210.0, 210.0, (width - 1) / 2.0, (height - 1) / 2.0};
  const SyntheticView view = synthetic_view(camera, 40);
  const PointImage& points = view.points;
  segmentation::PlaneExtractionParams params;
  params.mode = mode;
  segmentation::PlaneExtractor extractor(context, camera, params);
  const segmentation::PlaneSet set = extractor.extract(points, view.color);
  std::uint64_t valid = 0, labelled = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    valid += is_valid(points.data()[i]);
    labelled += set.labels.data()[i] != kUnlabeled;
    if (!is_valid(points.data()[i])) {
      EXPECT_EQ(set.labels.data()[i], kUnlabeled);
    }
  }
  std::printf("%s %dx%d: %zu planes, %.1f %% of valid pixels\n",
              mode == segmentation::PlaneExtractionMode::cells ? "cells" : "regions", width, height,
              set.planes.size(), 100.0 * double(labelled) / double(valid));
  return {double(labelled) / double(valid), set.planes.size()};
}

// A frame whose size is no multiple of the cells' (the last row and column of cells cut by the
// border, some of their blocks empty) covers as much of the view as one at a multiple, and about
// what the regions mode covers. At this focal length (210 px) the synthetic sensor's disparity
// steps are 2.5 times those at 525 px: without CellPlaneParams::reference_focal's scaling the
// cells mode covered 40 % here against the regions mode's 95 %.
// A board 6 pixels wide in front of a wall: no cell or block of it is planar (its edges jump on
// every row), so only the leftover regions make it a plane.
TEST(PlaneExtraction, CellsModeMakesPlanesOfStripsNarrowerThanACell) {
  const compute::Context context = compute::Context::cpu();
  const PinholeIntrinsics camera{320, 240, 262.5, 262.5, 159.5, 119.5};
  PointImage points(camera.width, camera.height, invalid_point());
  const RgbImage colours(camera.width, camera.height, Rgb8{128, 128, 128});
  const auto on_board = [](int u) { return u >= 100 && u < 106; };
  for (int v = 0; v < camera.height; ++v) {
    for (int u = 0; u < camera.width; ++u) {
      const float z = on_board(u) ? 2.0f : 3.0f;
      points(u, v) = Point4f(float((u - camera.cx) / camera.fx) * z,
                             float((v - camera.cy) / camera.fy) * z, z, 1.0f);
    }
  }
  segmentation::PlaneExtractionParams params;
  params.mode = segmentation::PlaneExtractionMode::cells;
  for (const bool leftover : {true, false}) {
    params.cells.leftover_planes = leftover;
    const segmentation::PlaneSet set =
        segmentation::PlaneExtractor(context, camera, params).extract(points, colours);
    std::size_t board = 0, labelled = 0;
    Label board_label = kUnlabeled;
    for (int v = 0; v < camera.height; ++v) {
      for (int u = 100; u < 106; ++u) {
        ++board;
        labelled += set.labels(u, v) != kUnlabeled;
        board_label = set.labels(u, v) != kUnlabeled ? set.labels(u, v) : board_label;
      }
    }
    if (leftover) {
      EXPECT_GE(labelled * 10, board * 9);
      ASSERT_NE(board_label, kUnlabeled);
      const segmentation::Plane& plane = set.planes[board_label - 1];
      EXPECT_NEAR(std::fabs(plane.normal.z()), 1.0, 1e-3);
      EXPECT_NEAR(std::fabs(plane.offset), 2.0, 1e-3);
    } else {
      EXPECT_EQ(labelled, 0u);
    }
  }
}

// A depth camera without colour (cells mode): the view's surfaces are found on depth alone, with
// the normals the coloured run finds where both label a pixel. Colour only tells coplanar
// surfaces apart (a door flush with its wall), so depth alone labels about as much of the view.
// The extractor keeps no trace of the colourless frame: the next coloured one comes out as a
// fresh extractor's.
TEST(PlaneExtraction, CellsModeWorksOnDepthAlone) {
  const compute::Context context = compute::Context::cpu();
  const PinholeIntrinsics camera{320, 240, 262.5, 262.5, 159.5, 119.5};
  const SyntheticView view = synthetic_view(camera, 120);
  segmentation::PlaneExtractionParams params;
  params.mode = segmentation::PlaneExtractionMode::cells;
  segmentation::PlaneExtractor extractor(context, camera, params);
  const segmentation::PlaneSet coloured = extractor.extract(view.points, view.color);
  const segmentation::PlaneSet depth_only = extractor.extract(view.points, RgbImage());
  std::size_t valid = 0, in_coloured = 0, in_depth_only = 0, in_both = 0, agreeing = 0;
  for (std::size_t i = 0; i < view.points.size(); ++i) {
    if (!is_valid(view.points.data()[i])) continue;
    ++valid;
    const Label a = coloured.labels.data()[i], b = depth_only.labels.data()[i];
    in_coloured += a != kUnlabeled;
    in_depth_only += b != kUnlabeled;
    if (a == kUnlabeled || b == kUnlabeled) continue;
    ++in_both;
    agreeing += angle_deg(coloured.planes[a - 1].normal, depth_only.planes[b - 1].normal) < 2.0;
  }
  std::printf(
      "depth alone: %zu planes, %.1f %% of valid pixels (with colour %zu, %.1f %%); "
      "normals within 2 deg on %.1f %% of the pixels both label\n",
      depth_only.planes.size(), 100.0 * double(in_depth_only) / double(valid),
      coloured.planes.size(), 100.0 * double(in_coloured) / double(valid),
      100.0 * double(agreeing) / double(in_both));
  EXPECT_GE(depth_only.planes.size(), 2u);
  EXPECT_GE(double(in_depth_only), 0.95 * double(in_coloured));
  EXPECT_GE(double(agreeing), 0.98 * double(in_both));
  segmentation::PlaneExtractor fresh(context, camera, params);
  expect_same_planes(extractor.extract(view.points, view.color),
                     fresh.extract(view.points, view.color), 0.0);
}

TEST(PlaneExtraction, CellsModeTakesFramesOfAnySize) {
  using segmentation::PlaneExtractionMode;
  const auto [odd, odd_planes] = view_coverage(250, 187, PlaneExtractionMode::cells);
  const auto [even, even_planes] = view_coverage(256, 192, PlaneExtractionMode::cells);
  const double regions = view_coverage(250, 187, PlaneExtractionMode::regions).first;
  EXPECT_GE(odd_planes, 2u);
  EXPECT_GE(even_planes, 2u);
  EXPECT_NEAR(odd, even, 0.05);
  EXPECT_GE(odd, 0.8 * regions);
}

TEST(PlaneExtraction, RejectsBadInput) {
  const compute::Context context = compute::Context::cpu();
  const PinholeIntrinsics camera{8, 6, 10, 10, 4, 3};
  segmentation::PlaneExtractor extractor(context, camera);
  EXPECT_ERROR_MENTIONS(extractor.extract(PointImage(8, 6), RgbImage(7, 6)), "colour image is 7x6",
                        "8x6");
  EXPECT_ERROR_MENTIONS(extractor.extract(PointImage(8, 5), RgbImage(8, 6)), "point image is 8x5",
                        "8x6");
  EXPECT_ERROR_MENTIONS(extractor.extract(PointImage(), RgbImage(8, 6)), "empty input");
  // No colour: the regions mode grows colour regions; the cells mode takes depth alone.
  EXPECT_ERROR_MENTIONS(extractor.extract(PointImage(8, 6), RgbImage()), "no colour image",
                        "cells mode");
  segmentation::PlaneExtractionParams cells_mode;
  cells_mode.mode = segmentation::PlaneExtractionMode::cells;
  segmentation::PlaneExtractor cells_extractor(context, camera, cells_mode);
  EXPECT_ERROR_MENTIONS(cells_extractor.extract(PointImage(8, 5), RgbImage()), "point image is 8x5",
                        "8x6");
  EXPECT_ERROR_MENTIONS(cells_extractor.extract(PointImage(8, 6), RgbImage(7, 6)),
                        "colour image is 7x6", "8x6");
  segmentation::PlaneExtractionParams bad;
  bad.merge.max_normal_angle_deg = -1;
  EXPECT_ERROR_MENTIONS(segmentation::PlaneExtractor(context, camera, bad), "max_normal_angle_deg");
  segmentation::PlaneExtractionParams bad_cells;
  bad_cells.cells.cell_size = 15;  // not 2 x 2 blocks
  EXPECT_ERROR_MENTIONS(segmentation::PlaneExtractor(context, camera, bad_cells), "cell_size",
                        "even", "15");
  bad_cells.cells.cell_size = 66;  // a block's row of validity bits would not fit in 32
  EXPECT_ERROR_MENTIONS(segmentation::PlaneExtractor(context, camera, bad_cells), "cell_size",
                        "4..64", "66");
  bad_cells = {};
  bad_cells.cells.reach_passes = 0;
  EXPECT_ERROR_MENTIONS(segmentation::PlaneExtractor(context, camera, bad_cells), "reach_passes");
  // A point at infinity is named, in both modes (not silently summed into inf / NaN planes).
  PointImage infinite(8, 6, Point4f(0.1f, 0.2f, 1.0f, 1.0f));
  infinite(3, 2) = Point4f(std::numeric_limits<float>::infinity(), 0.0f, 1.0f, 1.0f);
  for (const auto mode :
       {segmentation::PlaneExtractionMode::regions, segmentation::PlaneExtractionMode::cells}) {
    segmentation::PlaneExtractionParams with_mode;
    with_mode.mode = mode;
    segmentation::PlaneExtractor modal(context, camera, with_mode);
    EXPECT_ERROR_MENTIONS(modal.extract(infinite, RgbImage(8, 6)), "infinite coordinate");
  }
  bad_cells = {};
  bad_cells.cells.min_valid_fraction = 1.5;
  EXPECT_ERROR_MENTIONS(segmentation::PlaneExtractor(context, camera, bad_cells),
                        "min_valid_fraction");
  EXPECT_ERROR_MENTIONS(segmentation::PlaneExtractor(context, PinholeIntrinsics{}, {}),
                        "plane extraction", "image size");
  // No valid point: no plane, all labels 0.
  const segmentation::PlaneSet none =
      extractor.extract(PointImage(8, 6, invalid_point()), RgbImage(8, 6));
  EXPECT_TRUE(none.planes.empty());
  EXPECT_EQ(std::count(none.labels.pixels().begin(), none.labels.pixels().end(), kUnlabeled), 48);
}

}  // namespace
}  // namespace kartograf
