// Open3D's side of the plane comparison (Debian's libopen3d-dev 0.16, OpenMP inside SegmentPlane:
// its thread count is OMP_NUM_THREADS). Open3D 0.16 has one plane detector, SegmentPlane (RANSAC
// for the single best plane of a cloud); the usual way to get every plane is to call it in a loop,
// taking each plane's inliers out of the cloud. DetectPlanarPatches, which finds all planes at
// once, arrived in Open3D 0.17 and is not in Debian bookworm's headers.
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <open3d/geometry/PointCloud.h>
#include <open3d/utility/Logging.h>
#include <open3d/utility/Random.h>

#include "peer_methods.hpp"
#include "plane_methods.hpp"

namespace kartograf::peer {
namespace {

namespace o3d = open3d;

constexpr int kRansacPoints = 3;
constexpr int kRansacIterations = 1000;

// One frame's cloud and, after a call, its planes.
struct Prepared {
  std::shared_ptr<o3d::geometry::PointCloud> cloud;  // the frame's valid points and colours
  std::vector<std::size_t> pixels;                   // the organized index of each point
  int width = 0, height = 0;
  // Each plane's model and its inliers, as indices into the cloud that was left when it was
  // found (the frame's cloud minus every earlier plane's inliers).
  std::vector<std::pair<Eigen::Vector4d, std::vector<std::size_t>>> planes;
};

std::shared_ptr<Prepared> prepare_cloud(const PlaneFrame& frame) {
  auto prepared = std::make_shared<Prepared>();
  prepared->cloud = std::make_shared<o3d::geometry::PointCloud>();
  for (std::size_t i = 0; i < frame.points.size(); ++i) {
    const Point4f& p = frame.points.data()[i];
    if (!is_valid(p)) continue;
    prepared->cloud->points_.emplace_back(p.x(), p.y(), p.z());
    const Rgb8& c = frame.color.data()[i];
    prepared->cloud->colors_.emplace_back(c[0] / 255.0, c[1] / 255.0, c[2] / 255.0);
    prepared->pixels.push_back(i);
  }
  prepared->width = frame.points.width();
  prepared->height = frame.points.height();
  return prepared;
}

void segment_planes(Prepared& prepared, int max_planes) {
  o3d::utility::random::Seed(0);  // the same planes in every call
  prepared.planes.clear();
  std::shared_ptr<o3d::geometry::PointCloud> rest = prepared.cloud;
  while (static_cast<int>(prepared.planes.size()) < max_planes &&
         rest->points_.size() >= kMinPlanePixels) {
    auto [model, inliers] = rest->SegmentPlane(kPlaneDistance, kRansacPoints, kRansacIterations);
    if (inliers.size() < kMinPlanePixels) break;
    rest = rest->SelectByIndex(inliers, /*invert=*/true);
    prepared.planes.emplace_back(model, std::move(inliers));
  }
}

PlaneOutput to_output(const Prepared& prepared) {
  PlaneOutput output{LabelImage(prepared.width, prepared.height, kUnlabeled), {}};
  // Replays the loop on pixel indices: SelectByIndex(invert) keeps the order of the points it
  // leaves.
  std::vector<std::size_t> pixels = prepared.pixels;
  for (std::size_t k = 0; k < prepared.planes.size(); ++k) {
    const auto id = static_cast<Label>(k + 1);
    const auto& [model, inliers] = prepared.planes[k];
    std::vector<bool> taken(pixels.size(), false);
    for (const std::size_t i : inliers) {
      output.labels.data()[pixels[i]] = id;
      taken[i] = true;
    }
    std::size_t kept = 0;
    for (std::size_t i = 0; i < pixels.size(); ++i) {
      if (!taken[i]) pixels[kept++] = pixels[i];
    }
    pixels.resize(kept);
    output.normals[id] = model.head<3>();
  }
  return output;
}

PlaneMethod segment_plane_loop(int max_planes) {
  PlaneMethod method;
  method.name = "open3d SegmentPlane loop";
  method.library = "open3d";
  method.threads = openmp_threads();
  method.settings = "RANSAC, distance 0.02 m, " + std::to_string(kRansacPoints) + " points, " +
                    std::to_string(kRansacIterations) +
                    " iterations (early exit at probability 0.99999999, the default), random "
                    "seed 0 per frame; planes taken out of the cloud (SelectByIndex) until one "
                    "has fewer than " +
                    std::to_string(kMinPlanePixels) + " inliers, fewer than " +
                    std::to_string(kMinPlanePixels) + " points remain or " +
                    std::to_string(max_planes) +
                    " planes are found; the cloud holds the frame's valid points and colours";
  method.prepare = [max_planes](const PlaneFrame& frame) {
    const std::shared_ptr<Prepared> prepared = prepare_cloud(frame);
    return PlaneRun{[prepared, max_planes] {
                      segment_planes(*prepared, max_planes);
                      return TimeParts{};
                    },
                    [prepared] { return to_output(*prepared); }};
  };
  return method;
}

}  // namespace

std::vector<PlaneMethod> open3d_plane_methods(int max_planes) {
  o3d::utility::SetVerbosityLevel(o3d::utility::VerbosityLevel::Error);
  return {segment_plane_loop(max_planes)};
}

}  // namespace kartograf::peer
