#include "kartograf/outputs/room_run.hpp"

#include <nlohmann/json.hpp>

namespace kartograf::io {

std::string room_run_json(const RoomRunRecord& run) {
  const nlohmann::ordered_json json = {{"method", run.method},
                                       {"resolution", run.resolution},
                                       {"free_threshold", run.free_threshold}};
  return json.dump();
}

}  // namespace kartograf::io
