#pragma once
// The frames of the plane part of the peer benchmark. Every method gets the same organized cloud
// per frame, made once by Kartograf (back-projection on the CPU backend, NaN where the depth is
// invalid or out of range) with the frame's colour, and each method's planes are scored against
// the same ground truth.
#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include "kartograf/core/color.hpp"
#include "kartograf/core/intrinsics.hpp"
#include "kartograf/core/label_image.hpp"
#include "kartograf/core/point_image.hpp"
#include "kartograf/eval/plane_metrics.hpp"
#include "peer_data.hpp"

namespace kartograf::peer {

enum class PlaneDataset { synthetic, seven_scenes, mosd };
const char* to_string(PlaneDataset dataset);  // "synthetic", "7scenes", "mosd"
// Every data set, in the order the tables show them.
inline constexpr PlaneDataset kPlaneDatasets[] = {PlaneDataset::synthetic,
                                                  PlaneDataset::seven_scenes, PlaneDataset::mosd};

struct PlaneFrame {
  PlaneDataset dataset = PlaneDataset::synthetic;
  std::string name;  // "7scenes 30", "mosd test0", ...
  PinholeIntrinsics camera;
  PointImage points;  // camera frame, NaN where invalid
  RgbImage color;
  // synthetic: the plane id of every pixel with depth (coplanar faces that touch as one id), 0
  // elsewhere; mOSD: 1 on the table (labels 1-9 at valid points), 0 elsewhere; 7-Scenes: empty.
  LabelImage truth;
  eval::PlaneNormals truth_normals;  // synthetic: every plane id's normal in the camera frame
};

// `count` frames spread over frames 7..294 of a 300-frame robot tour through the synthetic
// building (seed 1), 640x480, fx = fy = 525, Kinect noise model: the frames and ground truth of
// tests/plane_extraction_test.cpp.
std::vector<PlaneFrame> synthetic_plane_frames(int count);
// The given frames of a 7-Scenes sequence, with the registration part's depth range.
std::vector<PlaneFrame> seven_scenes_plane_frames(const Dataset& dataset,
                                                  const std::vector<std::size_t>& indices);
// The six organized frames of PCL's mOSD (test0, 16, 24, 31, 55, 57; test43 and test56 are
// stored unorganized), with the 7-Scenes Kinect intrinsics as the test uses.
std::vector<PlaneFrame> mosd_plane_frames(const std::filesystem::path& folder);

}  // namespace kartograf::peer
