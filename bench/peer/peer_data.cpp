#include "peer_data.hpp"

#include <cmath>
#include <cstdint>

#include "kartograf/compute/context.hpp"
#include "kartograf/core/error.hpp"
#include "kartograf/geometry/normals.hpp"
#include "kartograf/geometry/subsample.hpp"
#include "kartograf/geometry/voxel_downsample.hpp"
#include "kartograf/outputs/synthetic_dataset.hpp"

namespace kartograf::peer {
namespace {

// Clouds are cut on the CPU backend: input preparation, not part of any timed method.
const compute::Context& cpu_context() {
  static const compute::Context context = compute::Context::cpu();
  return context;
}

geometry::DepthRange range_of(const io::Sequence& sequence) {
  return {sequence.depth_units_per_metre(), kMinDepthMetres, kMaxDepthMetres};
}

PointCloud voxel_downsample(const PointCloud& cloud, double voxel_size) {
  geometry::VoxelDownsampleParams params;
  params.voxel_size = static_cast<float>(voxel_size);
  const auto device = geometry::DeviceCloud::from_host(cpu_context(), cloud);
  return geometry::voxel_downsample(cpu_context(), device, params).to_host();
}

}  // namespace

Frame Dataset::frame(std::size_t index) const {
  io::RgbdFrame loaded = sequence->frame(index);
  require(loaded.pose.has_value(),
          name + ": frame " + std::to_string(index) + " has no ground-truth pose");
  return {index, std::move(loaded.color), std::move(loaded.depth), *loaded.pose};
}

Dataset open_seven_scenes_dataset(const std::filesystem::path& folder) {
  Dataset dataset;
  dataset.name = "7scenes";
  dataset.note =
      "7-Scenes RedKitchen (real Kinect v1, depth mm, fx = fy = 585, cx = 320, cy = 240); colour "
      "and depth come from different cameras and are NOT registered: colour terms see a "
      "misaligned colour";
  dataset.sequence = io::open_seven_scenes(folder);
  dataset.range = range_of(*dataset.sequence);
  return dataset;
}

Dataset open_synthetic_dataset(const std::filesystem::path& folder) {
  Dataset dataset;
  dataset.name = "synthetic";
  dataset.note =
      "Kartograf synthetic hand-held sequence (Kinect v1 noise model, depth 1/5000 m, fx = fy = "
      "525); colour registered to depth exactly";
  dataset.sequence = io::open_tum_sequence(folder);
  dataset.range = range_of(*dataset.sequence);
  return dataset;
}

void write_synthetic_sequence(const std::filesystem::path& folder, int frames) {
  io::SyntheticDatasetParams options;
  options.frames = frames;
  options.trajectory = io::SyntheticTrajectory::handheld;
  options.force = true;
  io::write_synthetic_dataset(folder, options);
}

CloudMaker::CloudMaker(const Dataset& dataset, std::size_t target_points)
    : dataset_(&dataset), target_points_(target_points) {
  // Bisect the voxel edge (the count falls as the edge grows) on the first frame's cloud.
  const PointCloud first = full_cloud(dataset.frame(0));
  require(first.size() > target_points,
          dataset.name + ": frame 0 has fewer valid points than the downsampling target");
  double low = 0.001, high = 0.2;
  for (int step = 0; step < 24; ++step) {
    voxel_size_ = std::sqrt(low * high);
    const std::size_t count = voxel_downsample(first, voxel_size_).size();
    if (count > target_points_ * 1.02) {
      low = voxel_size_;
    } else if (count < target_points_ * 0.98) {
      high = voxel_size_;
    } else {
      break;
    }
  }
}

PointCloud CloudMaker::full_cloud(const Frame& frame) const {
  const PinholeIntrinsics camera = dataset_->camera();
  const PointImage points =
      geometry::backproject(cpu_context(), frame.depth, camera, dataset_->range);
  const NormalImage normals = geometry::estimate_normals(cpu_context(), points);
  const bool with_colors =
      frame.color.width() == points.width() && frame.color.height() == points.height();
  PointCloud cloud;
  for (int v = 0; v < points.height(); ++v) {
    for (int u = 0; u < points.width(); ++u) {
      if (!is_valid(points(u, v)) || !is_valid(normals(u, v))) continue;
      cloud.points.push_back(points(u, v).head<3>());
      cloud.normals.push_back(normals(u, v).head<3>());
      if (with_colors) cloud.colors.push_back(frame.color(u, v));
    }
  }
  return cloud;
}

FrameClouds CloudMaker::make(const Frame& frame) const {
  FrameClouds clouds;
  clouds.full = full_cloud(frame);
  clouds.sampled = voxel_downsample(clouds.full, voxel_size_);
  return clouds;
}

std::string FramePair::label() const {
  return dataset->name + " " + std::to_string(target.index) + "->" + std::to_string(source.index);
}

std::vector<FramePair> make_pairs(const Dataset& dataset, const CloudMaker& clouds,
                                  const std::vector<std::size_t>& starts,
                                  const std::vector<int>& gaps) {
  std::vector<FramePair> pairs;
  for (const std::size_t start : starts) {
    for (const int gap : gaps) {
      const std::size_t source = start + static_cast<std::size_t>(gap);
      require(source < dataset.size(), dataset.name + ": frame " + std::to_string(source) +
                                           " is beyond the sequence (" +
                                           std::to_string(dataset.size()) + " frames)");
      FramePair pair;
      pair.dataset = &dataset;
      pair.source = dataset.frame(source);
      pair.target = dataset.frame(start);
      pair.source_clouds = clouds.make(pair.source);
      pair.target_clouds = clouds.make(pair.target);
      pair.truth = pair.target.pose.inverse() * pair.source.pose;
      pairs.push_back(std::move(pair));
    }
  }
  return pairs;
}

}  // namespace kartograf::peer
