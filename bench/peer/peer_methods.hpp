#pragma once
// What the peer benchmark runs: registration methods of Kartograf, Open3D and PCL behind one
// interface, so that every method sees the same frame pairs and is timed the same way.
//
// A Method prepares a pair (untimed: converting the shared clouds into the library's own types,
// or giving an odometry front end its reference frame) and returns the timed call, which
// estimates the transform mapping source points into the target frame.
// An OdometryFrontEnd tracks a sequence frame by frame (chained trajectories) and also serves the
// pair runs: reference = target (untimed), track(source) timed.
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "peer_data.hpp"

namespace kartograf::peer {

struct Estimate {
  Eigen::Isometry3d source_to_target = Eigen::Isometry3d::Identity();
  bool success = true;  // what the method itself reports
};

// What a method registers: the RGB-D frames, the full clouds or the downsampled ones.
enum class InputKind { rgbd, cloud_full, cloud_sampled };

struct Method {
  std::string name;
  std::string library;  // "kartograf", "open3d", "pcl"
  InputKind input = InputKind::rgbd;
  std::string threads;  // how its thread count is set, e.g. "OMP_NUM_THREADS=2"
  // Ratios of this method's time are taken against this Kartograf method (empty: none).
  std::string compared_with;
  std::function<std::function<Estimate()>(const FramePair&)> prepare;
};

class OdometryFrontEnd {
 public:
  virtual ~OdometryFrontEnd() = default;
  virtual void set_reference(const Frame& frame) = 0;
  // Aligns frame to the reference; the reference stays.
  virtual Estimate track(const Frame& frame) = 0;
  // The frame of the last track() becomes the reference (no work).
  virtual void advance() = 0;
};

using OdometryFactory = std::function<std::unique_ptr<OdometryFrontEnd>(const Dataset&)>;

// A pair method over an odometry front end made per dataset (cached): the target becomes the
// reference untimed, track(source) is timed. both_frames: the timed call sets the reference too
// (the cost of one pair from scratch, as a library that cannot keep a frame pays every call).
Method odometry_method(std::string name, std::string library, std::string threads,
                       std::string compared_with, OdometryFactory factory,
                       bool both_frames = false);

// Cloud ICP parameters shared by every cloud method (the same gate and iteration limit).
struct CloudIcpSettings {
  double max_distance = 0.05;  // metres
  int max_iterations = 30;
};

// Thread counts as the environment pins them (the benchmark never changes them itself).
std::string kartograf_threads();  // "KARTOGRAF_CPU_THREADS=n" (unset: 1)
std::string openmp_threads();     // "OMP_NUM_THREADS=n" or "OMP_NUM_THREADS unset (n cores)"

// Kartograf: projective point-to-plane odometry on every available backend (the first method is
// the CPU one), the CPU both-frames variant, and k-d tree point-to-plane ICP on the clouds
// (plain, and with the HSI colour gate as the counterpart of coloured ICP).
std::vector<Method> kartograf_methods(const CloudIcpSettings& settings, bool device_backends);
// The CPU odometry front end (chained trajectories).
OdometryFactory kartograf_odometry_factory();
// registration::RgbdOdometry with its defaults on the CPU (chained trajectories only).
OdometryFactory kartograf_rgbd_odometry_factory();
inline constexpr const char* kKartografRgbdOdometry =
    "kartograf RGB-D odometry (RgbdOdometry: motion model, k = 5) (cpu)";
inline constexpr const char* kKartografOdometry = "kartograf p2plane odometry (cpu)";
inline constexpr const char* kKartografCloudFull = "kartograf p2plane ICP k-d tree (cpu)";
inline constexpr const char* kKartografCloudSampled = "kartograf p2plane ICP k-d tree (cpu) 20k";
inline constexpr const char* kKartografColorSampled =
    "kartograf p2plane ICP k-d tree + colour gate (cpu) 20k";

// Open3D: RGB-D odometry (hybrid term), point-to-plane ICP (full and 20k), coloured ICP (20k).
std::vector<Method> open3d_methods(const CloudIcpSettings& settings);
OdometryFactory open3d_odometry_factory();
std::string open3d_version();

// PCL: IterativeClosestPoint and GeneralizedIterativeClosestPoint on the 20k clouds.
std::vector<Method> pcl_methods(const CloudIcpSettings& settings);
std::string pcl_version();

}  // namespace kartograf::peer
