#pragma once
// An organized RGB-D frame as ICP uses it: points, normals and (optionally) colours at several
// resolutions, all on the device. Level 0 is the camera's resolution; level l + 1 halves level l.
// Coarse-to-fine ICP aligns the coarse levels first (few points, wide basin), then refines.
//
// Downsampling rule, identical on every backend: coarse pixel (x, y) averages the valid points of
// the fine block (2x..2x+1, 2y..2y+1) whose depth exceeds the block's nearest depth z_min by at
// most max_depth_jump * z_min (so a block straddling an object edge takes the foreground, not a
// point floating between the surfaces); coordinates are summed in float in row-major block order
// and multiplied by the float reciprocal of the count (within ~2 ulp of the exact mean; products,
// unlike divisions, round identically on every driver). Colours average the same pixels per
// channel (rounded half up). No valid point: NaN, colour 0.
// Normals of every level from first_normals_level on come from geometry::estimate_normals on
// that level's points; finer levels have none (ICP that starts coarser never reads them, and at
// 640x480 they cost more than all coarser levels together).
#include <cstdint>
#include <vector>

#include "kartograf/compute/buffer.hpp"
#include "kartograf/core/color.hpp"
#include "kartograf/core/intrinsics.hpp"
#include "kartograf/core/point_image.hpp"
#include "kartograf/geometry/backproject.hpp"
#include "kartograf/geometry/normals.hpp"
#include "kartograf/registration/correspondence_finder.hpp"

namespace kartograf::registration {

// Colours travel as one 32-bit word per pixel (core/color.hpp); the names stay usable here.
using kartograf::pack_rgb;
using kartograf::unpack_rgb;

// The camera of a level made by 2x2 blocks: pixel centres at integers on both levels.
PinholeIntrinsics half_resolution(const PinholeIntrinsics& camera);

struct PyramidParams {
  int levels = 3;                // 640x480 -> 320x240 -> 160x120
  float max_depth_jump = 0.05f;  // relative depth gap that splits a 2x2 block (as for normals)
  geometry::NormalParams normals;
  bool with_colors = false;     // allocate and downsample colour images
  int first_normals_level = 0;  // the finest level with normals, 0 .. levels - 1
};

struct PyramidLevel {
  PinholeIntrinsics camera;
  compute::DeviceImage<Point4f> points;
  compute::DeviceImage<Point4f> normals;       // empty on levels finer than first_normals_level
  compute::DeviceImage<std::uint32_t> colors;  // empty without colours
  CloudView view() const;
};

// Holds every level's device images, so rebuilding it for each new frame allocates nothing.
class FramePyramid {
 public:
  // Throws Error on invalid intrinsics, levels < 1, a coarsest level under 8x8 pixels, or
  // first_normals_level outside the levels.
  FramePyramid(const compute::Context& context, const PinholeIntrinsics& camera,
               const PyramidParams& params = {});

  // Level 0 inputs: write them (e.g. DepthBackprojector::run(depth, base_points())), then build().
  compute::DeviceImage<Point4f>& base_points() { return levels_[0].points; }
  compute::DeviceImage<std::uint32_t>& base_colors();  // throws without with_colors

  // The normals from first_normals_level, and every coarser level; only dispatches (no wait).
  void build();
  // Back-projects `depth` into level 0, then build().
  void build(const geometry::DepthBackprojector& projector,
             const compute::DeviceImage<std::uint16_t>& depth);

  int level_count() const { return static_cast<int>(levels_.size()); }
  const PyramidLevel& level(int index) const { return levels_.at(static_cast<std::size_t>(index)); }
  std::vector<CloudView> views() const;  // index 0: finest
  const PyramidParams& params() const { return params_; }

 private:
  const compute::Context* context_;
  PyramidParams params_;
  std::vector<PyramidLevel> levels_;
};

// Convenience for tests and tools: a pyramid built from host images (colours optional).
FramePyramid make_frame_pyramid(const compute::Context& context, const PinholeIntrinsics& camera,
                                const PointImage& points,
                                const Image<std::uint32_t>* colors = nullptr,
                                PyramidParams params = {});

}  // namespace kartograf::registration
