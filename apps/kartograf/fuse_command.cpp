// `kartograf fuse SEQUENCE --poses FILE|groundtruth --out DIR`: every frame fused at its known
// pose into a TSDF on the chosen backend, the surface meshed on the host. Wiring only.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <ostream>
#include <string>

#include "backend_option.hpp"
#include "commands.hpp"
#include "interrupts.hpp"
#include "kartograf/formats/image_io.hpp"
#include "kartograf/formats/occupancy_map_io.hpp"
#include "kartograf/formats/ply.hpp"
#include "kartograf/formats/text_file.hpp"
#include "kartograf/mapping/frame_source.hpp"
#include "kartograf/mapping/tsdf_mesh.hpp"
#include "kartograf/mapping/tsdf_slice.hpp"
#include "kartograf/mapping/tsdf_volume.hpp"
#include "kartograf/outputs/fuse_summary.hpp"
#include "kartograf/outputs/map_outputs.hpp"
#include "output_transaction.hpp"
#include "sequence_run.hpp"

namespace kartograf::cli {

CLI::App* add_fuse_command(CLI::App& app, FuseOptions& o) {
  CLI::App* command = app.add_subcommand(
      "fuse", "Fuse the frames at known poses into a TSDF; writes its surface as a coloured mesh");
  command->add_option("SEQUENCE", o.run.sequence, "RGB-D sequence folder (as slam and map read)")
      ->required();
  add_sequence_input_options(*command, o.run.input, true, true);
  add_backend_option(*command, o.run.backend, o.run.backend_source);
  command
      ->add_option("--poses", o.poses,
                   "Camera poses: 'groundtruth' (the sequence's own) or a TUM trajectory file")
      ->required();
  command->add_option("--out", o.out_dir, "Output folder (mesh.ply, fuse.json)")->required();
  command->add_option("--voxel", o.voxel, "Voxel size [m]")
      ->check(CLI::Range(0.001, 1.0))
      ->capture_default_str();
  command->add_option("--truncation", o.truncation, "Truncation [m] (0: 4 voxels)")
      ->check(CLI::Range(0.0, 8.0))
      ->capture_default_str();
  command->add_option("--max-depth", o.max_depth, "Depth beyond this is not fused [m]")
      ->check(CLI::Range(0.1, 20.0))
      ->capture_default_str();
  command->add_option("--max-blocks", o.max_blocks, "Blocks of 8^3 voxels the volume holds")
      ->check(CLI::Range(1, 1 << 23))
      ->capture_default_str();
  command
      ->add_option("--floor-z", o.floor_z,
                   "Also write the 2-D maps of the robot's height band (0.05-1.5 m above this "
                   "floor height, world z up): occupancy.pgm/.yaml and esdf.png")
      ->check(CLI::Range(-1000.0, 1000.0));
  add_pose_mount_option(*command, o.run.pose_mount);
  command->add_flag(
      "--no-progress", [&o](std::int64_t) { o.run.progress = false; }, "No progress bar on stderr");
  command->add_flag("--force", o.force, "Replace the files of an earlier run");
  return command;
}

namespace {

// The height band's occupancy (ROS map_server files) and its ESDF as grey levels.
void write_band_maps(const std::filesystem::path& dir, const mapping::TsdfBlocks& blocks,
                     double floor_z) {
  mapping::TsdfSliceParams params;
  params.floor_z = floor_z;
  const OccupancyGrid grid = mapping::tsdf_occupancy(blocks, params);
  require(grid.width() > 0, "fuse --floor-z: the volume holds no surface to map");
  io::write_ros_map(dir / "occupancy.yaml", grid);
  io::write_png(dir / "esdf.png", io::esdf_picture(mapping::occupancy_esdf(grid)));
}

}  // namespace

int run_fuse_command(const FuseOptions& o, std::ostream& out, std::ostream& err) {
  OutputFolder folder("fuse", o.out_dir, o.force,
                      {"mesh.ply", "fuse.json", "occupancy.pgm", "occupancy.yaml", "esdf.png"});
  const OpenedRun run = open_run(o.run, err, o.poses);
  const compute::Context context = make_run_context(o.run);
  mapping::TsdfVolumeParams params;
  params.voxel_size = o.voxel;
  params.truncation = o.truncation > 0 ? o.truncation : 4 * o.voxel;
  params.max_blocks = o.max_blocks;
  mapping::TsdfVolume volume(context, params);
  const mapping::KnownPoseLookup pose_of = known_pose_lookup(
      "fuse", o.poses, !run.opened.detected.has_timestamps, "--poses", run.pose_mount);
  const PinholeIntrinsics camera = run.source->camera();
  const geometry::DepthRange range{run.source->depth_units_per_metre(), 0.1, o.max_depth};

  ProgressBar bar(err, o.run.progress);
  double fuse_seconds = 0;
  const std::size_t frames = run.source->size();
  mapping::for_each_frame(
      *run.source, 0, frames, [&](std::size_t i, registration::RgbdImages& images) {
        const Eigen::Isometry3d pose = pose_of(i, images);
        const auto start = std::chrono::steady_clock::now();
        volume.integrate(images.depth, images.color, camera, range, pose);
        context.finish();
        fuse_seconds +=
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        bar.update("fusing", i + 1, frames);
      });
  bar.finish();
  const mapping::TsdfBlocks blocks = volume.download();
  const TriangleMesh mesh = mapping::extract_mesh(blocks);

  const InterruptsDeferred writing;  // a signal waits for the files, then drops them
  io::write_mesh_ply(folder.dir() / "mesh.ply", mesh);
  if (!std::isnan(o.floor_z)) write_band_maps(folder.dir(), blocks, o.floor_z);
  const io::FuseRun record{
      o.run.sequence.string(),    o.poses, std::string(compute::to_string(context.backend())),
      context.device_info().name, frames,  fuse_seconds};
  io::write_text_file(folder.dir() / "fuse.json", io::fuse_summary_json(record, volume, mesh));
  folder.commit();
  char line[256];
  std::snprintf(line, sizeof(line),
                "fuse: %zu frames, %zu blocks of %.3f m voxels, mesh %zu vertices %zu triangles, "
                "%.1f ms/frame (%s)\n",
                frames, volume.block_count(), params.voxel_size, mesh.vertices.size(),
                mesh.triangles.size(), frames ? 1000.0 * fuse_seconds / frames : 0.0,
                std::string(compute::to_string(context.backend())).c_str());
  out << line << "  mesh " << (o.out_dir / "mesh.ply").string() << "\n";
  return 0;
}

}  // namespace kartograf::cli
