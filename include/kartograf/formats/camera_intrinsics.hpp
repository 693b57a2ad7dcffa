#pragma once
// Camera intrinsics as users and data sets give them: a preset name (tum-fr1, tum-fr2, tum-fr3,
// kinect, 7scenes), "fx,fy,cx,cy", or a file in one of the layouts' formats: camera-intrinsics.txt
// (7-Scenes, 3DMatch, SUN3D: the 3x3 matrix K as 9 numbers) or camera_intrinsics.json (Open3D).
// The matrix and the four numbers carry no image size: a Camera without one (width 0) takes the
// frames' size when a sequence is opened.
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "kartograf/core/intrinsics.hpp"

namespace kartograf::io {

struct Camera {
  PinholeIntrinsics intrinsics;  // width and height 0: not known yet (the frames' size)
  std::string source;            // "preset", "file", "option" or "default"
  std::string description;       // e.g. "preset tum-fr3", "file 'a/camera-intrinsics.txt'"
};

// The published intrinsics of TUM's Freiburg 1, 2 and 3 cameras, a generic Kinect (525, TUM's
// default) and 7-Scenes' (585), all for 640x480 frames; empty for any other name.
std::optional<PinholeIntrinsics> camera_preset(std::string_view name);
// The preset names, for messages and help texts.
const std::vector<std::string>& camera_preset_names();

// A 3x3 K as 9 whitespace-separated numbers (row-major: fx 0 cx 0 fy cy 0 0 1); errors name the
// file and what is wrong. The result has no image size.
PinholeIntrinsics read_camera_matrix_txt(const std::filesystem::path& path);

// --camera's value: a preset name, "fx,fy,cx,cy" or a file (.json: Open3D, else a 3x3 matrix).
// Throws Error naming the value and the accepted forms.
Camera parse_camera_argument(const std::string& value);

// The preset for a folder whose name says which TUM camera took it ("rgbd_dataset_freiburg2_...":
// tum-fr2); empty when it says none.
std::optional<std::string> tum_preset_of_folder(const std::filesystem::path& folder);

// The camera for frames of width x height: the size filled in where the camera has none; a
// preset's or default's 640x480 values scaled to another size (the description then says so);
// a file whose size differs is an Error naming both sizes.
Camera fit_camera_to_frames(Camera camera, int width, int height);

// One line for people: "fx 535.4 fy 539.2 cx 320.1 cy 247.6 (640x480, preset tum-fr3)".
std::string describe(const Camera& camera);

}  // namespace kartograf::io
