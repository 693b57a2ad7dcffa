// Room segmentations on disk (io/room_io.hpp): rooms.json, the picture, benchmark folders.
#include <nlohmann/json.hpp>

#include "kartograf/compute/context.hpp"
#include "kartograf/outputs/room_io.hpp"
#include "kartograf/rooms/room_methods.hpp"
#include "room_test_maps.hpp"
#include "test_support.hpp"

namespace kartograf {
namespace {

using RoomIo = testing::TempDirTest;

TEST_F(RoomIo, RoomsJsonHoldsEveryRoomWithItsGeometry) {
  OccupancyGrid map = testing::rooms_in_a_row(2);
  map.origin = Eigen::Vector3d(10, 20, 0);
  const auto rooms =
      rooms::segment_rooms(compute::Context::cpu(), map, rooms::RoomMethod::distance);
  io::write_rooms_json(dir() / "rooms.json", rooms, map, "two rooms", R"({"method": "distance"})");
  const auto json = nlohmann::json::parse(testing::read_text(dir() / "rooms.json"));
  EXPECT_EQ(json["format"], "kartograf-rooms");
  EXPECT_EQ(json["method"], "distance");
  EXPECT_EQ(json["run"]["method"], "distance");
  ASSERT_EQ(json["rooms"].size(), 2u);
  const auto& first = json["rooms"][0];
  EXPECT_EQ(first["id"], 1);
  EXPECT_NEAR(first["area_m2"].get<double>(), 36.0, 0.1);
  // Room 1 spans cells 2..121 of 246 x 124: x from 10.1 to 16.1 m, y from 20.1 to 26.1 m.
  EXPECT_NEAR(first["bbox_min"][0].get<double>(), 10.125, 1e-9);
  EXPECT_NEAR(first["bbox_min"][1].get<double>(), 20.125, 1e-9);
  EXPECT_NEAR(first["centroid"][0].get<double>(), 13.1, 0.06);
  EXPECT_EQ(first["neighbours"], nlohmann::json::array({2}));
  ASSERT_EQ(first["doorways"].size(), 1u);
  EXPECT_EQ(first["doorways"][0]["to"], 2);
  EXPECT_FALSE(std::filesystem::exists(dir() / "rooms.json.tmp"));
}

TEST_F(RoomIo, OverlayColoursRoomsAndDrawsWallsBlack) {
  const OccupancyGrid map = testing::rooms_in_a_row(2);
  const auto rooms =
      rooms::segment_rooms(compute::Context::cpu(), map, rooms::RoomMethod::morphological);
  const RgbImage picture = io::room_overlay(map, rooms.rooms);
  EXPECT_EQ(picture(0, 0), (Rgb8{0, 0, 0}));
  EXPECT_NE(picture(10, 10), picture(200, 10));
  EXPECT_NE(picture(10, 10), (Rgb8{255, 255, 255}));
}

TEST_F(RoomIo, FindsBenchmarkMapsWithTheirGroundTruthAndVariants) {
  for (const char* file : {"b_gt_segmentation.png", "b.png", "b_furnitures.png", "a.png",
                           "a_gt_segmentation.png", "a_furnitures_trashbins.png", "c.png"}) {
    testing::write_file(dir() / file, "x");
  }
  const auto cases = io::find_room_maps(dir());
  ASSERT_EQ(cases.size(), 4u);
  EXPECT_EQ(cases[0].name, "a");
  EXPECT_EQ(cases[0].variant, "plain");
  EXPECT_EQ(cases[1].variant, "furnitures_trashbins");
  EXPECT_EQ(cases[2].map, dir() / "b.png");
  EXPECT_EQ(cases[3].variant, "furnitures");
  EXPECT_EQ(cases[3].ground_truth, dir() / "b_gt_segmentation.png");
  EXPECT_ERROR_MENTIONS(io::find_room_maps(dir() / "missing"), "missing", "not a folder");
  std::filesystem::create_directory(dir() / "empty");
  EXPECT_ERROR_MENTIONS(io::find_room_maps(dir() / "empty"), "empty", "gt_segmentation");
}

}  // namespace
}  // namespace kartograf
