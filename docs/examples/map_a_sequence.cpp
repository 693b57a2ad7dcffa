// The user guide's example (docs/user-guide.md): map an RGB-D sequence with the C++ API, print
// what was found, and write the same files as `kartograf map`. Built against an installed
// Kartograf by tests/consumer (find_package(kartograf)).
//
//   map_a_sequence SEQUENCE OUT_DIR
#include <cstdio>
#include <exception>

#include <kartograf/compute/context.hpp>
#include <kartograf/outputs/map_outputs.hpp>
#include <kartograf/formats/sequence_detect.hpp>
#include <kartograf/pipeline/map_pipeline.hpp>
#include <kartograf/pipeline/sequence_frame_source.hpp>

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: %s SEQUENCE OUT_DIR\n", argv[0]);
    return 2;
  }
  try {
    using namespace kartograf;
    const io::OpenedSequence opened = io::open_sequence(argv[1]);  // TUM, 7-Scenes, synthetic
    const pipeline::SequenceFrameSource frames(*opened.sequence);
    const compute::Context context = compute::Context::cpu();  // or a Vulkan / OpenCL device

    pipeline::MapPipelineParams params;
    params.label_step = 5;  // label and extract planes in every 5th frame
    params.room_method = rooms::RoomMethod::morphological;
    const pipeline::MapPipelineResult map = pipeline::run_map_pipeline(context, frames, params);

    std::printf("%zu poses, %zu map points, %zu planes, %zu rooms\n", map.poses.size(),
                map.map.size(), map.planes.size(), map.rooms.records.size());
    for (const rooms::RoomRecord& room : map.rooms.records)
      std::printf("  room %u: %.1f m^2 around (%.2f, %.2f)\n", room.id, room.area_m2,
                  room.centroid.x(), room.centroid.y());
    io::MapRunInfo info;
    info.sequence = argv[1];
    io::write_map_outputs(argv[2], map, std::nullopt, info);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
  return 0;
}
