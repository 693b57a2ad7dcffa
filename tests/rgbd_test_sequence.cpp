#include "rgbd_test_sequence.hpp"

#include <cmath>
#include <numeric>

#include "kartograf/eval/trajectory_metrics.hpp"
#include "kartograf/synth/render.hpp"
#include "kartograf/synth/trajectory.hpp"

namespace kartograf::testing {

const synth::World& test_world() {
  static const synth::World world = synth::make_building(1);
  return world;
}

PinholeIntrinsics qvga_kinect() {
  return {320, 240, 262.5, 262.5, 159.5, 119.5};
}

std::vector<Eigen::Isometry3d> survey_poses(const synth::World& world, std::size_t first,
                                            std::size_t count, std::size_t stride) {
  synth::TourParams tour;
  tour.survey = true;
  tour.pitch_deg = 20;
  const Trajectory trajectory =
      synth::robot_tour(world, synth::tour_frames_needed(world, tour), tour);
  std::vector<Eigen::Isometry3d> poses;
  for (std::size_t i = 0; i < count; ++i) poses.push_back(trajectory.at(first + i * stride).pose);
  return poses;
}

RenderedSequence render_sequence(const std::vector<Eigen::Isometry3d>& poses,
                                 const PinholeIntrinsics& camera, bool noise) {
  return render_sequence(test_world(), poses, camera, noise);
}

namespace {

RenderedSequence render_with(const synth::World& world, const std::vector<Eigen::Isometry3d>& poses,
                             const PinholeIntrinsics& camera, const synth::NoiseModel& model,
                             const std::vector<std::uint64_t>& noise_seeds) {
  RenderedSequence sequence;
  sequence.camera = camera;
  sequence.truth = poses;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    synth::SyntheticFrame frame = synth::render(world, camera, poses[i], model, noise_seeds.at(i));
    sequence.frames.push_back(
        {std::move(frame.depth), std::move(frame.color), static_cast<double>(i) / 30.0, poses[i]});
  }
  return sequence;
}

}  // namespace

RenderedSequence render_sequence(const synth::World& world,
                                 const std::vector<Eigen::Isometry3d>& poses,
                                 const PinholeIntrinsics& camera, bool noise) {
  std::vector<std::uint64_t> seeds(poses.size());
  std::iota(seeds.begin(), seeds.end(), std::uint64_t{100});
  return render_with(world, poses, camera,
                     noise ? synth::NoiseModel::kinect() : synth::NoiseModel::none(), seeds);
}

RenderedSequence render_sequence(const synth::World& world,
                                 const std::vector<Eigen::Isometry3d>& poses,
                                 const PinholeIntrinsics& camera,
                                 const std::vector<std::uint64_t>& noise_seeds) {
  return render_with(world, poses, camera, synth::NoiseModel::kinect(), noise_seeds);
}

double ate_rmse(const std::vector<Eigen::Isometry3d>& estimate,
                const std::vector<Eigen::Isometry3d>& truth) {
  eval::MatchedPoses matched;
  for (std::size_t i = 0; i < estimate.size() && i < truth.size(); ++i) {
    matched.ground_truth.push_back({static_cast<double>(i), truth[i]});
    matched.estimate.push_back({static_cast<double>(i), estimate[i]});
  }
  return eval::compute_ate(matched, eval::Alignment::se3).translation_m.rmse;
}

DepthImage depth_of(const PointImage& points, double units_per_metre) {
  DepthImage depth(points.width(), points.height(), 0);
  for (int v = 0; v < points.height(); ++v) {
    for (int u = 0; u < points.width(); ++u) {
      const Point4f& p = points(u, v);
      if (is_valid(p))
        depth(u, v) = static_cast<std::uint16_t>(std::lround(p.z() * units_per_metre));
    }
  }
  return depth;
}

const RenderedSequence& out_and_back() {
  static const RenderedSequence sequence = [] {
    const Trajectory tour = synth::robot_tour(test_world(), 500);
    std::vector<Eigen::Isometry3d> poses;
    for (int i = 400; i < 430; ++i) poses.push_back(tour[static_cast<std::size_t>(i)].pose);
    for (int i = 429; i >= 400; --i) poses.push_back(tour[static_cast<std::size_t>(i)].pose);
    return render_sequence(poses, qvga_kinect());
  }();
  return sequence;
}

}  // namespace kartograf::testing
