// mapping::PlaneMap: planes of several views pooled in the map frame.
#include <gtest/gtest.h>

#include <cmath>

#include "kartograf/core/error.hpp"
#include "kartograf/mapping/plane_map.hpp"

namespace kartograf {
namespace {

// A view of a horizontal floor (z = 0) below a camera at `position`, looking straight down: every
// pixel on the floor, x in [x0, x0 + 2) and y in [y0, y0 + 2), one plane with id 1.
struct FloorView {
  segmentation::PlaneSet planes;
  PointImage points;
  SemanticImage labels;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
};

FloorView floor_view(double x0, double y0, double height, SemanticClass label) {
  FloorView v;
  const int n = 40;
  v.points = PointImage(n, n);
  v.planes.labels = LabelImage(n, n, 1);
  v.labels = SemanticImage(n, n, label);
  // Sensor frame = world frame shifted: points given in world coordinates minus the pose.
  v.pose.translation() = Eigen::Vector3d(x0, y0, 1.0);
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x)
      v.points(x, y) = Point4f(float(2.0 * x / n), float(2.0 * y / n), float(height - 1.0), 1.0f);
  segmentation::Plane plane;
  plane.id = 1;
  plane.normal = Eigen::Vector3d::UnitZ();
  v.planes.planes.push_back(plane);
  return v;
}

TEST(PlaneMap, OverlappingViewsOfOnePlaneBecomeOneMapPlane) {
  mapping::PlaneMapParams params;
  params.min_points = 100;
  mapping::PlaneMap map(params);
  for (const double x0 : {0.0, 1.5, 3.0}) {
    const FloorView v = floor_view(x0, 0.0, 0.0, SemanticClass::floor);
    map.add_view(v.planes, v.points, v.labels, v.pose);
  }
  // A parallel plane 0.5 m up (a table top) stays apart, and keeps its own class.
  const FloorView table = floor_view(0.0, 0.0, 0.5, SemanticClass::furniture);
  map.add_view(table.planes, table.points, table.labels, table.pose);

  const std::vector<mapping::MapPlane> planes = map.planes();
  ASSERT_EQ(planes.size(), 2u);
  const mapping::MapPlane& floor = planes[0];
  EXPECT_EQ(floor.label, SemanticClass::floor);
  EXPECT_EQ(floor.views, 3);
  EXPECT_EQ(floor.point_count, 3u * 1600u);
  EXPECT_NEAR(floor.normal.z(), 1.0, 1e-9);
  EXPECT_NEAR(floor.offset, 0.0, 1e-9);
  EXPECT_LT(floor.rms_error, 1e-6);
  // Extent of the kept points (every 4th pixel: x, y in 0..1.8 per view): 3 + 1.8 along the major
  // axis, 1.8 along the minor one.
  EXPECT_NEAR(floor.extent_max.x() - floor.extent_min.x(), 4.8, 1e-5);
  EXPECT_NEAR(floor.extent_max.y() - floor.extent_min.y(), 1.8, 1e-5);
  EXPECT_EQ(planes[1].label, SemanticClass::furniture);
  EXPECT_NEAR(planes[1].offset, -0.5, 1e-9);

  // Moved into another frame: 1 m up.
  const std::vector<mapping::MapPlane> moved =
      map.planes(Eigen::Isometry3d(Eigen::Translation3d(0, 0, 1)));
  EXPECT_NEAR(moved[0].offset, -1.0, 1e-9);
}

TEST(PlaneMap, DistantPiecesOfOnePlaneStayApartAndSmallOnesAreDropped) {
  mapping::PlaneMapParams params;
  params.min_points = 2000;
  mapping::PlaneMap map(params);
  for (const double x0 : {0.0, 10.0}) {
    const FloorView v = floor_view(x0, 0.0, 0.0, SemanticClass::floor);
    map.add_view(v.planes, v.points, v.labels, v.pose);
  }
  EXPECT_TRUE(map.planes().empty());  // two planes of 1600 points, below min_points
  params.min_points = 100;
  mapping::PlaneMap kept(params);
  for (const double x0 : {0.0, 10.0}) {
    const FloorView v = floor_view(x0, 0.0, 0.0, SemanticClass::floor);
    kept.add_view(v.planes, v.points, v.labels, v.pose);
  }
  EXPECT_EQ(kept.planes().size(), 2u);
}

TEST(PlaneMap, BadInputIsAnError) {
  mapping::PlaneMapParams params;
  params.point_stride = 0;
  EXPECT_THROW(mapping::PlaneMap{params}, Error);
  mapping::PlaneMap map;
  FloorView v = floor_view(0, 0, 0, SemanticClass::floor);
  v.labels = SemanticImage(3, 3, SemanticClass::floor);
  EXPECT_THROW(map.add_view(v.planes, v.points, v.labels, v.pose), Error);
}

}  // namespace
}  // namespace kartograf
