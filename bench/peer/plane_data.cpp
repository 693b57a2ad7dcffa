#include "plane_data.hpp"

#include <algorithm>

#include "kartograf/compute/context.hpp"
#include "kartograf/core/error.hpp"
#include "kartograf/formats/pcd.hpp"
#include "kartograf/geometry/backproject.hpp"
#include "kartograf/synth/render.hpp"
#include "kartograf/synth/trajectory.hpp"
#include "kartograf/synth/world.hpp"

namespace kartograf::peer {
namespace {

// Input preparation, not part of any timed method.
const compute::Context& cpu_context() {
  static const compute::Context context = compute::Context::cpu();
  return context;
}

}  // namespace

const char* to_string(PlaneDataset dataset) {
  switch (dataset) {
    case PlaneDataset::synthetic:
      return "synthetic";
    case PlaneDataset::seven_scenes:
      return "7scenes";
    default:
      return "mosd";
  }
}

std::vector<PlaneFrame> synthetic_plane_frames(int count) {
  const synth::World world = synth::make_building(1);
  // The sensor sees faces that form one continuous planar surface as one plane.
  const std::vector<Label> surface = synth::continuous_surface_ids(world);
  const PinholeIntrinsics camera{640, 480, 525.0, 525.0, 319.5, 239.5};
  const Trajectory tour = synth::robot_tour(world, 300);
  geometry::DepthRange range;
  range.units_per_metre = synth::kTumDepthUnitsPerMetre;
  std::vector<PlaneFrame> frames;
  for (int f = 0; f < count; ++f) {
    const int index = 7 + f * 290 / count;
    const Eigen::Isometry3d& pose = tour[index].pose;
    synth::SyntheticFrame rendered =
        synth::render(world, camera, pose, synth::NoiseModel::kinect(), 1000 + index);
    PlaneFrame frame;
    frame.dataset = PlaneDataset::synthetic;
    frame.name = "synthetic " + std::to_string(index);
    frame.camera = camera;
    frame.points = geometry::backproject(cpu_context(), rendered.depth, camera, range);
    frame.color = std::move(rendered.color);
    frame.truth = std::move(rendered.plane_id);
    for (std::size_t i = 0; i < frame.truth.size(); ++i) {
      Label& label = frame.truth.data()[i];
      label = rendered.depth.data()[i] == 0 ? kUnlabeled : surface[label];
    }
    for (const synth::Plane& plane : world.planes)
      frame.truth_normals[plane.id] = pose.linear().transpose() * plane.normal;
    frames.push_back(std::move(frame));
  }
  return frames;
}

std::vector<PlaneFrame> seven_scenes_plane_frames(const Dataset& dataset,
                                                  const std::vector<std::size_t>& indices) {
  std::vector<PlaneFrame> frames;
  for (const std::size_t index : indices) {
    require(index < dataset.size(),
            dataset.name + ": frame " + std::to_string(index) + " is beyond the sequence");
    Frame loaded = dataset.frame(index);
    PlaneFrame frame;
    frame.dataset = PlaneDataset::seven_scenes;
    frame.name = dataset.name + " " + std::to_string(index);
    frame.camera = dataset.camera();
    frame.points = geometry::backproject(cpu_context(), loaded.depth, frame.camera, dataset.range);
    frame.color = std::move(loaded.color);
    frames.push_back(std::move(frame));
  }
  return frames;
}

std::vector<PlaneFrame> mosd_plane_frames(const std::filesystem::path& folder) {
  std::vector<PlaneFrame> frames;
  for (const char* name : {"test0", "test16", "test24", "test31", "test55", "test57"}) {
    const io::PcdCloud cloud = io::read_pcd(folder / (std::string(name) + ".pcd"));
    require(cloud.organized() && cloud.labels.size() == cloud.size() &&
                cloud.colors.size() == cloud.size(),
            std::string("mOSD ") + name + ": expected an organized cloud with labels and colours");
    PlaneFrame frame;
    frame.dataset = PlaneDataset::mosd;
    frame.name = std::string("mosd ") + name;
    frame.camera = PinholeIntrinsics::kinect_7scenes();
    frame.points = cloud.to_point_image();
    frame.color = RgbImage(cloud.width, cloud.height);
    std::copy(cloud.colors.begin(), cloud.colors.end(), frame.color.data());
    frame.truth = LabelImage(cloud.width, cloud.height, kUnlabeled);
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      const bool table = cloud.labels[i] >= 1 && cloud.labels[i] <= 9;
      if (table && is_valid(frame.points.data()[i])) frame.truth.data()[i] = 1;
    }
    frames.push_back(std::move(frame));
  }
  return frames;
}

}  // namespace kartograf::peer
