// Trains the Voronoi random field room segmentation's model (rooms/voronoi_random_field.hpp) on
// ipa_room_segmentation's VRF training drawings and writes it:
//
//   train_vrf <voronoi_random_field_training/training_maps folder> <model file (.yml.gz)> [map.png
//   ...]
//
// The drawings (training_*.png) are grey 0 obstacle, 77 room, 115 hallway, 179 doorway. Without a
// list of maps, every drawing of a building that is not among the ipa test maps is used: the
// folder also holds drawings of Freiburg 101, Freiburg 52, lab_c, lab_ipa and office_e, which are
// test maps, so those are left out. The shipped model, models/rooms/vrf_model.yml.gz, was made
// from ../shared/data/ipa_room_maps/training_maps/voronoi_random_field_training/training_maps with
// the default parameters.
#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <string>
#include <vector>

#include "kartograf/core/error.hpp"
#include "kartograf/formats/occupancy_map_io.hpp"
#include "kartograf/rooms/voronoi_random_field.hpp"

namespace fs = std::filesystem;
using namespace kartograf;

namespace {

// Drawings of buildings that are ipa test maps (never trained on by default).
constexpr std::array<const char*, 5> kTestBuildings = {
    "training_Fr101.png", "training_Fr52.png", "training_lab_c_furnitures.png",
    "training_lab_ipa.png", "training_office_e.png"};

std::vector<fs::path> default_drawings(const fs::path& folder) {
  require(fs::is_directory(folder), "training maps folder " + folder.string() + " does not exist");
  std::vector<fs::path> drawings;
  for (const fs::directory_entry& entry : fs::directory_iterator(folder)) {
    const std::string name = entry.path().filename().string();
    const bool test_building =
        std::find(kTestBuildings.begin(), kTestBuildings.end(), name) != kTestBuildings.end();
    if (entry.is_regular_file() && name.starts_with("training_") &&
        entry.path().extension() == ".png" && !test_building)
      drawings.push_back(entry.path());
  }
  std::sort(drawings.begin(), drawings.end());
  require(!drawings.empty(), "training maps folder " + folder.string() +
                                 " has no training_*.png of a non-test building");
  return drawings;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr,
                 "usage: %s <training_maps folder> <model file (.yml.gz)> [drawing.png ...]\n",
                 argv[0]);
    return 2;
  }
  try {
    const auto start = std::chrono::steady_clock::now();
    std::vector<fs::path> drawings;
    for (int i = 3; i < argc; ++i) drawings.push_back(fs::path(argv[1]) / argv[i]);
    if (drawings.empty()) drawings = default_drawings(argv[1]);
    std::vector<rooms::VrfTrainingMap> maps;
    for (const fs::path& path : drawings) {
      maps.push_back(rooms::vrf_training_map(path.filename().string(), io::read_map_gray(path)));
      std::printf("training map %s\n", maps.back().name.c_str());
    }
    const rooms::VrfModel model = rooms::VrfModel::train(maps);
    const fs::path output = argv[2];
    if (output.has_parent_path()) fs::create_directories(output.parent_path());
    model.save(output);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::printf("trained on %zu maps in %.1f s (pairwise weight %.2f), wrote %s\n", maps.size(),
                seconds, model.trained_pairwise_weight(), argv[2]);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "train_vrf: %s\n", e.what());
    return 1;
  }
}
