// Trains the room/hallway classifier of the feature-based room segmentation
// (rooms/feature_segmentation.hpp) on ipa_room_segmentation's training drawings and writes it:
//
//   train_room_classifier <training_maps folder> <model file (.yml.gz, .xml, ...)>
//
// The folder's *_room_training*.png drawings mark rooms grey, its *_hallway_training*.png ones
// hallways grey; white is the other class, black no free space (see room_training_map). The
// shipped model, models/rooms/room_hallway_boost.yml.gz, was made from
// ../shared/data/ipa_room_maps/training_maps with the default parameters.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <string>
#include <vector>

#include "kartograf/compute/context.hpp"
#include "kartograf/core/error.hpp"
#include "kartograf/formats/occupancy_map_io.hpp"
#include "kartograf/rooms/feature_segmentation.hpp"

namespace fs = std::filesystem;
using namespace kartograf;

namespace {

std::vector<rooms::RoomTrainingMap> read_training_maps(const fs::path& folder) {
  require(fs::is_directory(folder), "training maps folder " + folder.string() + " does not exist");
  std::vector<fs::path> drawings;
  for (const fs::directory_entry& entry : fs::directory_iterator(folder)) {
    const std::string name = entry.path().filename().string();
    if (entry.is_regular_file() && entry.path().extension() == ".png" &&
        (name.find("_room_training") != std::string::npos ||
         name.find("_hallway_training") != std::string::npos))
      drawings.push_back(entry.path());
  }
  std::sort(drawings.begin(), drawings.end());
  require(!drawings.empty(), "training maps folder " + folder.string() +
                                 " has no *_room_training*.png or *_hallway_training*.png");
  std::vector<rooms::RoomTrainingMap> maps;
  for (const fs::path& path : drawings) {
    const bool marks_rooms = path.filename().string().find("_room_training") != std::string::npos;
    maps.push_back(rooms::room_training_map(
        path.filename().string(), io::read_png_map(path, 0.05, 1),
        io::read_png_map(path, 0.05, 251),
        marks_rooms ? rooms::PlaceClass::hallway : rooms::PlaceClass::room));
  }
  return maps;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: %s <training_maps folder> <model file (.yml.gz)>\n", argv[0]);
    return 2;
  }
  try {
    const auto start = std::chrono::steady_clock::now();
    const std::vector<rooms::RoomTrainingMap> maps = read_training_maps(argv[1]);
    const rooms::RoomClassifier classifier =
        rooms::train_room_classifier(compute::Context::cpu(), maps);
    const fs::path output = argv[2];
    if (output.has_parent_path()) fs::create_directories(output.parent_path());
    classifier.save(output);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::printf("trained on %zu drawings in %.1f s, wrote %s\n", maps.size(), seconds, argv[2]);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "train_room_classifier: %s\n", e.what());
    return 1;
  }
}
