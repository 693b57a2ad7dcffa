#include "kartograf/outputs/fuse_summary.hpp"

#include "outputs/run_json.hpp"

namespace kartograf::io {

std::string fuse_summary_json(const FuseRun& run, const mapping::TsdfVolume& volume,
                              const TriangleMesh& mesh) {
  detail::RunJson json;
  json["sequence"] = run.sequence;
  json["poses"] = run.poses;
  json["backend"] = run.backend;
  json["device"] = run.device;
  json["frames"] = run.frames;
  const mapping::TsdfVolumeParams& p = volume.params();
  json["voxel_m"] = p.voxel_size;
  json["truncation_m"] = p.truncation;
  json["max_weight"] = p.max_weight;
  json["fusion_weight_depth_m"] = p.fusion_weight_depth;  // 0: every observation weighs 1
  json["blocks"] = volume.block_count();
  json["max_blocks"] = p.max_blocks;
  json["mesh"] = {{"file", "mesh.ply"},
                  {"vertices", mesh.vertices.size()},
                  {"triangles", mesh.triangles.size()}};
  json["fuse_ms_per_frame"] =
      run.frames ? 1000.0 * run.fuse_seconds / static_cast<double>(run.frames) : 0.0;
  return json.dump(2) + "\n";
}

}  // namespace kartograf::io
