#pragma once
// What `kartograf rooms` records in rooms.json's "run" (write_rooms_json's run_json).
#include <string>

namespace kartograf::io {

struct RoomRunRecord {
  std::string method;      // the room segmentation method's name
  double resolution = 0;   // the map's metres per cell
  int free_threshold = 0;  // the grey level from which a pixel is free
};
// A JSON object on one line.
std::string room_run_json(const RoomRunRecord& run);

}  // namespace kartograf::io
