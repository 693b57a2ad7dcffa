// Plane extraction on the PCL mOSD table-top frames (organized PCD files read through
// kartograf_formats, so in kartograf_pipeline_tests only, not in the device tests): the table is
// found as one plane.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include "kartograf/formats/pcd.hpp"
#include "kartograf/segmentation/plane_extraction.hpp"
#include "test_support.hpp"

namespace kartograf {
namespace {

TEST(PlaneExtraction, RecoversTheMosdTablePlane) {
  const compute::Context context = compute::Context::cpu();
  segmentation::PlaneExtractor extractor(context, PinholeIntrinsics::kinect_7scenes());
  // test43 and test56 are stored unorganized (valid points only, WIDTH = point count): region
  // growing needs the pixel grid, so they are not used.
  for (const char* name : {"test43", "test56"}) {
    EXPECT_FALSE(
        io::read_pcd(testing::data_dir() / "pcl_mosd" / (std::string(name) + ".pcd")).organized())
        << name;
  }
  int files = 0;
  for (const char* name : {"test0", "test16", "test24", "test31", "test55", "test57"}) {
    const io::PcdCloud cloud =
        io::read_pcd(testing::data_dir() / "pcl_mosd" / (std::string(name) + ".pcd"));
    ASSERT_EQ(cloud.width, 640);
    ASSERT_EQ(cloud.height, 480);
    ASSERT_EQ(cloud.labels.size(), cloud.size());
    ASSERT_EQ(cloud.colors.size(), cloud.size());
    const PointImage points = cloud.to_point_image();
    RgbImage rgb(640, 480);
    std::copy(cloud.colors.begin(), cloud.colors.end(), rgb.data());
    const segmentation::PlaneSet set = extractor.extract(points, rgb);
    // The table: labels 1-9 at valid points; the best plane by intersection over union.
    std::vector<std::int64_t> overlap(set.planes.size() + 1, 0), size(set.planes.size() + 1, 0);
    std::int64_t table = 0;
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      const bool on_table =
          cloud.labels[i] >= 1 && cloud.labels[i] <= 9 && is_valid(points.data()[i]);
      table += on_table;
      const Label l = set.labels.data()[i];
      ++size[l];
      overlap[l] += on_table;
    }
    double best = 0;
    for (std::size_t l = 1; l < overlap.size(); ++l) {
      best = std::max(best, double(overlap[l]) / double(table + size[l] - overlap[l]));
    }
    std::printf("mOSD %s: table %lld points, best plane IoU %.4f (%zu planes)\n", name,
                static_cast<long long>(table), best, set.planes.size());
    RecordProperty(std::string("iou_") + name, std::to_string(best));
    EXPECT_GE(best, 0.95) << name;
    ++files;
  }
  EXPECT_EQ(files, 6);
}

}  // namespace
}  // namespace kartograf
