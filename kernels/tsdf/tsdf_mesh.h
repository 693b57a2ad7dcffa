// The zero surface of the TSDF on the device (rules in include/kartograf/mapping/tsdf_mesh.hpp:
// marching cubes, its triangles from tsdf_mc_triangles below), one work item per cell, the cell
// whose lowest corner is voxel `cell % 512` of pool block `cell / 512`. A cell with every corner
// observed (weight >= min_weight) and corners on both sides of zero appends its triangles: each
// with its 3 vertices (position in metres, colour) and the keys of the edges they lie on, so that
// the host can join the vertices that triangles share, and an order key (cell x 16 + its k-th
// triangle) that gives the host mesher's order. A triangle with a vertex on an edge between two
// truncated values (|value| >= max_jump) lies on a jump, not a surface, and is left out.
#ifndef KARTOGRAF_KERNELS_TSDF_MESH_H
#define KARTOGRAF_KERNELS_TSDF_MESH_H
#include "kernels/tsdf/tsdf.h"
#include "kernels/tsdf/tsdf_voxel.h"

#define KG_TSDF_MESH_VOXEL_BIAS 524288  // 2^19: voxel coordinates an edge key holds each way
#define KG_TSDF_MC_NONE 15u             // no edge: after a case's last triangle

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

// Marching cubes. Corner c of a cell is at offset (c & 1, c >> 1 & 1, c >> 2 & 1) from its lowest
// voxel; edge e (0-11) is the (e % 4)-th edge along axis e / 4, counted by its lower corner.

// The lower corner of edge e; the upper one is that plus 1 << (e / 4).
KG_INLINE uint tsdf_mc_edge_lower(uint e) {
  const uint axis = e / 4u, k = e % 4u;
  return ((k >> axis) << (axis + 1u)) | (k & ((1u << axis) - 1u));
}

// The edge between corners a and b (which differ in one bit).
KG_INLINE uint tsdf_mc_edge(uint a, uint b) {
  const uint lower = min(a, b), bit = a ^ b;
  const uint axis = bit == 1u ? 0u : (bit == 2u ? 1u : 2u);
  return 4u * axis + (((lower >> (axis + 1u)) << axis) | (lower & ((1u << axis) - 1u)));
}

// Corner i (0-3, counter-clockwise seen from outside the cell) of face f (0-5: axis f / 2, low
// side for even f).
KG_INLINE uint tsdf_mc_face_corner(uint f, uint i) {
  const uint axis = f / 2u, u = 1u << ((axis + 1u) % 3u), v = 1u << ((axis + 2u) % 3u);
  const uint j = f % 2u == 1u ? i : 3u - i;  // the low side is seen from the other way
  const uint base = (f % 2u) << axis;
  return base | (j == 1u || j == 2u ? u : 0u) | (j >= 2u ? v : 0u);
}

// The triangles of the cell whose corners below zero are the bits of `inside`: edge numbers a
// nibble each, 3 per triangle, then KG_TSDF_MC_NONE (at most 5 triangles). On each face the
// surface separates every run of inside corners (along the face's boundary) from the rest: two
// inside corners on a diagonal are kept apart. The rule sees only the face's own corners, so
// the two cells that share a face cut it alike and the surface has no cracks. Each run gives a
// segment from the edge where the boundary leaves it to the edge where it enters it, so that
// the inside lies on its left seen from outside the cell; the segments join into loops, each cut
// into a fan of triangles that faces the + side.
KG_INLINE uint64_t tsdf_mc_triangles(uint inside) {
  uint next[12];
  for (uint e = 0u; e < 12u; ++e) next[e] = KG_TSDF_MC_NONE;
  for (uint f = 0u; f < 6u; ++f) {
    for (uint i = 0u; i < 4u; ++i) {
      const uint c = tsdf_mc_face_corner(f, i), before = tsdf_mc_face_corner(f, (i + 3u) % 4u);
      if (((inside >> c) & 1u) == 0u || ((inside >> before) & 1u) != 0u) continue;
      uint last = i;  // the run's last corner; `before` is outside, so the walk ends
      while (((inside >> tsdf_mc_face_corner(f, (last + 1u) % 4u)) & 1u) != 0u)
        last = (last + 1u) % 4u;
      next[tsdf_mc_edge(tsdf_mc_face_corner(f, last), tsdf_mc_face_corner(f, (last + 1u) % 4u))] =
          tsdf_mc_edge(before, c);
    }
  }
  uint64_t triangles = ~KG_UINT64(0);
  uint count = 0u, seen = 0u;
  for (uint first = 0u; first < 12u; ++first) {
    if (next[first] == KG_TSDF_MC_NONE || ((seen >> first) & 1u) != 0u) continue;
    uint previous = next[first];
    seen |= (1u << first) | (1u << previous);
    for (uint current = next[previous]; current != first; current = next[current]) {
      const uint64_t triangle = KG_UINT64(first | (current << 4u) | (previous << 8u));
      triangles &= ~(KG_UINT64(0xfffu) << (12u * count));
      triangles |= triangle << (12u * count);
      ++count;
      seen |= 1u << current;
      previous = current;
    }
  }
  return triangles;
}

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

// Whether the edge between two corners across zero is a jump (both values truncated).
KG_INLINE bool tsdf_mesh_jump(float a, float b, TsdfMeshParams p) {
  return kg_fabs(a) >= p.max_jump && kg_fabs(b) >= p.max_jump;
}

#if !defined(VULKAN) || defined(KG_TSDF_MESH_PASS)
// The shader declares keys, slot_blocks, block_keys, voxels, status, order, edge_keys, points and
// colors.

// Appends the triangle (v0, v1, v2) as triangle k of the cell.
KG_INLINE void tsdf_mesh_emit(KG_BUFFER_PARAM(uint, status) KG_BUFFER_PARAM(uint, order)
                                  KG_BUFFER_PARAM(uint64_t, edge_keys)
                                      KG_BUFFER_PARAM(float, points) KG_BUFFER_PARAM(uint, colors)
                                          TsdfMeshVertex v0,
                              TsdfMeshVertex v1, TsdfMeshVertex v2, uint cell, uint k,
                              TsdfMeshParams p) {
  const uint slot = kg_atomic_add_u32(status, 0u, 1u);
  if (slot >= p.capacity) return;  // the host sees the count and runs again with room
  order[slot] = cell * 16u + k;
  edge_keys[3u * slot] = v0.key;
  edge_keys[3u * slot + 1u] = v1.key;
  edge_keys[3u * slot + 2u] = v2.key;
  points[9u * slot] = v0.x;
  points[9u * slot + 1u] = v0.y;
  points[9u * slot + 2u] = v0.z;
  points[9u * slot + 3u] = v1.x;
  points[9u * slot + 4u] = v1.y;
  points[9u * slot + 5u] = v1.z;
  points[9u * slot + 6u] = v2.x;
  points[9u * slot + 7u] = v2.y;
  points[9u * slot + 8u] = v2.z;
  colors[3u * slot] = v0.color;
  colors[3u * slot + 1u] = v1.color;
  colors[3u * slot + 2u] = v2.color;
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

// The cell's triangles, appended (at most 5).
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
  uint inside = 0u;
  for (uint c = 0u; c < 8u; ++c) {
    corners[c] =
        tsdf_mesh_corner(KG_BUFFER_ARG(keys) KG_BUFFER_ARG(slot_blocks) KG_BUFFER_ARG(voxels) key,
                         block, in_block, c, p);
    if (corners[c].weight < 0.0f) return;  // no block holds it
    if (corners[c].value < 0.0f) inside |= 1u << c;
  }
  if (inside == 0u || inside == 255u) return;
  for (uint c = 0u; c < 8u; ++c)
    if (corners[c].weight < p.min_weight) return;
  const uint64_t triangles = tsdf_mc_triangles(inside);
  for (uint k = 0u; k < 5u; ++k) {
    const uint t = KG_UINT((triangles >> (12u * k)) & KG_UINT64(0xfffu));
    if ((t & 15u) == KG_TSDF_MC_NONE) break;
    const uint e0 = t & 15u, e1 = (t >> 4u) & 15u, e2 = (t >> 8u) & 15u;
    const uint a0 = tsdf_mc_edge_lower(e0), a1 = tsdf_mc_edge_lower(e1),
               a2 = tsdf_mc_edge_lower(e2);
    const uint b0 = a0 | (1u << (e0 / 4u)), b1 = a1 | (1u << (e1 / 4u)),
               b2 = a2 | (1u << (e2 / 4u));
    if (tsdf_mesh_jump(corners[a0].value, corners[b0].value, p) ||
        tsdf_mesh_jump(corners[a1].value, corners[b1].value, p) ||
        tsdf_mesh_jump(corners[a2].value, corners[b2].value, p))
      continue;
    tsdf_mesh_emit(KG_BUFFER_ARG(status) KG_BUFFER_ARG(order) KG_BUFFER_ARG(edge_keys)
                       KG_BUFFER_ARG(points) KG_BUFFER_ARG(colors)
                           tsdf_mesh_vertex(corners[a0], corners[b0], p),
                   tsdf_mesh_vertex(corners[a1], corners[b1], p),
                   tsdf_mesh_vertex(corners[a2], corners[b2], p), cell, k, p);
  }
}

#endif

KG_RULES_END

#endif
