// The zero surface of the TSDF on the device (rules in include/kartograf/mapping/tsdf_mesh.hpp:
// marching tetrahedra, 6 per cell around its main diagonal), one work item per cell, the cell
// whose lowest corner is voxel `cell % 512` of pool block `cell / 512`. A cell with every corner
// observed (weight >= min_weight) and corners on both sides of zero appends its triangles: each
// with its 3 vertices (position in metres, colour) and the keys of the edges they lie on, so that
// the host can join the vertices that triangles share, and an order key (cell x 16 + its k-th
// triangle) that gives the host mesher's order. An edge between two truncated values
// (|value| >= max_jump) is a jump, not a surface: its tetrahedron makes no triangle.
#ifndef KARTOGRAF_KERNELS_TSDF_MESH_H
#define KARTOGRAF_KERNELS_TSDF_MESH_H
#include "kernels/tsdf/tsdf.h"
#include "kernels/tsdf/tsdf_voxel.h"

#define KG_TSDF_MESH_VOXEL_BIAS 524288  // 2^19: voxel coordinates an edge key holds each way
// The tetrahedra's middle corners, a nibble each (the first is corner 0, the last corner 7):
// 0-1-3-7, 0-3-2-7, 0-2-6-7, 0-6-4-7, 0-4-5-7, 0-5-1-7.
#define KG_TSDF_MESH_SECOND 0x546231u
#define KG_TSDF_MESH_THIRD 0x154623u
#define KG_TSDF_MESH_FLIP 0x1000000u  // in a triangle's first colour: swap its last two vertices

KG_RULES_BEGIN

KG_PARAMS_BEGIN(TsdfMeshParams)
KG_PARAM(uint, capacity_log2)  // the table's
KG_PARAM(uint, count)          // cells: blocks x 512
KG_PARAM(uint, capacity)       // triangles the outputs hold
KG_PARAM(float, voxel_size)
KG_PARAM(float, min_weight)
KG_PARAM(float, max_jump)
KG_PARAMS_END(TsdfMeshParams)

KG_STRUCT_BEGIN(TsdfMeshCorner)
int x;  // voxel coordinates
int y;
int z;
float value;
float weight;
uint color;
KG_STRUCT_END(TsdfMeshCorner)

KG_STRUCT_BEGIN(TsdfMeshVertex)
float x;  // metres
float y;
float z;
uint color;
uint64_t key;  // its edge: lower end's biased coordinates, then the step to the other end
KG_STRUCT_END(TsdfMeshVertex)

// One colour channel between a and b at t, rounded to the nearest level.
KG_INLINE uint tsdf_mesh_mix(uint a, uint b, uint shift, float t) {
  const float x = KG_FLOAT((a >> shift) & 0xffu), y = KG_FLOAT((b >> shift) & 0xffu);
  return KG_UINT(floor(x + (y - x) * t + 0.5f)) << shift;
}

// The vertex where the surface crosses the edge between corners i and o (of different signs),
// placed from its lower end (the end whose coordinates are all at most the other's).
KG_INLINE TsdfMeshVertex tsdf_mesh_vertex(TsdfMeshCorner i, TsdfMeshCorner o, TsdfMeshParams p) {
  const bool ordered = o.x >= i.x && o.y >= i.y && o.z >= i.z;
  const TsdfMeshCorner a = ordered ? i : o;
  const TsdfMeshCorner b = ordered ? o : i;
  const int sx = b.x - a.x, sy = b.y - a.y, sz = b.z - a.z;
  const float t = a.value / (a.value - b.value);
  TsdfMeshVertex v;
  v.x = (KG_FLOAT(a.x) + t * KG_FLOAT(sx) + 0.5f) * p.voxel_size;
  v.y = (KG_FLOAT(a.y) + t * KG_FLOAT(sy) + 0.5f) * p.voxel_size;
  v.z = (KG_FLOAT(a.z) + t * KG_FLOAT(sz) + 0.5f) * p.voxel_size;
  v.color = tsdf_mesh_mix(a.color, b.color, 0u, t) | tsdf_mesh_mix(a.color, b.color, 8u, t) |
            tsdf_mesh_mix(a.color, b.color, 16u, t);
  const uint64_t bias = KG_UINT64(KG_TSDF_MESH_VOXEL_BIAS);
  v.key =
      (((KG_UINT64(a.x) + bias) | ((KG_UINT64(a.y) + bias) << 20) | ((KG_UINT64(a.z) + bias) << 40))
       << 3) |
      KG_UINT64(sx | (sy << 1) | (sz << 2));
  return v;
}

// Whether the tetrahedron's corner pairs across zero include a jump.
KG_INLINE bool tsdf_mesh_jump(float a, float b, TsdfMeshParams p) {
  return kg_fabs(a) >= p.max_jump && kg_fabs(b) >= p.max_jump;
}

#if !defined(VULKAN) || defined(KG_TSDF_MESH_PASS)
// The shader declares keys, slot_blocks, block_keys, voxels, status, order, edge_keys, points and
// colors.

// Appends the triangle on edges (i0, o0), (i1, o1), (i2, o2) (inside corner, outside corner),
// facing outside, as triangle k of the cell.
KG_INLINE void tsdf_mesh_emit(KG_BUFFER_PARAM(uint, status) KG_BUFFER_PARAM(uint, order)
                                  KG_BUFFER_PARAM(uint64_t, edge_keys)
                                      KG_BUFFER_PARAM(float, points) KG_BUFFER_PARAM(uint, colors)
                                          TsdfMeshVertex v0,
                              TsdfMeshVertex v1, TsdfMeshVertex v2, float3 outward, uint cell,
                              uint k, TsdfMeshParams p) {
  const float3 a = KG_FLOAT3(v0.x, v0.y, v0.z), b = KG_FLOAT3(v1.x, v1.y, v1.z),
               c = KG_FLOAT3(v2.x, v2.y, v2.z);
  // Written in the edges' order, which decides the vertices' numbers; whether the second and
  // third swap to face outside goes in the first colour's top byte.
  const bool flip = dot(cross(b - a, c - a), outward) < 0.0f;
  const TsdfMeshVertex second = v1;
  const TsdfMeshVertex third = v2;
  const uint slot = kg_atomic_add_u32(status, 0u, 1u);
  if (slot >= p.capacity) return;  // the host sees the count and runs again with room
  order[slot] = cell * 16u + k;
  edge_keys[3u * slot] = v0.key;
  edge_keys[3u * slot + 1u] = second.key;
  edge_keys[3u * slot + 2u] = third.key;
  points[9u * slot] = v0.x;
  points[9u * slot + 1u] = v0.y;
  points[9u * slot + 2u] = v0.z;
  points[9u * slot + 3u] = second.x;
  points[9u * slot + 4u] = second.y;
  points[9u * slot + 5u] = second.z;
  points[9u * slot + 6u] = third.x;
  points[9u * slot + 7u] = third.y;
  points[9u * slot + 8u] = third.z;
  colors[3u * slot] = v0.color | (flip ? KG_TSDF_MESH_FLIP : 0u);
  colors[3u * slot + 1u] = second.color;
  colors[3u * slot + 2u] = third.color;
}

// Corner c (offset c & 1, c >> 1 & 1, c >> 2 & 1 from the cell's lowest voxel) of the cell; weight
// -1 where no block holds it.
KG_INLINE TsdfMeshCorner tsdf_mesh_corner(KG_BUFFER_PARAM(const uint64_t, keys)
                                              KG_BUFFER_PARAM(const uint, slot_blocks)
                                                  KG_BUFFER_PARAM(const TsdfVoxel, voxels)
                                                      uint64_t key,
                                          uint block, uint in_block, uint c, TsdfMeshParams p) {
  const int lx = KG_INT(in_block & 7u) + KG_INT(c & 1u);
  const int ly = KG_INT((in_block >> 3u) & 7u) + KG_INT((c >> 1u) & 1u);
  const int lz = KG_INT(in_block >> 6u) + KG_INT(c >> 2u);
  const int bx = tsdf_key_axis(key, 0u), by = tsdf_key_axis(key, 21u), bz = tsdf_key_axis(key, 42u);
  uint owner = block;
  if (lx > 7 || ly > 7 || lz > 7) {
    const int slot = voxel_find_key(
        KG_BUFFER_ARG(keys) tsdf_block_key(bx + (lx >> 3), by + (ly >> 3), bz + (lz >> 3)),
        p.capacity_log2);
    owner = slot < 0 ? KG_TSDF_NO_BLOCK : slot_blocks[slot];
  }
  TsdfMeshCorner corner;
  corner.x = bx * KG_TSDF_BLOCK_SIDE + lx;
  corner.y = by * KG_TSDF_BLOCK_SIDE + ly;
  corner.z = bz * KG_TSDF_BLOCK_SIDE + lz;
  corner.value = 0.0f;
  corner.weight = -1.0f;
  corner.color = 0u;
  if (owner == KG_TSDF_NO_BLOCK) return corner;
  const TsdfVoxel v = voxels[owner * KG_TSDF_BLOCK_VOXELS + tsdf_local_index(lx, ly, lz)];
  corner.value = v.tsdf;
  corner.weight = v.weight;
  corner.color = v.color;
  return corner;
}

// The cell's triangles, appended (at most 12: 2 per tetrahedron).
KG_FORCE_INLINE void tsdf_mesh_cell(
    KG_BUFFER_PARAM(const uint64_t, keys) KG_BUFFER_PARAM(const uint, slot_blocks)
        KG_BUFFER_PARAM(const uint64_t, block_keys) KG_BUFFER_PARAM(const TsdfVoxel, voxels)
            KG_BUFFER_PARAM(uint, status) KG_BUFFER_PARAM(uint, order)
                KG_BUFFER_PARAM(uint64_t, edge_keys) KG_BUFFER_PARAM(float, points)
                    KG_BUFFER_PARAM(uint, colors) uint cell,
    TsdfMeshParams p) {
  const uint block = cell / KG_TSDF_BLOCK_VOXELS, in_block = cell % KG_TSDF_BLOCK_VOXELS;
  const uint64_t key = block_keys[block];
  TsdfMeshCorner corners[8];
  bool inside = false, outside = false;
  for (uint c = 0u; c < 8u; ++c) {
    corners[c] =
        tsdf_mesh_corner(KG_BUFFER_ARG(keys) KG_BUFFER_ARG(slot_blocks) KG_BUFFER_ARG(voxels) key,
                         block, in_block, c, p);
    if (corners[c].weight < 0.0f) return;  // no block holds it
    inside = inside || corners[c].value < 0.0f;
    outside = outside || !(corners[c].value < 0.0f);
  }
  if (!inside || !outside) return;
  for (uint c = 0u; c < 8u; ++c)
    if (corners[c].weight < p.min_weight) return;
  uint k = 0u;
  for (uint t = 0u; t < 6u; ++t) {
    const uint tet = (((KG_TSDF_MESH_SECOND >> (4u * t)) & 15u) << 4u) |
                     (((KG_TSDF_MESH_THIRD >> (4u * t)) & 15u) << 8u) | (7u << 12u);
    uint ins = 0u, outs = 0u, n_in = 0u, n_out = 0u;  // corner numbers, a nibble each
    for (uint i = 0u; i < 4u; ++i) {
      const uint c = (tet >> (4u * i)) & 15u;
      if (corners[c].value < 0.0f) {
        ins |= c << (4u * n_in);
        ++n_in;
      } else {
        outs |= c << (4u * n_out);
        ++n_out;
      }
    }
    if (n_in == 0u || n_out == 0u) continue;
    bool jump = false;
    for (uint i = 0u; i < n_in; ++i)
      for (uint o = 0u; o < n_out; ++o)
        jump = jump || tsdf_mesh_jump(corners[(ins >> (4u * i)) & 15u].value,
                                      corners[(outs >> (4u * o)) & 15u].value, p);
    if (jump) continue;
    const TsdfMeshCorner i0 = corners[ins & 15u], i1 = corners[(ins >> 4u) & 15u],
                         i2 = corners[(ins >> 8u) & 15u];
    const TsdfMeshCorner o0 = corners[outs & 15u], o1 = corners[(outs >> 4u) & 15u],
                         o2 = corners[(outs >> 8u) & 15u];
    const float3 outward =
        KG_FLOAT3(KG_FLOAT(o0.x - i0.x), KG_FLOAT(o0.y - i0.y), KG_FLOAT(o0.z - i0.z));
    const TsdfMeshVertex first = tsdf_mesh_vertex(i0, o0, p);
    if (n_in == 1u || n_out == 1u) {
      const bool lone_inside = n_in == 1u;
      tsdf_mesh_emit(KG_BUFFER_ARG(status) KG_BUFFER_ARG(order) KG_BUFFER_ARG(edge_keys)
                         KG_BUFFER_ARG(points) KG_BUFFER_ARG(colors) first,
                     tsdf_mesh_vertex(lone_inside ? i0 : i1, lone_inside ? o1 : o0, p),
                     tsdf_mesh_vertex(lone_inside ? i0 : i2, lone_inside ? o2 : o0, p), outward,
                     cell, k, p);
      ++k;
      continue;
    }
    const TsdfMeshVertex across = tsdf_mesh_vertex(i1, o1, p);
    tsdf_mesh_emit(KG_BUFFER_ARG(status) KG_BUFFER_ARG(order) KG_BUFFER_ARG(edge_keys)
                       KG_BUFFER_ARG(points) KG_BUFFER_ARG(colors) first,
                   tsdf_mesh_vertex(i0, o1, p), across, outward, cell, k, p);
    tsdf_mesh_emit(KG_BUFFER_ARG(status) KG_BUFFER_ARG(order) KG_BUFFER_ARG(edge_keys)
                       KG_BUFFER_ARG(points) KG_BUFFER_ARG(colors) first,
                   across, tsdf_mesh_vertex(i1, o0, p), outward, cell, k + 1u, p);
    k += 2u;
  }
}

#endif

KG_RULES_END

#endif
