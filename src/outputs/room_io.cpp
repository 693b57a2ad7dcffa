#include "kartograf/outputs/room_io.hpp"

#include <algorithm>
#include <map>
#include <string>

#include <nlohmann/json.hpp>

#include "formats/atomic_file.hpp"
#include "outputs/json_array.hpp"
#include "kartograf/core/error.hpp"
#include "kartograf/formats/occupancy_map_io.hpp"

namespace kartograf::io {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;
using detail::json_array;

namespace {

Json room_json(const rooms::RoomRecord& room) {
  Json doorways = Json::array();
  for (const rooms::Doorway& door : room.doorways) {
    doorways.push_back({{"to", door.other},
                        {"from", json_array(door.from)},
                        {"to_point", json_array(door.to)},
                        {"width_m", door.width_m},
                        {"cells", door.cells}});
  }
  return {
      {"id", room.id},
      {"area_m2", room.area_m2},
      {"cells", room.cells},
      {"centroid", json_array(room.centroid)},
      {"bbox_min", json_array(room.min_corner)},
      {"bbox_max", json_array(room.max_corner)},
      {"bbox_cells", {room.min_cell.x(), room.min_cell.y(), room.max_cell.x(), room.max_cell.y()}},
      {"neighbours", room.neighbours},
      {"doorways", std::move(doorways)}};
}

}  // namespace

void write_rooms_json(const fs::path& path, const rooms::RoomSegmentation& rooms,
                      const OccupancyGrid& map, const std::string& source,
                      const std::string& run_json) {
  Json json;
  json["format"] = "kartograf-rooms";
  json["version"] = 1;
  json["source"] = source;
  json["method"] = rooms.method;
  json["seconds"] = rooms.seconds;
  json["resolution"] = map.resolution;
  json["origin"] = json_array(map.origin);
  json["width"] = map.width();
  json["height"] = map.height();
  Json list = Json::array();
  for (const rooms::RoomRecord& room : rooms.records) list.push_back(room_json(room));
  json["rooms"] = std::move(list);
  if (!run_json.empty()) json["run"] = Json::parse(run_json);
  const std::string text = json.dump(1) + "\n";
  detail::write_file_atomically(path, text.data(), text.size());
}

RgbImage room_overlay(const OccupancyGrid& map, const LabelImage& rooms) {
  require(rooms.width() == map.width() && rooms.height() == map.height(),
          "room_overlay: the room image differs from the map in size");
  RgbImage picture = colorize_labels(rooms);
  const int width = map.width(), height = map.height();
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const Label l = rooms(x, y);
      if (l == 0 || map.cells(x, y) != CellState::free) {
        const CellState c = map.cells(x, y);
        picture(x, y) = c == CellState::free       ? Rgb8{255, 255, 255}
                        : c == CellState::occupied ? Rgb8{0, 0, 0}
                                                   : Rgb8{160, 160, 160};
        continue;
      }
      // A room cell with a 4-neighbour in another room lies on a border: drawn dark.
      const bool border = (x + 1 < width && rooms(x + 1, y) != 0 && rooms(x + 1, y) != l) ||
                          (y + 1 < height && rooms(x, y + 1) != 0 && rooms(x, y + 1) != l);
      if (border) picture(x, y) = Rgb8{40, 40, 40};
    }
  }
  return picture;
}

std::vector<RoomMapCase> find_room_maps(const fs::path& folder) {
  const std::string name = "room map folder " + detail::quoted(folder);
  require(fs::is_directory(folder), name + ": not a folder");
  const std::string suffix = "_gt_segmentation.png";
  std::vector<RoomMapCase> cases;
  for (const fs::directory_entry& entry : fs::directory_iterator(folder)) {
    const std::string file = entry.path().filename().string();
    if (file.size() <= suffix.size() ||
        file.compare(file.size() - suffix.size(), suffix.size(), suffix) != 0)
      continue;
    const std::string base = file.substr(0, file.size() - suffix.size());
    for (const std::string& variant : room_map_variants()) {
      const fs::path map =
          folder / (variant == "plain" ? base + ".png" : base + "_" + variant + ".png");
      if (fs::exists(map)) cases.push_back({base, variant, map, entry.path()});
    }
  }
  require(!cases.empty(), name + ": holds no NAME_gt_segmentation.png beside a NAME.png map");
  const auto rank = [](const std::string& variant) {
    const auto& v = room_map_variants();
    return std::find(v.begin(), v.end(), variant) - v.begin();
  };
  std::sort(cases.begin(), cases.end(), [&](const RoomMapCase& a, const RoomMapCase& b) {
    return a.name != b.name ? a.name < b.name : rank(a.variant) < rank(b.variant);
  });
  return cases;
}

}  // namespace kartograf::io
