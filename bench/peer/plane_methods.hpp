#pragma once
// What the plane part of the peer benchmark runs: plane segmentation of Kartograf, PCL and Open3D
// behind one interface, so that every method sees the same frames, is timed the same way and is
// scored from the same kind of output (a plane id per pixel and each plane's normal).
//
// A PlaneMethod prepares a frame (untimed: converting the shared organized cloud into the
// library's own types) and returns the timed call, which leaves the library's raw result behind,
// and the untimed conversion of that result into a per-pixel label image.
#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "kartograf/core/label_image.hpp"
#include "kartograf/eval/plane_metrics.hpp"
#include "plane_data.hpp"

namespace kartograf::peer {

struct PlaneOutput {
  LabelImage labels;           // plane id per pixel, 0 = none
  eval::PlaneNormals normals;  // plane id -> normal
};

// Named parts of one timed call in milliseconds (PCL's normal estimation, Kartograf's stages),
// shown beside the total.
using TimeParts = std::vector<std::pair<std::string, double>>;

struct PlaneRun {
  std::function<TimeParts()> call;      // timed: the library's work on the frame
  std::function<PlaneOutput()> output;  // untimed: the last call's planes per pixel
};

struct PlaneMethod {
  std::string name;
  std::string library;   // "kartograf", "pcl", "open3d"
  std::string threads;   // how its thread count is set
  std::string settings;  // its parameters, for the notes under the table
  std::function<PlaneRun(const PlaneFrame&)> prepare;
  // A new instance that shares nothing with this one, for another thread (plane_throughput.hpp);
  // empty where the method runs threads of its own (PCL, Open3D, the device backends).
  std::function<PlaneMethod()> another;
};

// The smallest plane every method keeps: Kartograf's min_plane_pixels default.
inline constexpr std::uint64_t kMinPlanePixels = 300;
// Every method's distance tolerance between a point and its plane where it has one (PCL's
// organized segmentation demo default, Open3D's RANSAC threshold).
inline constexpr double kPlaneDistance = 0.02;  // metres

// Kartograf: segmentation::PlaneExtractor with its defaults on the CPU backend (the first method,
// the reference of every ratio) and, with device_backends, on every available device backend.
std::vector<PlaneMethod> kartograf_plane_methods(bool device_backends);
inline constexpr const char* kKartografPlanes = "kartograf PlaneExtractor (cpu)";
inline constexpr const char* kKartografCellPlanes = "kartograf PlaneExtractor cells (cpu)";

// PCL: IntegralImageNormalEstimation + OrganizedMultiPlaneSegmentation, without and with its
// refinement step.
std::vector<PlaneMethod> pcl_plane_methods();

// Open3D: PointCloud::SegmentPlane (RANSAC) in a loop, at most max_planes planes.
// (DetectPlanarPatches appeared in Open3D 0.17; Debian bookworm ships 0.16.)
std::vector<PlaneMethod> open3d_plane_methods(int max_planes);

// CAPE (pedropro/CAPE) as its example runs it, planes only; only in builds with
// KARTOGRAF_CAPE_DIR (bench/CMakeLists.txt), which define KARTOGRAF_WITH_CAPE.
std::vector<PlaneMethod> cape_plane_methods();

}  // namespace kartograf::peer
