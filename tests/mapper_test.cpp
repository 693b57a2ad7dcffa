// The online mapper (pipeline/mapper.hpp) on rendered sequences: frame by frame it gives the batch
// SLAM's poses, its TSDF stays inside its block budget by evicting what is far from the camera,
// its mesh lies on the true surfaces, and misuse is an Error. Plus the frame store it keeps frames
// in (mapping/frame_store.hpp).
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "kartograf/core/error.hpp"
#include "kartograf/mapping/esdf_volume.hpp"
#include "kartograf/mapping/frame_store.hpp"
#include "kartograf/mapping/slam.hpp"
#include "kartograf/pipeline/mapper.hpp"
#include "kartograf/synth/trajectory.hpp"
#include "rgbd_test_sequence.hpp"
#include "test_support_core.hpp"

namespace kartograf {
namespace {

// Every 4th frame of the first 400 of the survey, without noise: it crosses several rooms.
const testing::RenderedSequence& survey_walk() {
  static const testing::RenderedSequence sequence = testing::render_sequence(
      testing::survey_poses(testing::test_world(), 0, 100, 4), testing::qvga_kinect(), false);
  return sequence;
}

pipeline::MapperParams loop_params() {
  pipeline::MapperParams params;
  params.pipeline.features = false;
  params.pipeline.slam.loops.min_frame_gap = 20;
  return params;
}

std::vector<pipeline::MapperStep> feed(pipeline::Mapper& mapper,
                                       const testing::RenderedSequence& sequence, bool with_truth) {
  std::vector<pipeline::MapperStep> steps;
  for (std::size_t i = 0; i < sequence.frames.size(); ++i) {
    steps.push_back(mapper.add_frame(sequence.frames[i],
                                     with_truth ? std::optional(sequence.truth[i]) : std::nullopt));
  }
  return steps;
}

TEST(Mapper, GivesTheBatchSlamPosesFrameByFrame) {
  const compute::Context cpu = compute::Context::cpu();
  const pipeline::MapperParams params = loop_params();
  const testing::MemoryFrameSource source(testing::out_and_back());
  mapping::SlamParams batch_params = params.pipeline.slam;
  batch_params.build_map = false;
  const mapping::SlamResult batch = mapping::run_slam(cpu, source, batch_params);

  pipeline::Mapper mapper(cpu, source.camera(), source.depth_units_per_metre(), params);
  const std::vector<pipeline::MapperStep> steps = feed(mapper, testing::out_and_back(), false);
  bool moved = false;
  for (std::size_t i = 0; i < steps.size(); ++i) {
    EXPECT_EQ(steps[i].frame, i);
    EXPECT_NE(steps[i].status, pipeline::FrameStatus::given);
    EXPECT_TRUE(steps[i].pose.matrix().isApprox(batch.odometry.poses[i].matrix(), 0.05) ||
                steps[i].poses_moved || moved)
        << "frame " << i << ": the step's pose is not the tracking's";
    moved = moved || steps[i].poses_moved;
  }
  EXPECT_TRUE(moved) << "no loop closure moved the poses: the sequence tests less than it should";
  ASSERT_EQ(mapper.poses().size(), batch.poses.size());
  const pipeline::MapPipelineResult result = mapper.finish();
  ASSERT_EQ(result.slam.poses.size(), batch.poses.size());
  for (std::size_t i = 0; i < batch.poses.size(); ++i)
    EXPECT_TRUE(result.slam.poses[i].isApprox(batch.poses[i], 1e-12)) << "frame " << i;
  EXPECT_EQ(result.slam.loop_closures.size(), batch.loop_closures.size());
  EXPECT_GE(result.volume.refusions, 1u);  // the final poses were fused again
  EXPECT_FALSE(result.mesh.triangles.empty());
  EXPECT_EQ(result.mesh.vertices.size(), result.map.size());
  EXPECT_GT(result.volume.keyframe_memory_bytes, 0u);
  EXPECT_EQ(result.volume.keyframe_disk_bytes, 0u);
}

// With no memory for the keyframes (their depth, samples and features all in temporary files)
// the mapper finds the same loops and gives the same poses.
TEST(Mapper, KeyframesKeptOnDiskGiveTheSamePoses) {
  const compute::Context cpu = compute::Context::cpu();
  pipeline::MapperParams params = loop_params();
  params.pipeline.features = true;
  pipeline::MapperParams on_disk = params;
  on_disk.pipeline.slam.loops.keyframe_depth_memory = 0;
  on_disk.pipeline.slam.loops.keyframe_feature_memory = 0;
  const testing::MemoryFrameSource source(testing::out_and_back());
  pipeline::Mapper kept(cpu, source.camera(), source.depth_units_per_metre(), params);
  pipeline::Mapper spilled(cpu, source.camera(), source.depth_units_per_metre(), on_disk);
  feed(kept, testing::out_and_back(), false);
  feed(spilled, testing::out_and_back(), false);
  const pipeline::VolumeStats stats = spilled.volume_stats();
  EXPECT_EQ(stats.keyframe_memory_bytes, 0u);
  EXPECT_GT(stats.keyframe_disk_bytes, 0u);
  const mapping::SlamResult a = kept.finish().slam, b = spilled.finish().slam;
  ASSERT_FALSE(a.loop_closures.empty());
  EXPECT_EQ(b.loop_closures.size(), a.loop_closures.size());
  ASSERT_EQ(b.poses.size(), a.poses.size());
  for (std::size_t i = 0; i < a.poses.size(); ++i)
    EXPECT_TRUE(b.poses[i].matrix() == a.poses[i].matrix()) << "frame " << i;
}

// With frame-to-model tracking the mapper still gives the batch SLAM's poses (and so its
// odometry is the model's).
TEST(Mapper, WithModelTrackingGivesTheBatchSlamPoses) {
  const compute::Context cpu = compute::Context::cpu();
  pipeline::MapperParams params = loop_params();
  params.pipeline.slam.model.enabled = true;
  const testing::MemoryFrameSource source(testing::out_and_back());
  mapping::SlamParams batch_params = params.pipeline.slam;
  batch_params.build_map = false;
  const mapping::SlamResult batch = mapping::run_slam(cpu, source, batch_params);
  ASSERT_TRUE(batch.odometry.model_tracking);

  pipeline::Mapper mapper(cpu, source.camera(), source.depth_units_per_metre(), params);
  feed(mapper, testing::out_and_back(), false);
  const pipeline::MapPipelineResult result = mapper.finish();
  EXPECT_TRUE(result.slam.odometry.model_tracking);
  EXPECT_EQ(result.slam.odometry.model_kept, batch.odometry.model_kept);
  ASSERT_EQ(result.slam.poses.size(), batch.poses.size());
  for (std::size_t i = 0; i < batch.poses.size(); ++i)
    EXPECT_TRUE(result.slam.poses[i].isApprox(batch.poses[i], 1e-12)) << "frame " << i;
}

// A budget of 1000 blocks (4 cm voxels: about 100 m^2 of surface) on a walk through several rooms:
// the volume evicts, never holds more than its budget, and keeps what is around the camera.
TEST(Mapper, EvictsFarBlocksWithinItsBudget) {
  const compute::Context cpu = compute::Context::cpu();
  pipeline::MapperParams params;
  params.volume.max_blocks = 1000;
  params.keep_radius_m = 3;
  const testing::RenderedSequence& walk = survey_walk();
  pipeline::Mapper mapper(cpu, walk.camera, testing::kSynthUnitsPerMetre, params);
  const std::vector<pipeline::MapperStep> steps = feed(mapper, walk, true);
  std::size_t evictions = 0;
  for (const pipeline::MapperStep& step : steps) {
    EXPECT_EQ(step.status, pipeline::FrameStatus::given);
    evictions += step.evicted;
  }
  const pipeline::VolumeStats stats = mapper.volume_stats();
  EXPECT_GE(evictions, 1u);
  EXPECT_EQ(stats.evictions, evictions);
  EXPECT_LE(stats.peak_blocks, params.volume.max_blocks);
  EXPECT_FALSE(stats.covers_all_frames);
  EXPECT_GT(stats.store_memory_bytes, 0u);
  // The mesh is the camera's surroundings: every vertex within reach of the last frames' cameras.
  const TriangleMesh mesh = mapper.mesh();
  ASSERT_FALSE(mesh.vertices.empty());
  const Eigen::Vector3f last_camera = mapper.poses().back().translation().cast<float>();
  double farthest = 0;
  for (const Eigen::Vector3f& v : mesh.vertices)
    farthest = std::max(farthest, static_cast<double>((v - last_camera).norm()));
  EXPECT_LT(farthest, params.keep_radius_m + params.max_fusion_depth_m + 0.5);
}

// Known poses, exact depth: the mesh lies on the world's surfaces (4 cm voxels).
// The distance field against the true distances of its cells' centres: hardly ever below them by
// more than a cell's diagonal (its surfaces are true ones); within a cell of them near the
// surfaces it saw (farther out, the nearest true surface is often one it did not see: 30-70 % of
// cells); the mesh's vertices within a cell's diagonal of its surfaces.
void expect_distance_field_measures_the_surfaces(const mapping::EsdfGrid& field,
                                                 const TriangleMesh& mesh,
                                                 const Eigen::Isometry3f& world_from_first) {
  ASSERT_GT(field.size(), 10000u);
  const double cell = field.resolution, diagonal = std::sqrt(3.0) * cell;
  std::size_t measured = 0, below = 0, near = 0, near_close = 0;
  for (int z = 0; z < field.dims.z(); ++z) {
    for (int y = 0; y < field.dims.y(); ++y) {
      for (int x = 0; x < field.dims.x(); ++x) {
        const Eigen::Vector3i c = field.first_cell + Eigen::Vector3i(x, y, z);
        const float d = field.distances[std::size_t(field.index(c))];
        if (d <= 0 || d >= field.max_distance - cell) continue;
        const Eigen::Vector3d centre = (c.cast<double>().array() + 0.5) * cell;
        const double truth = synth::distance_to_surfaces(testing::test_world(),
                                                         world_from_first.cast<double>() * centre);
        ++measured;
        below += d < truth - diagonal;
        if (d > 1.5 * cell) continue;
        ++near;
        near_close += std::abs(d - truth) <= cell;
      }
    }
  }
  ASSERT_GT(measured, 5000u);
  EXPECT_LE(below, measured / 200) << "of " << measured;
  EXPECT_GE(near_close, near * 85 / 100) << "of " << near;
  std::size_t off = 0;
  for (const Eigen::Vector3f& v : mesh.vertices) off += field.distance(v.cast<double>()) > diagonal;
  EXPECT_LE(off, mesh.vertices.size() / 100) << "of " << mesh.vertices.size();
}

TEST(Mapper, MeshFromGivenPosesLiesOnTheTrueSurfaces) {
  const compute::Context cpu = compute::Context::cpu();
  const testing::RenderedSequence& walk = survey_walk();
  pipeline::MapperParams params;
  // The distance field's surfaces as the mesh's: voxels observed once included.
  params.distance_field.min_weight = params.mesh.min_weight;
  pipeline::Mapper mapper(cpu, walk.camera, testing::kSynthUnitsPerMetre, params);
  feed(mapper, walk, true);
  const TriangleMesh mesh = mapper.mesh();
  ASSERT_GT(mesh.vertices.size(), 10000u);
  // Poses are relative to the first frame's: back to the world's.
  const Eigen::Isometry3f world_from_first = walk.truth.front().cast<float>();
  const auto distance = [&](const Eigen::Vector3f& v) {
    return synth::distance_to_surfaces(testing::test_world(),
                                       (world_from_first * v).cast<double>());
  };
  double sum = 0;
  for (const Eigen::Vector3f& v : mesh.vertices) sum += distance(v);
  EXPECT_LT(sum / mesh.vertices.size(), 0.01);
  // Surface more than 4 cm off (flying pixels at outlines), by area: a share of vertices would
  // depend on how densely the mesher places them (marching tetrahedra 1.6 % of its vertices, 1.45 %
  // of its area; marching cubes 2.1 % and 1.29 %).
  double area = 0, far_area = 0;
  for (const Eigen::Vector3i& t : mesh.triangles) {
    const Eigen::Vector3f &a = mesh.vertices[t[0]], &b = mesh.vertices[t[1]],
                          &c = mesh.vertices[t[2]];
    const double triangle_area = 0.5 * (b - a).cross(c - a).norm();
    area += triangle_area;
    if (distance((a + b + c) / 3) > 0.04) far_area += triangle_area;
  }
  EXPECT_LT(far_area / area, 0.02);
  EXPECT_EQ(mapper.volume_stats().evictions, 0u);
  EXPECT_TRUE(mapper.volume_stats().covers_all_frames);
  expect_distance_field_measures_the_surfaces(mapper.distance_field(), mesh, world_from_first);
}

// A depth camera alone (frames without colour): the same surface as with colour, and no colour
// on it (the voxels' colours would all be black), in mesh() and in the finished map.
TEST(Mapper, FramesWithoutColourGiveTheSameSurfaceWithoutColours) {
  const compute::Context cpu = compute::Context::cpu();
  const testing::RenderedSequence& walk = survey_walk();
  const auto first_frames = [&](bool colour) {
    pipeline::MapperParams params;
    params.pipeline.features = false;
    auto mapper =
        std::make_unique<pipeline::Mapper>(cpu, walk.camera, testing::kSynthUnitsPerMetre, params);
    for (std::size_t i = 0; i < 30; ++i) {
      registration::RgbdImages frame = walk.frames[i];
      if (!colour) frame.color = RgbImage();
      mapper->add_frame(frame, walk.truth[i]);
    }
    return mapper;
  };
  const auto coloured = first_frames(true);
  const auto depth_alone = first_frames(false);
  const TriangleMesh with = coloured->mesh(), without = depth_alone->mesh();
  ASSERT_GT(with.vertices.size(), 1000u);
  EXPECT_EQ(with.colors.size(), with.vertices.size());
  EXPECT_TRUE(without.colors.empty());
  ASSERT_EQ(without.vertices.size(), with.vertices.size());
  for (std::size_t i = 0; i < with.vertices.size(); ++i)
    ASSERT_LT((without.vertices[i] - with.vertices[i]).norm(), 1e-6f) << "vertex " << i;
  const pipeline::MapPipelineResult result = depth_alone->finish();
  EXPECT_TRUE(result.mesh.colors.empty());
  EXPECT_FALSE(result.map.has_colors());
  EXPECT_GT(result.map.size(), 1000u);
}

// max_views bounds the views stage: 100 frames, every 5th would be 20 views; 7 are allowed, so
// every 15th frame is labelled.
TEST(Mapper, LabelsAtMostMaxViews) {
  const compute::Context cpu = compute::Context::cpu();
  const testing::RenderedSequence& walk = survey_walk();
  pipeline::MapperParams params;
  params.pipeline.max_views = 7;
  pipeline::Mapper mapper(cpu, walk.camera, testing::kSynthUnitsPerMetre, params);
  feed(mapper, walk, true);
  const pipeline::MapPipelineResult result = mapper.finish();
  EXPECT_EQ(result.labelled_views + result.unlabelled_views, 7);
  EXPECT_GT(result.labelled_views, 3);
}

TEST(Mapper, RejectsMixedPosesUseAfterFinishAndBadParameters) {
  const compute::Context cpu = compute::Context::cpu();
  const testing::RenderedSequence& walk = survey_walk();
  {
    pipeline::Mapper mapper(cpu, walk.camera, testing::kSynthUnitsPerMetre);
    mapper.add_frame(walk.frames[0], walk.truth[0]);
    EXPECT_ERROR_MENTIONS(mapper.add_frame(walk.frames[1]), "has no pose");
    Eigen::Isometry3d sheared = walk.truth[1];
    sheared.linear()(0, 1) += 0.2;
    EXPECT_ERROR_MENTIONS(mapper.add_frame(walk.frames[1], sheared), "not a rotation");
  }
  {
    pipeline::Mapper mapper(cpu, walk.camera, testing::kSynthUnitsPerMetre);
    EXPECT_ERROR_MENTIONS(mapper.finish(), "no frame");
  }
  {
    pipeline::Mapper mapper(cpu, walk.camera, testing::kSynthUnitsPerMetre);
    registration::RgbdImages small = walk.frames[0];
    small.depth = DepthImage(100, 100);
    EXPECT_ERROR_MENTIONS(mapper.add_frame(small), "100x100");
  }
  PinholeIntrinsics no_camera = walk.camera;
  no_camera.fx = 0;
  EXPECT_ERROR_MENTIONS(pipeline::Mapper(cpu, no_camera, testing::kSynthUnitsPerMetre), "mapper");
  pipeline::MapperParams bad;
  bad.high_water = 1.5;
  EXPECT_ERROR_MENTIONS(pipeline::Mapper(cpu, walk.camera, testing::kSynthUnitsPerMetre, bad),
                        "high_water");
}

// Room in memory for one frame and a half: the first stays there, the others go to the file.
TEST(FrameStore, GivesBackTheDecimatedFramesFromMemoryAndDisk) {
  const testing::RenderedSequence& walk = survey_walk();
  const std::size_t frame_bytes = 160 * 120 * 5;
  mapping::FrameStore store(walk.camera, testing::kSynthUnitsPerMetre, 2, frame_bytes * 3 / 2);
  for (std::size_t i = 0; i < 3; ++i) store.add(walk.frames[i]);
  ASSERT_EQ(store.size(), 3u);
  EXPECT_EQ(store.camera().width, walk.camera.width / 2);
  EXPECT_DOUBLE_EQ(store.camera().fx, walk.camera.fx / 2);
  for (std::size_t i : {2u, 0u, 1u}) {
    const registration::RgbdImages back = store.frame(i);
    const registration::RgbdImages& original = walk.frames[i];
    EXPECT_DOUBLE_EQ(back.timestamp, original.timestamp);
    for (int y = 0; y < back.depth.height(); y += 7) {
      for (int x = 0; x < back.depth.width(); x += 5) {
        ASSERT_EQ(back.depth(x, y), original.depth(2 * x, 2 * y)) << i << " " << x << " " << y;
        ASSERT_EQ(back.color(x, y), original.color(2 * x, 2 * y));
      }
    }
  }
  EXPECT_ERROR_MENTIONS(store.frame(3), "no frame 3");
  EXPECT_EQ(store.bytes_in_memory(), frame_bytes);
  EXPECT_EQ(store.bytes_on_disk(), 2 * frame_bytes);
}

}  // namespace
}  // namespace kartograf
