// The user guide's example (docs/user-guide.md): map an RGB-D sequence with the C++ API as a robot
// would, handing the online mapper one frame at a time and asking for the map while it runs;
// then print what was found and write the same files as `kartograf map`. Built against an
// installed Kartograf by tests/consumer (find_package(kartograf)).
//
//   map_a_sequence SEQUENCE OUT_DIR
#include <cstdio>
#include <exception>

#include <kartograf/compute/context.hpp>
#include <kartograf/formats/sequence_detect.hpp>
#include <kartograf/outputs/map_outputs.hpp>
#include <kartograf/pipeline/mapper.hpp>
#include <kartograf/pipeline/sequence_frame_source.hpp>

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: %s SEQUENCE OUT_DIR\n", argv[0]);
    return 2;
  }
  try {
    using namespace kartograf;
    const io::OpenedSequence opened = io::open_sequence(argv[1]);  // TUM, 7-Scenes, synthetic
    const pipeline::SequenceFrameSource frames(*opened.sequence);  // stands in for a camera
    const compute::Context context = compute::Context::cpu();      // or a Vulkan / OpenCL device

    pipeline::MapperParams params;
    params.pipeline.label_step = 5;  // label and extract planes in every 5th frame
    params.pipeline.room_method = rooms::RoomMethod::morphological;
    params.volume.max_blocks = 8192;  // the TSDF's budget: 48 MiB of 4 cm voxels
    pipeline::Mapper mapper(context, frames.camera(), frames.depth_units_per_metre(), params);

    for (std::size_t i = 0; i < frames.size(); ++i) {
      const pipeline::MapperStep step = mapper.add_frame(frames.frame(i));  // as frames arrive
      if (step.status == pipeline::FrameStatus::fallback)
        std::printf("frame %zu: tracking lost, the motion model's guess\n", i);
      if (i == frames.size() / 2) {  // the map can be asked for at any time
        const TriangleMesh mesh = mapper.mesh();
        std::printf("half way: camera at (%.2f, %.2f, %.2f), mesh of %zu triangles\n",
                    step.pose.translation().x(), step.pose.translation().y(),
                    step.pose.translation().z(), mesh.triangles.size());
      }
    }
    const pipeline::MapPipelineResult map = mapper.finish();

    std::printf("%zu poses, %zu mesh triangles, %zu planes, %zu rooms\n", map.poses.size(),
                map.mesh.triangles.size(), map.planes.size(), map.rooms.records.size());
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
