// The truncated signed distance field (rules in include/kartograf/mapping/tsdf_volume.hpp): voxel
// blocks of 8^3 voxels, found through the open-addressing table of kernels/voxel_hash (one key
// per block), each block's voxels at its pool index. Per frame (src/mapping/tsdf_volume.cpp):
//   1 touch      every valid depth pixel (every `step`-th) inserts the blocks its ray crosses
//                within +-truncation of its depth, and stamps their slots
//   2 assign     every table slot whose block has no pool index yet takes the next one; every
//                stamped slot appends its block to the frame's active list
//   3 integrate  every voxel of the active blocks: projected into the depth image, the
//                projective distance d - z, truncated and divided by the truncation, joins the
//                voxel's weighted mean (as its colour does), where d - z >= -truncation, with
//                weight 1 or, with weight_depth, less for far observations
// Ray casting reads the field: every pixel's ray marches through the blocks to the first change
// from + to -, refined on the trilinear field, and returns the point in the camera's frame.
// Voxel v of a block at block coordinates b is at world (8 b + v + 0.5) x voxel_size (its centre).
#ifndef KARTOGRAF_KERNELS_TSDF_H
#define KARTOGRAF_KERNELS_TSDF_H
#include "kernels/tsdf/tsdf_voxel.h"
#include "kernels/voxel_hash/voxel_hash.h"

#define KG_TSDF_LOCAL_X 64
#define KG_TSDF_LOCAL_2D 16
#define KG_TSDF_BLOCK_SIDE 8
#define KG_TSDF_BLOCK_VOXELS 512u
#define KG_TSDF_NO_BLOCK 0xffffffffu
#define KG_TSDF_BLOCK_LIMIT 1048576  // 2^20 blocks each way from the origin

// The status counters the passes fill and the host reads.
#define KG_TSDF_STATUS_BLOCKS 0u         // blocks given a pool index (may pass the capacity)
#define KG_TSDF_STATUS_ACTIVE 1u         // blocks the frame touched
#define KG_TSDF_STATUS_TABLE_FULL 2u     // keys the table had no slot for
#define KG_TSDF_STATUS_OUT_OF_BLOCKS 3u  // blocks the pool had no room for
#define KG_TSDF_STATUS_OUT_OF_RANGE 4u   // points beyond 2^20 blocks (or not finite)
#define KG_TSDF_STATUS_VALUES 5u

// A rigid motion p' = R p + t in a parameter block (R row-major): the TSDF's passes and the band's.
#define KG_TSDF_RIGID_PARAMS \
  KG_PARAM(float, r00)       \
  KG_PARAM(float, r01)       \
  KG_PARAM(float, r02)       \
  KG_PARAM(float, r10)       \
  KG_PARAM(float, r11)       \
  KG_PARAM(float, r12)       \
  KG_PARAM(float, r20)       \
  KG_PARAM(float, r21)       \
  KG_PARAM(float, r22)       \
  KG_PARAM(float, tx)        \
  KG_PARAM(float, ty)        \
  KG_PARAM(float, tz)

KG_RULES_BEGIN

// One parameter block for every pass: the camera, its pose (camera to world: p_w = R p_c + t,
// R row-major) and the field's layout.
KG_PARAMS_BEGIN(TsdfParams)
KG_PARAM(uint, width)
KG_PARAM(uint, height)
KG_PARAM(uint, min_units)  // valid depth values are min_units..max_units (never 0)
KG_PARAM(uint, max_units)
KG_PARAM(float, metres_per_unit)
KG_PARAM(float, fx)
KG_PARAM(float, fy)
KG_PARAM(float, cx)
KG_PARAM(float, cy)
KG_PARAM(float, voxel_size)
KG_PARAM(float, truncation)
KG_PARAM(float, max_weight)
KG_PARAM(float, inverse_voxel)  // 1 / voxel_size, rounded once on the host (a device's division
                                // may round otherwise); a block's is an eighth of it, exactly
KG_PARAM(float, weight_depth)   // an observation beyond it weighs (weight_depth / z)^4; 0: all 1
KG_TSDF_RIGID_PARAMS
KG_PARAM(uint, capacity_log2)   // the table has 2^capacity_log2 slots
KG_PARAM(uint, block_capacity)  // the pool's blocks
KG_PARAM(uint, stamp)           // this frame's stamp (never 0)
KG_PARAM(uint, count)           // items of the pass: slots, active voxels
KG_PARAM(uint, step)            // touch: every step-th pixel each way; ray cast: the most steps
KG_PARAM(uint, has_color)
KG_PARAMS_END(TsdfParams)

// 1 / (8 voxel_size): the host's rounded 1 / voxel_size scaled by a power of two, so the same
// float as rounding 1 / (8 voxel_size) itself.
KG_INLINE float tsdf_inverse_block(TsdfParams p) {
  return p.inverse_voxel * 0.125f;
}

KG_INLINE bool tsdf_depth_valid(uint d, TsdfParams p) {
  return KG_BOTH(d != 0u, KG_BOTH(d >= p.min_units, d <= p.max_units));
}

// Depth value d (16 bits) in metres; through int, which converts as vector code on every CPU.
KG_INLINE float tsdf_metres(uint d, TsdfParams p) {
  return KG_FLOAT(KG_INT(d)) * p.metres_per_unit;
}

KG_INLINE float3 tsdf_to_world(float3 c, TsdfParams p) {
  return KG_FLOAT3(p.r00 * c.x + p.r01 * c.y + p.r02 * c.z + p.tx,
                   p.r10 * c.x + p.r11 * c.y + p.r12 * c.z + p.ty,
                   p.r20 * c.x + p.r21 * c.y + p.r22 * c.z + p.tz);
}

// A direction (no translation) from the camera's frame to the world's.
KG_INLINE float3 tsdf_rotate_to_world(float3 c, TsdfParams p) {
  return KG_FLOAT3(p.r00 * c.x + p.r01 * c.y + p.r02 * c.z, p.r10 * c.x + p.r11 * c.y + p.r12 * c.z,
                   p.r20 * c.x + p.r21 * c.y + p.r22 * c.z);
}

KG_INLINE float3 tsdf_to_camera(float3 w, TsdfParams p) {
  const float3 d = w - KG_FLOAT3(p.tx, p.ty, p.tz);
  return KG_FLOAT3(p.r00 * d.x + p.r10 * d.y + p.r20 * d.z, p.r01 * d.x + p.r11 * d.y + p.r21 * d.z,
                   p.r02 * d.x + p.r12 * d.y + p.r22 * d.z);
}

// Whether floor(x) is a block coordinate with a key (false for NaN and infinities).
KG_INLINE bool tsdf_axis_in_range(float x) {
  return x >= -KG_FLOAT(KG_TSDF_BLOCK_LIMIT) && x < KG_FLOAT(KG_TSDF_BLOCK_LIMIT);
}

KG_INLINE uint64_t tsdf_block_key(int bx, int by, int bz) {
  return 1UL + (KG_UINT64(bx + KG_TSDF_BLOCK_LIMIT) | (KG_UINT64(by + KG_TSDF_BLOCK_LIMIT) << 21) |
                (KG_UINT64(bz + KG_TSDF_BLOCK_LIMIT) << 42));
}

KG_INLINE int tsdf_key_axis(uint64_t key, uint shift) {
  return KG_INT(KG_INT64(((key - 1UL) >> shift) & 0x1fffffUL) - KG_INT64(KG_TSDF_BLOCK_LIMIT));
}

// The voxel's index in its block: x fastest.
KG_INLINE uint tsdf_local_index(int vx, int vy, int vz) {
  return KG_UINT(vx & 7) + 8u * KG_UINT(vy & 7) + 64u * KG_UINT(vz & 7);
}

// A walk through the unit cells that the segment from a to b crosses (grid units), cell by cell.
KG_STRUCT_BEGIN(TsdfSegmentWalk)
int x;  // the current cell
int y;
int z;
int sx;  // the step along each axis (-1, 0, 1)
int sy;
int sz;
float tx;  // the segment's parameter at the next cell boundary of each axis
float ty;
float tz;
float dx;  // the parameter's growth per cell along each axis
float dy;
float dz;
int more;  // 0: the segment ends in the current cell
KG_STRUCT_END(TsdfSegmentWalk)

KG_INLINE float tsdf_first_boundary(float from, int step, float delta) {
  const float cell = floor(from);
  if (step > 0) return (cell + 1.0f - from) * delta;
  if (step < 0) return (from - cell) * delta;
  return 1e30f;
}

KG_INLINE TsdfSegmentWalk tsdf_segment_walk(float3 a, float3 b) {
  const float3 d = b - a;
  TsdfSegmentWalk w;
  w.x = KG_INT(floor(a.x));
  w.y = KG_INT(floor(a.y));
  w.z = KG_INT(floor(a.z));
  w.sx = d.x > 0.0f ? 1 : (d.x < 0.0f ? -1 : 0);
  w.sy = d.y > 0.0f ? 1 : (d.y < 0.0f ? -1 : 0);
  w.sz = d.z > 0.0f ? 1 : (d.z < 0.0f ? -1 : 0);
  w.dx = w.sx != 0 ? 1.0f / kg_fabs(d.x) : 1e30f;
  w.dy = w.sy != 0 ? 1.0f / kg_fabs(d.y) : 1e30f;
  w.dz = w.sz != 0 ? 1.0f / kg_fabs(d.z) : 1e30f;
  w.tx = tsdf_first_boundary(a.x, w.sx, w.dx);
  w.ty = tsdf_first_boundary(a.y, w.sy, w.dy);
  w.tz = tsdf_first_boundary(a.z, w.sz, w.dz);
  w.more = 1;
  return w;
}

// The walk in the next cell, or with `more` = 0 when the segment ends in the current one.
KG_INLINE TsdfSegmentWalk tsdf_segment_step(TsdfSegmentWalk w) {
  if (w.tx <= w.ty && w.tx <= w.tz) {
    w.more = w.tx <= 1.0f ? 1 : 0;
    w.x += w.more * w.sx;
    w.tx += w.dx;
  } else if (w.ty <= w.tz) {
    w.more = w.ty <= 1.0f ? 1 : 0;
    w.y += w.more * w.sy;
    w.ty += w.dy;
  } else {
    w.more = w.tz <= 1.0f ? 1 : 0;
    w.z += w.more * w.sz;
    w.tz += w.dz;
  }
  return w;
}

// ---- Pass 1 (touch): the shader declares keys, stamps and status.
#if !defined(VULKAN) || defined(KG_TSDF_TOUCH_PASS)

// Inserts the block (bx, by, bz) and stamps its slot.
KG_INLINE void tsdf_touch_block(KG_BUFFER_PARAM(uint64_t, keys) KG_BUFFER_PARAM(uint, stamps)
                                    KG_BUFFER_PARAM(uint, status) int bx,
                                int by, int bz, TsdfParams p) {
  const int slot =
      voxel_insert_key(KG_BUFFER_ARG(keys) tsdf_block_key(bx, by, bz), p.capacity_log2);
  if (slot < 0) {
    kg_atomic_add_u32(status, KG_TSDF_STATUS_TABLE_FULL, 1u);
  } else if (stamps[slot] != p.stamp) {
    stamps[slot] = p.stamp;  // every writer writes the same value
  }
}

// Pixel (x, y) with depth value d: the walk over the blocks its ray crosses between depths
// d - truncation and d + truncation, where the field it writes is not saturated (a 3-D DDA over
// the block grid, Amanatides and Woo 1987); an empty walk (more = 0) for an invalid depth or a
// point out of range (counted). Voxels off this ray are on other pixels' rays: allocating the box
// of +-truncation around the point instead took 1.47x the blocks (7-Scenes, 1 cm voxels).
KG_FORCE_INLINE TsdfSegmentWalk tsdf_touch_walk(KG_BUFFER_PARAM(uint, status) uint x, uint y,
                                                uint d, TsdfParams p) {
  const float z = tsdf_metres(d, p);
  const float3 ray = KG_FLOAT3((KG_FLOAT(x) - p.cx) / p.fx, (KG_FLOAT(y) - p.cy) / p.fy, 1.0f);
  const float inverse_block = tsdf_inverse_block(p);
  const float3 a = tsdf_to_world(ray * (z - p.truncation), p) * inverse_block;
  const float3 b = tsdf_to_world(ray * (z + p.truncation), p) * inverse_block;
  const bool in_range = tsdf_axis_in_range(a.x) && tsdf_axis_in_range(a.y) &&
                        tsdf_axis_in_range(a.z) && tsdf_axis_in_range(b.x) &&
                        tsdf_axis_in_range(b.y) && tsdf_axis_in_range(b.z);
  const bool valid = tsdf_depth_valid(d, p);
  if (valid && !in_range) kg_atomic_add_u32(status, KG_TSDF_STATUS_OUT_OF_RANGE, 1u);
  TsdfSegmentWalk walk = tsdf_segment_walk(in_range ? a : KG_FLOAT3(0.0f, 0.0f, 0.0f),
                                           in_range ? b : KG_FLOAT3(0.0f, 0.0f, 0.0f));
  walk.more = valid && in_range ? 1 : 0;
  return walk;
}

// The segment is at most two blocks long (truncation <= a block's side): at most 7 blocks.
#define KG_TSDF_WALK_BLOCKS 8

// Pixel (x, y) with depth value d: every block of its walk inserted and stamped.
KG_FORCE_INLINE void tsdf_touch_pixel(KG_BUFFER_PARAM(uint64_t, keys) KG_BUFFER_PARAM(uint, stamps)
                                          KG_BUFFER_PARAM(uint, status) uint x,
                                      uint y, uint d, TsdfParams p) {
  TsdfSegmentWalk walk = tsdf_touch_walk(KG_BUFFER_ARG(status) x, y, d, p);
  for (int i = 0; i < KG_TSDF_WALK_BLOCKS && walk.more != 0; ++i) {
    tsdf_touch_block(KG_BUFFER_ARG(keys) KG_BUFFER_ARG(stamps) KG_BUFFER_ARG(status) walk.x, walk.y,
                     walk.z, p);
    walk = tsdf_segment_step(walk);
  }
}

#endif

// ---- Pass 2 (assign): the shader declares keys, slot_blocks, block_keys, stamps, active and
// status.
#if !defined(VULKAN) || defined(KG_TSDF_ASSIGN_PASS)

KG_FORCE_INLINE void tsdf_assign_slot(KG_BUFFER_PARAM(const uint64_t, keys)
                                          KG_BUFFER_PARAM(uint, slot_blocks)
                                              KG_BUFFER_PARAM(uint64_t, block_keys)
                                                  KG_BUFFER_PARAM(const uint, stamps)
                                                      KG_BUFFER_PARAM(uint, active_blocks)
                                                          KG_BUFFER_PARAM(uint, status) uint slot,
                                      TsdfParams p) {
  const uint64_t key = keys[slot];
  if (key == KG_EMPTY_VOXEL_KEY) return;
  uint block = slot_blocks[slot];
  if (block == KG_TSDF_NO_BLOCK) {
    block = kg_atomic_add_u32(status, KG_TSDF_STATUS_BLOCKS, 1u);
    if (block >= p.block_capacity) {
      kg_atomic_add_u32(status, KG_TSDF_STATUS_OUT_OF_BLOCKS, 1u);
      return;
    }
    slot_blocks[slot] = block;
    block_keys[block] = key;
  }
  if (stamps[slot] == p.stamp)
    active_blocks[kg_atomic_add_u32(status, KG_TSDF_STATUS_ACTIVE, 1u)] = block;
}

#endif

// ---- Pass 3 (integrate): per voxel, the wrapper reads the pixel the rule names.

// Voxel `cell` of the block with `key`: its centre in the camera's frame.
KG_INLINE float3 tsdf_voxel_in_camera(uint64_t key, uint cell, TsdfParams p) {
  const int vx = tsdf_key_axis(key, 0u) * KG_TSDF_BLOCK_SIDE + KG_INT(cell & 7u);
  const int vy = tsdf_key_axis(key, 21u) * KG_TSDF_BLOCK_SIDE + KG_INT((cell >> 3u) & 7u);
  const int vz = tsdf_key_axis(key, 42u) * KG_TSDF_BLOCK_SIDE + KG_INT(cell >> 6u);
  const float3 w =
      KG_FLOAT3(KG_FLOAT(vx) + 0.5f, KG_FLOAT(vy) + 0.5f, KG_FLOAT(vz) + 0.5f) * p.voxel_size;
  return tsdf_to_camera(w, p);
}

// The pixel (y * width + x) a voxel centre at c (camera frame) projects to (the nearest pixel
// centre), or -1. Without branches, so that the CPU's loop over a block is vector code: the
// conversion truncates, which is floor() for the u, v >= 0 it keeps (and 0 stands in elsewhere:
// converting a float out of int's range is undefined).
KG_INLINE int tsdf_pixel_of(float3 c, TsdfParams p) {
  const float u = p.fx * c.x / c.z + p.cx + 0.5f;
  const float v = p.fy * c.y / c.z + p.cy + 0.5f;
  const bool seen = KG_BOTH(KG_BOTH(c.z > 0.0f, KG_BOTH(u >= 0.0f, v >= 0.0f)),
                            KG_BOTH(u < KG_FLOAT(p.width), v < KG_FLOAT(p.height)));
  const int column = KG_INT(seen ? u : 0.0f), row = KG_INT(seen ? v : 0.0f);
  return seen ? row * KG_INT(p.width) + column : -1;
}

KG_STRUCT_BEGIN(TsdfVoxelView)
uint voxel;  // index in the pool's voxels
int pixel;   // the pixel it projects to (y * width + x), or -1
float z;     // its centre's depth in the camera
KG_STRUCT_END(TsdfVoxelView)

// Item i of the integration: voxel i % 512 of active block i / 512, and where the camera sees it.
// The shader declares active_blocks and block_keys.
#if !defined(VULKAN) || defined(KG_TSDF_INTEGRATE_PASS)
KG_INLINE TsdfVoxelView tsdf_voxel_view(KG_BUFFER_PARAM(const uint, active_blocks)
                                            KG_BUFFER_PARAM(const uint64_t, block_keys) uint i,
                                        TsdfParams p) {
  const uint block = active_blocks[i / KG_TSDF_BLOCK_VOXELS];
  const uint cell = i % KG_TSDF_BLOCK_VOXELS;
  const float3 c = tsdf_voxel_in_camera(block_keys[block], cell, p);
  TsdfVoxelView view;
  view.voxel = block * KG_TSDF_BLOCK_VOXELS + cell;
  view.pixel = tsdf_pixel_of(c, p);
  view.z = c.z;
  return view;
}
#endif

// One channel's weighted mean, rounded to the nearest level.
KG_INLINE uint tsdf_mean_channel(uint old_color, uint new_color, uint shift, float old_weight,
                                 float new_weight, float share) {
  const float a = KG_FLOAT((old_color >> shift) & 0xffu);
  const float b = KG_FLOAT((new_color >> shift) & 0xffu);
  const float mean = (a * old_weight + b * new_weight) * share;
  return KG_UINT(min(KG_INT(mean + 0.5f), 255)) << shift;  // int: a vector conversion
}

// Whether depth value d, seen at depth z of a voxel's centre, changes the voxel: a valid depth,
// and the voxel not hidden behind the surface. The wrappers write only those voxels.
KG_INLINE bool tsdf_fuses(uint d, float z, TsdfParams p) {
  return KG_BOTH(tsdf_depth_valid(d, p), tsdf_metres(d, p) - z >= -p.truncation);
}

// An observation's weight at depth z: 1, or with weight_depth > 0 the inverse variance of a
// structured-light sensor's depth noise (which grows as z^2) relative to weight_depth's,
// (weight_depth / z)^4, at most 1.
KG_INLINE float tsdf_observation_weight(float z, TsdfParams p) {
  const float ratio = min(1.0f, p.weight_depth / max(z, 1e-6f));
  const float squared = ratio * ratio;
  return p.weight_depth > 0.0f ? squared * squared : 1.0f;
}

// The voxel after fusing depth value d (and colour) seen at depth z of the voxel's centre.
// Selections instead of branches: the CPU wrapper runs it over a block as vector code.
KG_INLINE TsdfVoxel tsdf_fuse(TsdfVoxel voxel, uint d, float z, uint color, TsdfParams p) {
  const bool fuses = tsdf_fuses(d, z, p);
  const float distance = tsdf_metres(d, p) - z;
  const float value = min(1.0f, distance / p.truncation);
  const float weight = tsdf_observation_weight(z, p);
  const float share = 1.0f / (voxel.weight + weight);  // the mean's divisor, as a factor
  const uint mean = tsdf_mean_channel(voxel.color, color, 0u, voxel.weight, weight, share) |
                    tsdf_mean_channel(voxel.color, color, 8u, voxel.weight, weight, share) |
                    tsdf_mean_channel(voxel.color, color, 16u, voxel.weight, weight, share);
  TsdfVoxel fused;
  fused.tsdf = fuses ? (voxel.tsdf * voxel.weight + value * weight) * share : voxel.tsdf;
  fused.weight = fuses ? min(voxel.weight + weight, p.max_weight) : voxel.weight;
  fused.color = KG_BOTH(fuses, p.has_color != 0u) ? mean : voxel.color;
  return fused;
}

// ---- Ranges (before a ray cast): the image in tiles of KG_TSDF_TILE x KG_TSDF_TILE pixels, each
// with the depths (in depth units) between which blocks can lie on its rays, so that a ray starts
// at the first block instead of crossing empty space a block at a time. ranges[2 t] holds
// 0xffffffff - nearest, ranges[2 t + 1] the farthest: all 0 is a tile without blocks.
#define KG_TSDF_TILE 8u

KG_INLINE uint tsdf_tile_columns(TsdfParams p) {
  return (p.width + KG_TSDF_TILE - 1u) / KG_TSDF_TILE;
}

KG_INLINE uint tsdf_tile_count(TsdfParams p) {
  return tsdf_tile_columns(p) * ((p.height + KG_TSDF_TILE - 1u) / KG_TSDF_TILE);
}

KG_STRUCT_BEGIN(TsdfTileBox)
uint x0;  // tiles x0..x1, y0..y1; x0 > x1 where the block is out of view
uint x1;
uint y0;
uint y1;
uint near_units;  // its depths, widened to whole depth units
uint far_units;
KG_STRUCT_END(TsdfTileBox)

// The tiles and depths the block with `key` can cover: its 8 corners' projections where all lie
// in front of the camera (a box's image is inside its corners'), else the whole image.
KG_INLINE TsdfTileBox tsdf_block_tiles(uint64_t key, TsdfParams p) {
  const float side = p.voxel_size * KG_FLOAT(KG_TSDF_BLOCK_SIDE);
  const float3 origin =
      KG_FLOAT3(KG_FLOAT(tsdf_key_axis(key, 0u)), KG_FLOAT(tsdf_key_axis(key, 21u)),
                KG_FLOAT(tsdf_key_axis(key, 42u))) *
      side;
  float near = 1e30f, far = -1e30f, u0 = 1e30f, u1 = -1e30f, v0 = 1e30f, v1 = -1e30f;
  for (uint corner = 0u; corner < 8u; ++corner) {
    const float3 offset =
        KG_FLOAT3(KG_FLOAT(corner & 1u), KG_FLOAT((corner >> 1u) & 1u), KG_FLOAT(corner >> 2u));
    const float3 c = tsdf_to_camera(origin + offset * side, p);
    near = min(near, c.z);
    far = max(far, c.z);
    const float z = max(c.z, 1e-6f);
    u0 = min(u0, p.fx * c.x / z + p.cx);
    u1 = max(u1, p.fx * c.x / z + p.cx);
    v0 = min(v0, p.fy * c.y / z + p.cy);
    v1 = max(v1, p.fy * c.y / z + p.cy);
  }
  const float right = KG_FLOAT(p.width - 1u), bottom = KG_FLOAT(p.height - 1u);
  const bool whole = !(near > 1e-4f);  // a corner at or behind the camera
  const bool seen =
      far > 0.0f && (whole || (u1 >= 0.0f && u0 <= right && v1 >= 0.0f && v0 <= bottom));
  TsdfTileBox box;
  box.x0 = whole ? 0u : KG_UINT(max(u0, 0.0f)) / KG_TSDF_TILE;
  box.x1 = whole ? (p.width - 1u) / KG_TSDF_TILE : KG_UINT(min(u1, right)) / KG_TSDF_TILE;
  box.y0 = whole ? 0u : KG_UINT(max(v0, 0.0f)) / KG_TSDF_TILE;
  box.y1 = whole ? (p.height - 1u) / KG_TSDF_TILE : KG_UINT(min(v1, bottom)) / KG_TSDF_TILE;
  box.x0 = seen ? box.x0 : 1u;
  box.x1 = seen ? box.x1 : 0u;
  box.near_units = KG_UINT(floor(max(near, 0.0f) / p.metres_per_unit));
  box.far_units = KG_UINT(min(floor(max(far, 0.0f) / p.metres_per_unit) + 2.0f, 4.0e9f));
  return box;
}

#if !defined(VULKAN) || defined(KG_TSDF_RANGE_PASS)
// The shader declares ranges.
KG_INLINE void tsdf_range_block(KG_BUFFER_PARAM(uint, ranges) uint64_t key, TsdfParams p) {
  const TsdfTileBox box = tsdf_block_tiles(key, p);
  const uint columns = tsdf_tile_columns(p);
  for (uint ty = box.y0; ty <= box.y1 && box.x0 <= box.x1; ++ty) {
    for (uint tx = box.x0; tx <= box.x1; ++tx) {
      const uint tile = ty * columns + tx;
      kg_atomic_max_u32(ranges, 2u * tile, 0xffffffffu - box.near_units);
      kg_atomic_max_u32(ranges, 2u * tile + 1u, box.far_units);
    }
  }
}
#endif

// ---- Ray casting: the shader declares keys, slot_blocks and voxels.
#if !defined(VULKAN) || defined(KG_TSDF_READ_PASS)

// A voxel's tsdf where no block holds it (weight 0 too): beyond any stored value.
#define KG_TSDF_NO_BLOCK_VALUE 2.0f

// The voxel (vx, vy, vz) (integral voxel coordinates); weight 0 and tsdf KG_TSDF_NO_BLOCK_VALUE
// where no block holds it.
// The pool index of the block with `key`, or KG_TSDF_NO_BLOCK.
KG_INLINE uint tsdf_find_block(KG_BUFFER_PARAM(const uint64_t, keys)
                                   KG_BUFFER_PARAM(const uint, slot_blocks) uint64_t key,
                               TsdfParams p) {
  const int slot = voxel_find_key(KG_BUFFER_ARG(keys) key, p.capacity_log2);
  return slot < 0 ? KG_TSDF_NO_BLOCK : slot_blocks[slot];
}

// Voxel (vx, vy, vz) of pool block `block` (KG_TSDF_NO_BLOCK: the missing voxel).
KG_INLINE TsdfVoxel tsdf_voxel_in(KG_BUFFER_PARAM(const TsdfVoxel, voxels) uint block, int vx,
                                  int vy, int vz) {
  if (block == KG_TSDF_NO_BLOCK) {
    TsdfVoxel none;
    none.tsdf = KG_TSDF_NO_BLOCK_VALUE;
    none.weight = 0.0f;
    none.color = 0u;
    return none;
  }
  return voxels[block * KG_TSDF_BLOCK_VOXELS + tsdf_local_index(vx, vy, vz)];
}

KG_INLINE TsdfVoxel tsdf_voxel_at(KG_BUFFER_PARAM(const uint64_t, keys)
                                      KG_BUFFER_PARAM(const uint, slot_blocks)
                                          KG_BUFFER_PARAM(const TsdfVoxel, voxels) int vx,
                                  int vy, int vz, TsdfParams p) {
  const uint block = tsdf_find_block(
      KG_BUFFER_ARG(keys) KG_BUFFER_ARG(slot_blocks) tsdf_block_key(vx >> 3, vy >> 3, vz >> 3), p);
  return tsdf_voxel_in(KG_BUFFER_ARG(voxels) block, vx, vy, vz);
}

// The ray parameter (depth) where the ray origin + direction x t leaves the block holding w,
// reached at parameter t; a hair beyond, so that the next sample lies in the next block.
KG_INLINE float tsdf_block_exit(float3 w, float3 direction, float t, TsdfParams p) {
  const float side = p.voxel_size * KG_FLOAT(KG_TSDF_BLOCK_SIDE);
  float exit = 1e30f;
  const float inverse_block = tsdf_inverse_block(p);
  const float bx = floor(w.x * inverse_block), by = floor(w.y * inverse_block),
              bz = floor(w.z * inverse_block);
  if (direction.x != 0.0f)
    exit = min(exit, ((direction.x > 0.0f ? bx + 1.0f : bx) * side - w.x) / direction.x);
  if (direction.y != 0.0f)
    exit = min(exit, ((direction.y > 0.0f ? by + 1.0f : by) * side - w.y) / direction.y);
  if (direction.z != 0.0f)
    exit = min(exit, ((direction.z > 0.0f ? bz + 1.0f : bz) * side - w.z) / direction.z);
  // A step of at least a tenth of a voxel along the ray: never stuck on a block's face.
  const float length = sqrt(dot(direction, direction));
  return t + max(exit, 0.0f) + 0.1f * p.voxel_size / length;
}

// Whether world point w lies in the range of keys.
KG_INLINE bool tsdf_point_in_range(float3 w, TsdfParams p) {
  const float inverse_block = tsdf_inverse_block(p);
  return tsdf_axis_in_range(w.x * inverse_block - 1.0f) &&
         tsdf_axis_in_range(w.y * inverse_block - 1.0f) &&
         tsdf_axis_in_range(w.z * inverse_block - 1.0f) &&
         tsdf_axis_in_range(w.x * inverse_block + 1.0f) &&
         tsdf_axis_in_range(w.y * inverse_block + 1.0f) &&
         tsdf_axis_in_range(w.z * inverse_block + 1.0f);
}

// The voxel whose cell contains world point w.
KG_INLINE TsdfVoxel tsdf_nearest(KG_BUFFER_PARAM(const uint64_t, keys)
                                     KG_BUFFER_PARAM(const uint, slot_blocks)
                                         KG_BUFFER_PARAM(const TsdfVoxel, voxels) float3 w,
                                 TsdfParams p) {
  const float3 g = w * p.inverse_voxel;
  return tsdf_voxel_at(KG_BUFFER_ARG(keys) KG_BUFFER_ARG(slot_blocks) KG_BUFFER_ARG(voxels)
                           KG_INT(floor(g.x)),
                       KG_INT(floor(g.y)), KG_INT(floor(g.z)), p);
}

// The field at world point w, trilinear between the 8 voxel centres around it; NaN where one of
// them was never observed.
KG_FORCE_INLINE float tsdf_trilinear(KG_BUFFER_PARAM(const uint64_t, keys)
                                         KG_BUFFER_PARAM(const uint, slot_blocks)
                                             KG_BUFFER_PARAM(const TsdfVoxel, voxels) float3 w,
                                     TsdfParams p) {
  const float3 g = w * p.inverse_voxel - KG_FLOAT3(0.5f, 0.5f, 0.5f);
  const float fx = floor(g.x), fy = floor(g.y), fz = floor(g.z);
  const float ax = g.x - fx, ay = g.y - fy, az = g.z - fz;
  const int x0 = KG_INT(fx), y0 = KG_INT(fy), z0 = KG_INT(fz);
  float sum = 0.0f;
  // The corners mostly share a block: its lookup is kept.
  uint64_t cached_key = KG_EMPTY_VOXEL_KEY;
  uint cached_block = KG_TSDF_NO_BLOCK;
  for (uint corner = 0u; corner < 8u; ++corner) {
    const int dx = KG_INT(corner & 1u), dy = KG_INT((corner >> 1u) & 1u), dz = KG_INT(corner >> 2u);
    const int vx = x0 + dx, vy = y0 + dy, vz = z0 + dz;
    const uint64_t key = tsdf_block_key(vx >> 3, vy >> 3, vz >> 3);
    if (key != cached_key) {
      cached_block = tsdf_find_block(KG_BUFFER_ARG(keys) KG_BUFFER_ARG(slot_blocks) key, p);
      cached_key = key;
    }
    const TsdfVoxel v = tsdf_voxel_in(KG_BUFFER_ARG(voxels) cached_block, vx, vy, vz);
    if (v.weight <= 0.0f) return KG_NAN;
    const float weight =
        (dx == 1 ? ax : 1.0f - ax) * (dy == 1 ? ay : 1.0f - ay) * (dz == 1 ? az : 1.0f - az);
    sum += weight * v.tsdf;
  }
  return sum;
}

// The trilinear field at depth t of the ray origin + direction x t.
KG_INLINE float tsdf_field_on_ray(KG_BUFFER_PARAM(const uint64_t, keys)
                                      KG_BUFFER_PARAM(const uint, slot_blocks)
                                          KG_BUFFER_PARAM(const TsdfVoxel, voxels) float3 origin,
                                  float3 direction, float t, TsdfParams p) {
  return tsdf_trilinear(
      KG_BUFFER_ARG(keys) KG_BUFFER_ARG(slot_blocks) KG_BUFFER_ARG(voxels) origin + direction * t,
      p);
}

// Where the ray crosses zero between depths t0 (voxel value f0 > 0) and t1 (f1 <= 0): linear in
// the trilinear field, else in the voxels' values. The voxels' signs change up to half a voxel
// away from the field's: where the field at t1 is still > 0, the crossing lies beyond, and where
// it is <= 0 at t0 already, before; the bracket moves by half a voxel (at most
// KG_TSDF_CROSSING_MOVES times) to catch it. Taking the voxels' values there instead biased the
// surface by up to half a voxel, and frame-to-model tracking drifted with it (synthetic,
// noise-free: 4.8 mm at 2 cm).
#define KG_TSDF_CROSSING_MOVES 4u
KG_INLINE float tsdf_crossing(KG_BUFFER_PARAM(const uint64_t, keys)
                                  KG_BUFFER_PARAM(const uint, slot_blocks)
                                      KG_BUFFER_PARAM(const TsdfVoxel, voxels) float3 origin,
                              float3 direction, float t0, float f0, float t1, float f1,
                              float half_voxel, TsdfParams p) {
  float s0 =
      tsdf_field_on_ray(KG_BUFFER_ARG(keys) KG_BUFFER_ARG(slot_blocks) KG_BUFFER_ARG(voxels) origin,
                        direction, t0, p);
  float s1 =
      tsdf_field_on_ray(KG_BUFFER_ARG(keys) KG_BUFFER_ARG(slot_blocks) KG_BUFFER_ARG(voxels) origin,
                        direction, t1, p);
  float u0 = t0, u1 = t1;  // the bracket in the field
  for (uint i = 0u; i < KG_TSDF_CROSSING_MOVES; ++i) {
    const bool beyond = s1 > 0.0f;  // NaN compares false: no move
    const bool before = s0 <= 0.0f;
    if (!beyond && !before) break;
    // Beyond: the far end becomes the near one; before: the near end becomes the far one.
    const float kept = beyond ? s1 : s0;
    const float from = beyond ? u1 : u0;
    const float to = beyond ? u1 + half_voxel : u0 - half_voxel;
    const float moved = tsdf_field_on_ray(KG_BUFFER_ARG(keys) KG_BUFFER_ARG(slot_blocks)
                                              KG_BUFFER_ARG(voxels) origin,
                                          direction, to, p);
    u0 = beyond ? from : to;
    u1 = beyond ? to : from;
    s0 = beyond ? kept : moved;
    s1 = beyond ? moved : kept;
  }
  const bool interpolated = !kg_isnan(s0) && !kg_isnan(s1) && s0 > 0.0f && s1 <= 0.0f;
  if (interpolated) return u0 + (u1 - u0) * s0 / (s0 - s1);
  return t0 + (t1 - t0) * f0 / (f0 - f1);
}

// Pixel (x, y)'s ray from depth min to max (metres along the optical axis): the first surface
// (a change from + to -) as a point in the camera's frame (w = 1); the invalid point where the
// ray meets none, or meets the back of one first.
KG_FORCE_INLINE float4 tsdf_cast_ray(KG_BUFFER_PARAM(const uint64_t, keys)
                                         KG_BUFFER_PARAM(const uint, slot_blocks)
                                             KG_BUFFER_PARAM(const TsdfVoxel, voxels) uint x,
                                     uint y, float min_depth, float max_depth, TsdfParams p) {
  // Along the optical axis: depth t is the ray's parameter.
  const float3 ray_c = KG_FLOAT3((KG_FLOAT(x) - p.cx) / p.fx, (KG_FLOAT(y) - p.cy) / p.fy, 1.0f);
  const float3 direction = tsdf_rotate_to_world(ray_c, p);
  const float3 origin = KG_FLOAT3(p.tx, p.ty, p.tz);
  const float per_depth = sqrt(dot(ray_c, ray_c));  // metres along the ray per unit of depth
  float t = min_depth;
  float previous_t = t;
  float previous = KG_NAN;
  // Consecutive samples mostly fall in one block: its lookup is kept.
  uint64_t cached_key = KG_EMPTY_VOXEL_KEY;
  uint cached_block = KG_TSDF_NO_BLOCK;
  for (uint i = 0u; i < p.step && t <= max_depth; ++i) {
    const float3 w = origin + direction * t;
    if (!tsdf_point_in_range(w, p)) break;
    const float3 g = w * p.inverse_voxel;
    const int vx = KG_INT(floor(g.x)), vy = KG_INT(floor(g.y)), vz = KG_INT(floor(g.z));
    const uint64_t key = tsdf_block_key(vx >> 3, vy >> 3, vz >> 3);
    if (key != cached_key) {
      cached_block = tsdf_find_block(KG_BUFFER_ARG(keys) KG_BUFFER_ARG(slot_blocks) key, p);
      cached_key = key;
    }
    const TsdfVoxel v = tsdf_voxel_in(KG_BUFFER_ARG(voxels) cached_block, vx, vy, vz);
    const bool known = v.weight > 0.0f;
    if (known && v.tsdf <= 0.0f) {
      if (kg_isnan(previous)) break;  // the back of a surface, or inside it from the start
      const float hit = tsdf_crossing(
          KG_BUFFER_ARG(keys) KG_BUFFER_ARG(slot_blocks) KG_BUFFER_ARG(voxels) origin, direction,
          previous_t, previous, t, v.tsdf, 0.5f * p.voxel_size / per_depth, p);
      return KG_FLOAT4(ray_c.x * hit, ray_c.y * hit, hit, 1.0f);
    }
    previous = known ? v.tsdf : KG_NAN;
    previous_t = t;
    // Never past the surface the value promises is at least this far; a voxel at a time near it;
    // out of a missing block at once (no surface lies in it).
    if (v.tsdf == KG_TSDF_NO_BLOCK_VALUE) {
      t = tsdf_block_exit(w, direction, t, p);
    } else {
      const float ahead =
          known ? max(0.8f * v.tsdf * p.truncation, p.voxel_size) : 0.5f * p.truncation;
      t += ahead / per_depth;
    }
  }
  return KG_INVALID_POINT;
}

KG_STRUCT_BEGIN(TsdfDepthSpan)
float near;  // metres along the optical axis; near > far: nothing to search
float far;
KG_STRUCT_END(TsdfDepthSpan)

// The depths pixel (x, y)'s ray searches: its tile's range (the ray cast's shader declares
// ranges too) within min_depth..max_depth.
KG_INLINE TsdfDepthSpan tsdf_ray_span(KG_BUFFER_PARAM(const uint, ranges) uint x, uint y,
                                      float min_depth, float max_depth, TsdfParams p) {
  const uint tile = (y / KG_TSDF_TILE) * tsdf_tile_columns(p) + x / KG_TSDF_TILE;
  const uint far_units = ranges[2u * tile + 1u];
  TsdfDepthSpan span;
  span.near = max(min_depth, KG_FLOAT(0xffffffffu - ranges[2u * tile]) * p.metres_per_unit);
  span.far = far_units == 0u ? -1.0f : min(max_depth, KG_FLOAT(far_units) * p.metres_per_unit);
  return span;
}

// The colour of the voxel at a ray cast's point c (camera frame).
KG_INLINE uint tsdf_color_at(KG_BUFFER_PARAM(const uint64_t, keys)
                                 KG_BUFFER_PARAM(const uint, slot_blocks)
                                     KG_BUFFER_PARAM(const TsdfVoxel, voxels) float4 c,
                             TsdfParams p) {
  if (kg_isnan(c.x)) return 0u;
  return tsdf_nearest(KG_BUFFER_ARG(keys) KG_BUFFER_ARG(slot_blocks) KG_BUFFER_ARG(voxels)
                          tsdf_to_world(kg_xyz(c), p),
                      p)
      .color;
}

#endif

KG_RULES_END

#endif
