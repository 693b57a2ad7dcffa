#pragma once
// fuse.json, the summary `kartograf fuse` writes beside mesh.ply.
#include <cstddef>
#include <string>

#include "kartograf/core/triangle_mesh.hpp"
#include "kartograf/mapping/tsdf_volume.hpp"

namespace kartograf::io {

struct FuseRun {
  std::string sequence, poses, backend, device;
  std::size_t frames = 0;
  double fuse_seconds = 0;  // integration alone, summed over the frames
};

std::string fuse_summary_json(const FuseRun& run, const mapping::TsdfVolume& volume,
                              const TriangleMesh& mesh);

}  // namespace kartograf::io
