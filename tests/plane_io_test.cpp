// Planes on disk (io/plane_io.hpp): planes.json round trips and its errors, the overlay picture
// and the plane points; one plane per segment (fit_segment_planes) for the clustering baselines.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include <Eigen/Geometry>

#include "kartograf/outputs/plane_io.hpp"
#include "kartograf/segmentation/plane_extraction.hpp"
#include "test_support_core.hpp"

namespace kartograf {
namespace {

using testing::TempDirTest;

segmentation::PlaneSet two_planes() {
  segmentation::PlaneSet set;
  set.labels = LabelImage(4, 3, kUnlabeled);
  set.labels(0, 0) = set.labels(1, 0) = 1;
  set.labels(3, 2) = 2;
  set.segment_count = 9;
  set.merged_count = 3;
  for (Label id : {Label{1}, Label{2}}) {
    segmentation::Plane plane;
    plane.id = id;
    plane.normal = Eigen::Vector3d(0.1 * id, -0.2, -1.0).normalized();
    plane.offset = 1.25 * id;
    plane.centroid = Eigen::Vector3d(0.3, -0.1 * id, 2.0);
    plane.major_axis = plane.normal.unitOrthogonal();
    plane.minor_axis = plane.normal.cross(plane.major_axis);
    plane.extent_min = Eigen::Vector2d(-0.5, -0.25 * id);
    plane.extent_max = Eigen::Vector2d(0.75, 0.125);
    plane.inlier_count = 1000 + id;
    plane.rms_error = 0.001 * id;
    set.planes.push_back(plane);
  }
  return set;
}

class PlanesIo : public TempDirTest {};

TEST_F(PlanesIo, JsonRoundTripKeepsEveryPlaneField) {
  const segmentation::PlaneSet set = two_planes();
  const auto path = dir() / "planes.json";
  io::write_planes_json(path, set,
                        {"frame 7", {4, 3, 500, 501, 1.5, 1.25}, R"({"backend": "cpu"})"});
  const std::string text = testing::read_text(path);
  EXPECT_NE(text.find("\"source\": \"frame 7\""), std::string::npos);
  EXPECT_NE(text.find("\"backend\": \"cpu\""), std::string::npos);
  EXPECT_NE(text.find("\"fy\": 501.0"), std::string::npos);
  const std::vector<segmentation::Plane> planes = io::read_planes_json(path);
  ASSERT_EQ(planes.size(), 2u);
  for (std::size_t i = 0; i < planes.size(); ++i) {
    const segmentation::Plane& a = set.planes[i];
    const segmentation::Plane& b = planes[i];
    EXPECT_EQ(a.id, b.id);
    EXPECT_EQ(a.normal, b.normal);  // doubles are written in a form that reads back exactly
    EXPECT_EQ(a.offset, b.offset);
    EXPECT_EQ(a.centroid, b.centroid);
    EXPECT_EQ(a.major_axis, b.major_axis);
    EXPECT_EQ(a.minor_axis, b.minor_axis);
    EXPECT_EQ(a.extent_min, b.extent_min);
    EXPECT_EQ(a.extent_max, b.extent_max);
    EXPECT_EQ(a.inlier_count, b.inlier_count);
    EXPECT_EQ(a.rms_error, b.rms_error);
  }
}

TEST_F(PlanesIo, ReadingRejectsWhatIsNotAPlanesFile) {
  const auto path = dir() / "bad.json";
  EXPECT_ERROR_MENTIONS(io::read_planes_json(dir() / "missing.json"), "missing.json",
                        "no such file");
  testing::write_file(path, "{\"planes\": [");
  EXPECT_ERROR_MENTIONS(io::read_planes_json(path), "bad.json", "not valid JSON");
  testing::write_file(path, "{\"format\": \"other\", \"planes\": []}");
  EXPECT_ERROR_MENTIONS(io::read_planes_json(path), "not a kartograf planes file");
  const std::string head = "{\"format\": \"kartograf-planes\", \"planes\": [";
  testing::write_file(path, head + "{\"id\": 1}]}");
  EXPECT_ERROR_MENTIONS(io::read_planes_json(path), "plane 0", "\"normal\"");
  testing::write_file(path, head + "{\"id\": 0}]}");
  EXPECT_ERROR_MENTIONS(io::read_planes_json(path), "\"id\" must be an integer in 1..65535");
  io::write_planes_json(path, two_planes(), {});
  std::string text = testing::read_text(path);
  text.replace(text.find("\"normal\": ["), 11, "\"normal\": [7, ");
  testing::write_file(path, text);
  EXPECT_ERROR_MENTIONS(io::read_planes_json(path), "plane 0", "\"normal\"");
}

TEST(PlaneOverlay, DimsUnlabelledPixelsAndColoursPlanes) {
  const segmentation::PlaneSet set = two_planes();
  const RgbImage rgb(4, 3, Rgb8{200, 200, 200});
  const RgbImage overlay = io::plane_overlay(rgb, set.labels);
  ASSERT_EQ(overlay.width(), 4);
  const Rgb8 unlabelled = overlay(2, 1);
  EXPECT_EQ(unlabelled[0], unlabelled[1]);
  EXPECT_LT(unlabelled[0], 200);  // dimmed
  EXPECT_NE(overlay(1, 0), unlabelled);
  EXPECT_NE(overlay(3, 2), overlay(1, 0));  // two planes, two colours
  EXPECT_ERROR_MENTIONS(io::plane_overlay(RgbImage(3, 3), set.labels), "differ in size");
}

TEST(PlanePoints, KeepsTheValidPixelsWithAPlane) {
  const segmentation::PlaneSet set = two_planes();
  PointImage points(4, 3, Point4f(0, 0, 1, 1));
  points(1, 0) = invalid_point();
  const PointCloud cloud = io::plane_points(points, set.labels);
  EXPECT_EQ(cloud.size(), 2u);  // (0, 0) and (3, 2)
  EXPECT_EQ(cloud.colors.size(), 2u);
}

TEST(SegmentPlanes, FitsOnePlanePerSegmentAndSkipsDegenerateOnes) {
  // Segment 0: a tilted plane patch; 1: a single row (collinear); 2: two pixels.
  PointImage points(12, 6);
  segmentation::SegmentLabelImage segments(12, 6, 0);
  for (int y = 0; y < 6; ++y) {
    for (int x = 0; x < 12; ++x) {
      points(x, y) = Point4f(0.01f * x, 0.01f * y, 2.0f + 0.005f * x, 1.0f);
    }
  }
  for (int x = 0; x < 12; ++x) segments(x, 5) = 1;
  segments(0, 0) = segments(1, 0) = 2;
  const segmentation::PlaneSet set = segmentation::fit_segment_planes(points, segments, 3);
  ASSERT_EQ(set.planes.size(), 1u);
  const Eigen::Vector3d truth = Eigen::Vector3d(-0.5, 0.0, 1.0).normalized();
  EXPECT_NEAR(std::fabs(set.planes[0].normal.dot(truth)), 1.0, 1e-9);
  EXPECT_LT(set.planes[0].normal.dot(set.planes[0].centroid), 0.0);
  EXPECT_EQ(set.labels(5, 2), 1);
  EXPECT_EQ(set.labels(5, 5), kUnlabeled);
  EXPECT_EQ(set.labels(0, 0), kUnlabeled);
  EXPECT_ERROR_MENTIONS(segmentation::fit_segment_planes(points, segments, 2), "label");
  EXPECT_ERROR_MENTIONS(segmentation::fit_segment_planes(PointImage(3, 3), segments, 3),
                        "segment planes");
}

}  // namespace
}  // namespace kartograf
