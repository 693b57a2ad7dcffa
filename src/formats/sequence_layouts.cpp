// Each layout's frames listed by content: what files there are, not a fixed first file name.
#include <algorithm>
#include <cctype>
#include <cstdio>
#include <iterator>
#include <map>
#include <string>
#include <vector>

#include "formats/atomic_file.hpp"
#include "formats/listed_sequence.hpp"
#include "formats/text_fields.hpp"
#include "kartograf/core/error.hpp"
#include "kartograf/formats/tum.hpp"

namespace kartograf::io::detail {

namespace {

namespace fs = std::filesystem;

// A camera file that a folder carries, in any of the layouts' formats.
std::optional<Camera> folder_camera(const std::vector<fs::path>& folders) {
  for (const fs::path& folder : folders) {
    if (fs::is_regular_file(folder / "camera_intrinsics.json"))
      return Camera{read_camera_intrinsics_json(folder / "camera_intrinsics.json"), "file",
                    "file " + quoted(folder / "camera_intrinsics.json")};
    if (fs::is_regular_file(folder / "camera-intrinsics.txt"))
      return Camera{read_camera_matrix_txt(folder / "camera-intrinsics.txt"), "file",
                    "file " + quoted(folder / "camera-intrinsics.txt")};
  }
  return std::nullopt;
}

// A preset assumed because nothing says which camera took the frames; the user is told.
Camera assumed_camera(const std::string& preset, const fs::path& folder, FrameList& list) {
  list.camera_warnings.push_back(quoted(folder) + " has no camera file: assuming the " + preset +
                                 " camera; give the real one with --camera (a preset " +
                                 "tum-fr1|tum-fr2|tum-fr3|kinect|7scenes, fx,fy,cx,cy or a file)");
  return {*camera_preset(preset), "default", "default " + preset + ", no camera file"};
}

void note_missing(FrameFiles& frame) {
  if (!fs::is_regular_file(frame.depth))
    frame.missing = frame.depth;
  else if (!frame.color.empty() && !fs::is_regular_file(frame.color))  // empty: depth alone
    frame.missing = frame.color;
}

// A folder without any colour image is a depth camera's: its frames have no colour, and the user
// is told which commands need it.
void note_depth_alone(const fs::path& folder, FrameList& list) {
  list.warnings.push_back(quoted(folder) +
                          " has no colour images: depth alone (the commands and methods that "
                          "need colour refuse it)");
}

// "frame-<digits><suffix>" -> the number and the suffix.
bool parse_numbered_name(const std::string& name, long long& number, std::string& suffix) {
  if (name.rfind("frame-", 0) != 0) return false;
  std::size_t end = 6;
  while (end < name.size() && std::isdigit(static_cast<unsigned char>(name[end]))) ++end;
  if (end == 6 || end - 6 > 12) return false;
  number = std::stoll(name.substr(6, end - 6));
  suffix = name.substr(end);
  return true;
}

struct NumberedFiles {
  bool depth = false, jpg = false, png = false, pose = false;
  int digits = 6;
};

std::map<long long, NumberedFiles> scan_numbered(const fs::path& folder) {
  std::map<long long, NumberedFiles> found;
  for (const fs::directory_entry& entry : fs::directory_iterator(folder)) {
    long long n = 0;
    std::string suffix;
    const std::string name = entry.path().filename().string();
    if (!parse_numbered_name(name, n, suffix)) continue;
    const bool known = suffix == ".depth.png" || suffix == ".color.jpg" || suffix == ".color.png" ||
                       suffix == ".pose.txt";
    if (!known) continue;
    NumberedFiles& files = found[n];
    files.digits = static_cast<int>(name.size() - 6 - suffix.size());
    files.depth |= suffix == ".depth.png";
    files.jpg |= suffix == ".color.jpg";
    files.png |= suffix == ".color.png";
    files.pose |= suffix == ".pose.txt";
  }
  return found;
}

// Image files of a folder, in frame order: by the number their name is when it is one (TUM names
// files by timestamp), else by name.
std::vector<fs::path> images_in(const fs::path& folder) {
  std::vector<fs::path> images;
  for (const fs::directory_entry& entry : fs::directory_iterator(folder)) {
    std::string extension = entry.path().extension().string();
    std::transform(extension.begin(), extension.end(), extension.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    if (entry.is_regular_file() &&
        (extension == ".png" || extension == ".jpg" || extension == ".jpeg"))
      images.push_back(entry.path());
  }
  const auto key = [](const fs::path& p) {
    const auto number = parse_number<double>(p.stem().string());
    return std::make_pair(number.value_or(1e300), p.filename().string());
  };
  std::sort(images.begin(), images.end(),
            [&](const fs::path& a, const fs::path& b) { return key(a) < key(b); });
  return images;
}

// The rgb/ + depth/ layout's camera and depth scale: the folder's camera file, else a Kinect's
// (said so), in millimetres.
FrameList with_folder_camera(const fs::path& folder, FrameList list) {
  const auto camera = folder_camera({folder});
  list.camera = camera ? *camera : assumed_camera("kinect", folder, list);
  list.depth_units_per_metre = 1000;
  list.depth_scale_source = "assumed millimetres (1000 units per metre; --depth-scale to change)";
  return list;
}

}  // namespace

std::optional<fs::path> numbered_frames_folder(const fs::path& folder) {
  for (const fs::path& candidate : {folder, folder / "frames"}) {
    if (!fs::is_directory(candidate)) continue;
    for (const auto& [n, files] : scan_numbered(candidate)) {
      if (files.depth) return candidate;
    }
  }
  return std::nullopt;
}

namespace {

// TUM's frames: rgb.txt and depth.txt associated by time, or depth.txt alone (a depth camera).
void list_tum_images(const fs::path& folder, double max_difference, FrameList& list) {
  const auto depth = read_tum_file_list(folder / "depth.txt");
  std::vector<double> rgb_times, depth_times;
  for (const auto& f : depth) depth_times.push_back(f.timestamp);
  if (!fs::exists(folder / "rgb.txt")) {
    note_depth_alone(folder, list);
    for (std::size_t j = 0; j < depth.size(); ++j) {
      FrameFiles frame{depth_times[j], {}, folder / depth[j].file, {}, {}, {}, 0};
      note_missing(frame);
      list.frames.push_back(std::move(frame));
    }
    require(!list.frames.empty(), quoted(folder / "depth.txt") + ": no depth image listed");
    return;
  }
  const auto rgb = read_tum_file_list(folder / "rgb.txt");
  for (const auto& f : rgb) rgb_times.push_back(f.timestamp);
  for (const auto& [i, j] : associate_timestamps(rgb_times, depth_times, max_difference)) {
    FrameFiles frame{depth_times[j], folder / rgb[i].file, folder / depth[j].file, {}, {}, {}, 0};
    note_missing(frame);
    list.frames.push_back(std::move(frame));
  }
  require(!list.frames.empty(), quoted(folder) + ": no rgb/depth pair within " +
                                    std::to_string(max_difference) +
                                    " s (empty or mismatched rgb.txt / depth.txt)");
}

}  // namespace

FrameList list_tum_frames(const fs::path& folder, double max_difference) {
  FrameList list;
  list_tum_images(folder, max_difference, list);
  std::vector<double> gt_times;
  Trajectory ground_truth;
  if (fs::exists(folder / "groundtruth.txt")) {
    ground_truth = read_tum_trajectory(folder / "groundtruth.txt");
    for (const auto& p : ground_truth) gt_times.push_back(p.timestamp);
  }
  std::vector<double> frame_times;
  for (const FrameFiles& f : list.frames) frame_times.push_back(f.timestamp);
  for (const auto& [f, g] : associate_timestamps(frame_times, gt_times, max_difference))
    list.frames[f].pose = ground_truth[g].pose;

  if (const auto camera = folder_camera({folder})) {
    list.camera = *camera;
  } else if (const auto preset = tum_preset_of_folder(folder)) {
    list.camera = {*camera_preset(*preset), "preset",
                   "preset " + *preset + ", from the folder's name"};
  } else {
    list.camera = assumed_camera("kinect", folder, list);
  }
  list.depth_units_per_metre = 5000;
  list.depth_scale_source = "TUM: 5000 units per metre";
  return list;
}

FrameList list_numbered_frames(const fs::path& folder) {
  const auto frames_folder = numbered_frames_folder(folder);
  require(frames_folder.has_value(), quoted(folder) +
                                         ": no frame-N.depth.png in it or in its frames/ "
                                         "subfolder (not a 7-Scenes / 3DMatch / SUN3D folder)");
  const std::map<long long, NumberedFiles> found = scan_numbered(*frames_folder);
  long long step = 0;
  for (auto it = found.begin(); std::next(it) != found.end(); ++it) {
    const long long gap = std::next(it)->first - it->first;
    step = step == 0 ? gap : std::min(step, gap);
  }
  step = std::max(step, 1LL);
  const bool png_colour = found.begin()->second.png && !found.begin()->second.jpg;
  const bool any_colour = std::any_of(found.begin(), found.end(), [](const auto& entry) {
    return entry.second.png || entry.second.jpg;
  });
  FrameList list;
  if (!any_colour) note_depth_alone(*frames_folder, list);
  for (long long n = found.begin()->first; n <= found.rbegin()->first; n += step) {
    const auto it = found.find(n);
    NumberedFiles files = it != found.end() ? it->second : NumberedFiles{};
    if (it == found.end()) files.digits = found.begin()->second.digits;
    char stem[48];
    std::snprintf(stem, sizeof(stem), "frame-%0*lld", files.digits, n);
    const fs::path base = *frames_folder / stem;
    const bool png = files.png || (!files.jpg && png_colour);
    FrameFiles frame{static_cast<double>(n) / 30.0,
                     any_colour ? base.string() + (png ? ".color.png" : ".color.jpg") : "",
                     base.string() + ".depth.png",
                     files.pose ? base.string() + ".pose.txt" : "",
                     {},
                     {},
                     0};
    note_missing(frame);
    list.frames.push_back(std::move(frame));
  }
  const auto camera = folder_camera({*frames_folder, frames_folder->parent_path()});
  list.camera = camera ? *camera : assumed_camera("7scenes", folder, list);
  list.depth_units_per_metre = 1000;
  list.depth_scale_source = "7-Scenes / 3DMatch: millimetres";
  return list;
}

FrameList list_rgb_depth_frames(const fs::path& folder) {
  const std::vector<fs::path> colour =
      fs::is_directory(folder / "rgb") ? images_in(folder / "rgb") : std::vector<fs::path>{};
  const std::vector<fs::path> depth = images_in(folder / "depth");
  std::map<std::string, fs::path> colour_by_stem;
  for (const fs::path& c : colour) colour_by_stem[c.stem().string()] = c;
  const bool same_names = std::all_of(depth.begin(), depth.end(), [&](const fs::path& d) {
    return colour_by_stem.count(d.stem().string()) > 0;
  });
  require(!depth.empty(), quoted(folder / "depth") + ": no PNG depth images");
  FrameList list;
  if (colour.empty()) {  // depth/ alone
    note_depth_alone(folder, list);
    for (std::size_t i = 0; i < depth.size(); ++i)
      list.frames.push_back({static_cast<double>(i) / 30.0, {}, depth[i], {}, {}, {}, 0});
    return with_folder_camera(folder, std::move(list));
  }
  require(same_names || colour.size() == depth.size(),
          quoted(folder) + ": rgb/ holds " + std::to_string(colour.size()) + " images, depth/ " +
              std::to_string(depth.size()) +
              " and their names differ: cannot pair colour with depth (same names, or as many "
              "of each in the same order)");
  for (std::size_t i = 0; i < depth.size(); ++i) {
    const fs::path& c = same_names ? colour_by_stem.at(depth[i].stem().string()) : colour[i];
    list.frames.push_back({static_cast<double>(i) / 30.0, c, depth[i], {}, {}, {}, 0});
  }
  return with_folder_camera(folder, std::move(list));
}

}  // namespace kartograf::io::detail
