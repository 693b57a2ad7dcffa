#include "frame_ops.hpp"

#include "kartograf/compute/buffer.hpp"
#include "kartograf/geometry/backproject.hpp"
#include "kartograf/geometry/normals.hpp"
#include "kartograf/geometry/segment_moments.hpp"
#include "kartograf/geometry/subsample.hpp"
#include "kartograf/geometry/voxel_downsample.hpp"
#include "kartograf/mapping/esdf_volume.hpp"
#include "kartograf/mapping/tsdf_mesh.hpp"
#include "kartograf/mapping/tsdf_slice.hpp"
#include "kartograf/mapping/tsdf_volume.hpp"
#include "kartograf/registration/color_gate.hpp"
#include "kartograf/registration/frame_pyramid.hpp"
#include "kartograf/registration/icp.hpp"
#include "kartograf/registration/icp_sums.hpp"
#include "kartograf/registration/projective_association.hpp"
#include "kartograf/registration/voxel_hash_correspondences.hpp"
#include "kartograf/segmentation/lab_color.hpp"
#include "kartograf/segmentation/plane_extraction.hpp"
#include "kartograf/segmentation/region_growing.hpp"

namespace kartograf::gpu_check {

struct Workspace {
  Workspace(const compute::Context& context, const FrameSet& frames)
      : context(context),
        frames(frames),
        projector(context, frames.camera, geometry::DepthRange{}),
        depth(context, frames.camera.width, frames.camera.height),
        points(context, frames.camera.width, frames.camera.height),
        normals(context, frames.camera.width, frames.camera.height),
        pyramids{registration::FramePyramid(context, frames.camera),
                 registration::FramePyramid(context, frames.camera)},
        reduction(context),
        association(context),
        engine(context),
        moments(context),
        downsampler(context),
        gate(context),
        hash(context),
        grower(context),
        cell_planes(context, frames.camera, cells_mode()),
        tsdf_fine(context, tsdf_params(0.01)),
        tsdf_coarse(context, tsdf_params(0.05)),
        esdf_fine(context, tsdf_params(0.01)) {}

  static segmentation::PlaneExtractionParams cells_mode() {
    segmentation::PlaneExtractionParams params;
    params.mode = segmentation::PlaneExtractionMode::cells;
    return params;
  }

  static mapping::TsdfVolumeParams tsdf_params(double voxel) {
    mapping::TsdfVolumeParams params;
    params.voxel_size = voxel;
    params.truncation = 4 * voxel;
    return params;
  }

  const RgbdFrame& next_frame() { return frames.frames[next++ % frames.frames.size()]; }
  registration::FramePyramid& reference() { return pyramids[reference_index]; }
  registration::FramePyramid& current() { return pyramids[1 - reference_index]; }
  registration::Correspondences pairs();  // current level 0 -> reference level 0, associated

  const compute::Context& context;
  const FrameSet& frames;
  std::size_t next = 0;
  geometry::DepthBackprojector projector;
  compute::DeviceImage<std::uint16_t> depth;
  compute::DeviceImage<Point4f> points, normals;
  registration::FramePyramid pyramids[2];
  int reference_index = 0;
  registration::IcpReduction reduction;
  registration::ProjectiveAssociation association;
  registration::CorrespondenceBuffers association_out;
  registration::Correspondences associated;  // pairs() of the set-up, for the sums alone
  registration::IcpEngine engine;
  compute::Buffer<std::uint32_t> labels;  // 16x16 tiles: one segment per tile
  std::uint32_t label_count = 0;
  geometry::SegmentMomentReducer moments;
  geometry::VoxelDownsampler downsampler;
  geometry::DeviceCloud cloud;  // level 0 of the current pyramid as an unorganized cloud
  registration::ColorGate gate;
  compute::Buffer<std::uint32_t> current_colors, reference_colors;  // packed, frames 1 and 0
  compute::Buffer<std::int32_t> gated;  // a copy of the association's pairs, gated in place
  registration::VoxelHashCorrespondences hash;
  registration::CorrespondenceBuffers hash_out;
  segmentation::RegionGrower grower;
  segmentation::LabCodeImage lab;          // of frame 1
  compute::Buffer<Point4f> frame1_points;  // frame 1 back-projected, for the region growing
  PointImage frame1_host_points;           // the same on the host, for the plane extraction
  segmentation::PlaneExtractor cell_planes;
  // TSDFs of 1 and 5 cm voxels. The poses are unknown here: the first frame is fused again and
  // again at the identity, so the block set stays that of one frame (the steady state of a
  // camera at rest).
  mapping::TsdfVolume tsdf_fine, tsdf_coarse;
  mapping::EsdfVolume esdf_fine;  // of tsdf_fine
  compute::DeviceImage<std::uint16_t> tsdf_depth;
  compute::DeviceImage<Point4f> cast;
};

namespace {

// The true relative pose is unknown here; a small motion keeps the association realistic.
const Eigen::Isometry3d kSmallMotion =
    Eigen::Translation3d(0.01, -0.005, 0.0) * Eigen::AngleAxisd(0.01, Eigen::Vector3d::UnitY());

compute::Buffer<std::uint32_t> tile_labels(const compute::Context& context, int width, int height,
                                           std::uint32_t& count) {
  const int tiles_x = (width + 15) / 16;
  std::vector<std::uint32_t> labels(static_cast<std::size_t>(width) * height);
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) labels[v * width + u] = (v / 16) * tiles_x + u / 16;
  }
  count = static_cast<std::uint32_t>(tiles_x * ((height + 15) / 16));
  return compute::Buffer<std::uint32_t>::from_host(context, labels);
}

compute::Buffer<std::uint32_t> packed_colors(const compute::Context& context, const RgbImage& rgb) {
  std::vector<std::uint32_t> packed(rgb.size());
  for (std::size_t i = 0; i < rgb.size(); ++i) packed[i] = pack_rgb(rgb.data()[i]);
  return compute::Buffer<std::uint32_t>::from_host(context, packed);
}

// The view without its camera: an unorganized cloud, the voxel-hash finder's input.
registration::CloudView unorganized(const registration::CloudView& view) {
  registration::CloudView result = view;
  result.camera.reset();
  return result;
}

void gate_colours(Workspace& w) {
  w.gated.raw().copy_from(w.association_out.target_index.raw(),
                          w.association_out.target_index.raw().size_bytes());
  w.gate.apply(w.current_colors, w.reference_colors, w.gated);
}

void voxel_hash_nearest(Workspace& w) {
  const registration::CloudView target = unorganized(w.reference().level(0).view());
  w.hash.prepare(target, 0);
  registration::AssociationParams params;
  params.max_distance = 0.05;
  params.subsample = 4;
  w.hash.find(unorganized(w.current().level(0).view()), target, kSmallMotion, params, w.hash_out);
}

// The first frame, fused once into both volumes before the TSDF operations are timed (not at
// set-up: the random frames, which only the per-pixel operations time, would fill any pool).
void ensure_tsdf(Workspace& w) {
  if (w.tsdf_depth.size() > 0) return;
  w.tsdf_depth =
      compute::DeviceImage<std::uint16_t>::from_host(w.context, w.frames.frames[0].depth);
  for (mapping::TsdfVolume* volume : {&w.tsdf_fine, &w.tsdf_coarse}) {
    volume->integrate(w.tsdf_depth, &w.current_colors, w.frames.camera, geometry::DepthRange{},
                      Eigen::Isometry3d::Identity());
  }
}

void integrate(Workspace& w, mapping::TsdfVolume& volume) {
  ensure_tsdf(w);
  volume.integrate(w.tsdf_depth, &w.current_colors, w.frames.camera, geometry::DepthRange{},
                   Eigen::Isometry3d::Identity());
}

void ray_cast(Workspace& w, const mapping::TsdfVolume& volume) {
  ensure_tsdf(w);
  volume.raycast(w.frames.camera, geometry::DepthRange{}, Eigen::Isometry3d::Identity(), w.cast);
}

// The height band's occupancy on the device (the camera's frame turned so that -y is up), and
// with `esdf` its ESDF there too.
void band_occupancy(Workspace& w, const mapping::TsdfVolume& volume, bool esdf) {
  ensure_tsdf(w);
  mapping::TsdfSliceParams params;
  params.world_to_level.linear() =
      Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitX()).toRotationMatrix();
  if (esdf)
    mapping::tsdf_band_maps(volume, params);
  else
    mapping::tsdf_occupancy(volume, params);
}

// The volume's mesh made on the device and joined on the host.
void mesh(Workspace& w, const mapping::TsdfVolume& volume) {
  ensure_tsdf(w);
  mapping::extract_mesh(volume);
}

void build_current(Workspace& w) {
  w.depth.upload(w.next_frame().depth);
  w.current().build(w.projector, w.depth);
}

}  // namespace

registration::Correspondences Workspace::pairs() {
  const registration::CloudView source = current().level(0).view();
  const registration::CloudView target = reference().level(0).view();
  association.find(source, target, kSmallMotion, registration::AssociationParams{},
                   association_out);
  registration::Correspondences result;
  result.source = source.points;
  result.target = target.points;
  result.target_normals = target.normals;
  result.correspondences = &association_out.target_index;
  result.source_to_target = kSmallMotion;
  result.max_distance = 0.1;
  return result;
}

std::shared_ptr<Workspace> make_workspace(const compute::Context& context, const FrameSet& frames) {
  auto w = std::make_shared<Workspace>(context, frames);
  w->labels = tile_labels(context, frames.camera.width, frames.camera.height, w->label_count);
  w->depth.upload(w->next_frame().depth);
  w->reference().build(w->projector, w->depth);
  build_current(*w);
  w->projector.run(w->depth, w->points);
  geometry::estimate_normals(context, w->points, w->normals);
  const compute::Buffer<Point4f>& level0 = w->current().level(0).points.buffer();
  w->cloud.points = compute::Buffer<Point4f>(context, level0.size());
  w->cloud.points.raw().copy_from(level0.raw(), level0.raw().size_bytes());
  w->associated = w->pairs();
  w->reference_colors = packed_colors(context, frames.frames[0].color);
  w->current_colors = packed_colors(context, frames.frames[1 % frames.frames.size()].color);
  w->gated = compute::Buffer<std::int32_t>(context, w->association_out.target_index.size());
  w->lab = segmentation::to_lab_codes(frames.frames[1 % frames.frames.size()].color);
  w->frame1_points = compute::Buffer<Point4f>(context, w->points.size());
  w->frame1_points.raw().copy_from(w->points.buffer().raw(), w->points.buffer().raw().size_bytes());
  w->frame1_host_points = w->points.to_image();
  context.finish();
  return w;
}

const std::vector<Operation>& frame_operations() {
  static const std::vector<Operation> list = {
      {"upload depth", 0, [](Workspace& w) { w.depth.upload(w.next_frame().depth); }},
      {"backproject", 2 + 16, [](Workspace& w) { w.projector.run(w.depth, w.points); }},
      {"normals", 16 + 16,
       [](Workspace& w) { geometry::estimate_normals(w.context, w.points, w.normals); }},
      {"pyramid (normals + 2 levels)", 52, [](Workspace& w) { w.current().build(); }},
      {"backproject + normals + pyramid", 70,
       [](Workspace& w) { w.current().build(w.projector, w.depth); }},
      {"projective association", 16 + 16 + 4, [](Workspace& w) { w.pairs(); }},
      {"point-to-plane sums", 16 + 16 + 16 + 4,
       [](Workspace& w) { w.reduction.point_to_plane(w.associated, Eigen::Vector3d(0, 0, 2)); }},
      {"point-to-point sums", 16 + 16 + 4,
       [](Workspace& w) { w.reduction.point_to_point(w.associated, Eigen::Vector3d(0, 0, 2)); }},
      {"ICP align (3 levels)", 0, [](Workspace& w) { w.engine.align(w.current(), w.reference()); }},
      {"frame-to-frame odometry", 0,
       [](Workspace& w) {
         build_current(w);
         w.engine.align(w.current(), w.reference());
         w.reference_index = 1 - w.reference_index;
       }},
      {"segment moments", 16 + 4,
       [](Workspace& w) {
         geometry::SegmentMomentParams params;
         params.label_count = w.label_count;
         params.origin = Eigen::Vector3f(0, 0, 2);
         w.moments.run(w.points.buffer(), w.labels, params);
       }},
      {"subsample 1 in 4", 16 + 4,
       [](Workspace& w) { geometry::subsample(w.context, w.cloud, 4); }},
      {"voxel downsample 5 cm", 0,
       [](Workspace& w) { w.downsampler.run(w.cloud, geometry::VoxelDownsampleParams{}); }},
      {"colour gate (HSI)", 0, gate_colours},
      {"voxel-hash build + nearest", 0, voxel_hash_nearest},
      {"TSDF integrate 1 cm", 0, [](Workspace& w) { integrate(w, w.tsdf_fine); }},
      {"TSDF ray cast 1 cm", 0, [](Workspace& w) { ray_cast(w, w.tsdf_fine); }},
      {"TSDF integrate 5 cm", 0, [](Workspace& w) { integrate(w, w.tsdf_coarse); }},
      {"TSDF ray cast 5 cm", 0, [](Workspace& w) { ray_cast(w, w.tsdf_coarse); }},
      {"TSDF band occupancy 1 cm", 0, [](Workspace& w) { band_occupancy(w, w.tsdf_fine, false); }},
      {"TSDF band + ESDF 1 cm", 0, [](Workspace& w) { band_occupancy(w, w.tsdf_fine, true); }},
      {"TSDF mesh 1 cm", 0, [](Workspace& w) { mesh(w, w.tsdf_fine); }},
      {"TSDF integrate + 3-D ESDF update 1 cm", 0,
       [](Workspace& w) {
         integrate(w, w.tsdf_fine);
         w.esdf_fine.update(w.tsdf_fine);
       }},
      {"region growing (Lab)", 0,
       [](Workspace& w) {
         w.grower.grow(w.lab, w.frame1_points, segmentation::RegionGrowingParams{});
       }},
      // The whole extraction from host images: upload, the block pass here, the rest on the host.
      {"plane extraction, cells mode", 0,
       [](Workspace& w) {
         w.cell_planes.extract(w.frame1_host_points,
                               w.frames.frames[1 % w.frames.frames.size()].color);
       }},
  };
  return list;
}

}  // namespace kartograf::gpu_check
