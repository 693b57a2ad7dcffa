#include "kartograf/formats/occupancy_map_io.hpp"

#include <unistd.h>

#include <array>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <system_error>
#include <vector>

#include <yaml-cpp/yaml.h>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "formats/atomic_file.hpp"
#include "formats/input_file.hpp"
#include "formats/opencv_decode.hpp"
#include "kartograf/core/error.hpp"
#include "kartograf/formats/image_io.hpp"

namespace kartograf::io {

namespace {

namespace fs = std::filesystem;
using detail::quoted;

// ---- Images ----------------------------------------------------------------------------------

using detail::decode_image;
using detail::pixel_format_name;

void require_8bit(const cv::Mat& image, const std::string& name) {
  require(image.depth() == CV_8U && image.channels() >= 1 && image.channels() <= 4,
          name + ": is " + pixel_format_name(image) + ", expected 8-bit with 1 to 4 channels");
}

// Luminance of an 8-bit image of 1 to 4 channels (OpenCV BGR order; alpha ignored), as
// ipa_room_segmentation reads its maps (imread as grey).
GrayImage to_gray(const cv::Mat& image) {
  cv::Mat gray;
  switch (image.channels()) {
    case 1:
      gray = image;
      break;
    case 2:
      cv::extractChannel(image, gray, 0);
      break;
    case 3:
      cv::cvtColor(image, gray, cv::COLOR_BGR2GRAY);
      break;
    default:
      cv::cvtColor(image, gray, cv::COLOR_BGRA2GRAY);
      break;
  }
  return detail::copy_single_channel<std::uint8_t>(gray);
}

void require_writable_grid(const fs::path& path, const OccupancyGrid& grid) {
  require(!grid.cells.empty(), "cannot write " + quoted(path) + ": the grid is empty (" +
                                   std::to_string(grid.width()) + "x" +
                                   std::to_string(grid.height()) + ")");
  require(std::isfinite(grid.resolution) && grid.resolution > 0,
          "cannot write " + quoted(path) + ": the resolution must be > 0, got " +
              std::to_string(grid.resolution));
  require(grid.origin.allFinite(), "cannot write " + quoted(path) + ": the origin is not finite");
}

// ---- ROS map_server ----------------------------------------------------------------------------

enum class RosMode { trinary, scale };

struct RosMapHeader {
  fs::path image;
  double resolution = 0;
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  double occupied_thresh = 0;
  double free_thresh = 0;
  bool negate = false;
  RosMode mode = RosMode::trinary;
};

// Typed access to the keys of a YAML mapping; every error names the file, the key and its line.
class YamlKeys {
 public:
  YamlKeys(YAML::Node root, std::string file) : root_(std::move(root)), file_(std::move(file)) {}

  bool has(const char* key) const { return static_cast<bool>(root_[key]); }

  YAML::Node get(const char* key) const {
    YAML::Node node = root_[key];
    if (!node || node.IsNull())
      throw Error(file_ + ": missing key '" + key + "' (or it has no value)");
    return node;
  }

  std::string where(const char* key, const YAML::Node& node) const {
    return file_ + ": key '" + key + "' (line " + std::to_string(node.Mark().line + 1) + "): ";
  }

  double number(const char* key, const YAML::Node& node) const {
    if (node.IsScalar()) {
      try {
        const double value = node.as<double>();
        if (std::isfinite(value)) return value;
      } catch (const YAML::Exception&) {
      }
      throw Error(where(key, node) + "expected a finite number, got '" + node.Scalar() + "'");
    }
    throw Error(where(key, node) + "expected a number, got a " +
                (node.IsSequence() ? "list" : "mapping"));
  }
  double number(const char* key) const { return number(key, get(key)); }

  std::string text(const char* key) const {
    const YAML::Node node = get(key);
    require(node.IsScalar() && !node.Scalar().empty(),
            where(key, node) + "expected a non-empty string");
    return node.Scalar();
  }

 private:
  YAML::Node root_;
  std::string file_;
};

RosMapHeader read_ros_header(const fs::path& yaml_path) {
  const std::string file = "ROS map YAML " + quoted(yaml_path);
  // A map YAML is a few lines: read at most kMaxYamlBytes, from a regular file only.
  constexpr std::uintmax_t kMaxYamlBytes = 1 << 20;
  std::error_code error;
  const auto status = fs::status(yaml_path, error);
  if (status.type() == fs::file_type::regular && fs::file_size(yaml_path, error) > kMaxYamlBytes) {
    throw Error(file + ": larger than 1 MB, not a map description");
  }
  const std::vector<std::uint8_t> bytes = detail::read_file_bytes(yaml_path, file);
  YAML::Node root;
  try {
    root = YAML::Load(std::string(bytes.begin(), bytes.end()));
  } catch (const YAML::Exception& e) {
    throw Error(file + ": line " + std::to_string(e.mark.line + 1) + ", column " +
                std::to_string(e.mark.column + 1) + ": not valid YAML: " + e.msg);
  }
  require(root.IsMap(),
          file + ": expected a YAML mapping of keys (image, resolution, origin, ...)");
  const YamlKeys keys(root, file);

  RosMapHeader header;
  header.image = keys.text("image");
  if (header.image.is_relative()) header.image = yaml_path.parent_path() / header.image;

  header.resolution = keys.number("resolution");
  require(header.resolution > 0, keys.where("resolution", keys.get("resolution")) +
                                     "must be > 0, got " + std::to_string(header.resolution));

  const YAML::Node origin = keys.get("origin");
  require(origin.IsSequence() && origin.size() == 3,
          keys.where("origin", origin) + "expected a list of 3 numbers [x, y, yaw]");
  for (std::size_t i = 0; i < 3; ++i) header.origin[i] = keys.number("origin", origin[i]);

  header.occupied_thresh = keys.number("occupied_thresh");
  header.free_thresh = keys.number("free_thresh");
  require(header.free_thresh >= 0 && header.free_thresh <= header.occupied_thresh &&
              header.occupied_thresh <= 1,
          file + ": keys 'free_thresh' " + std::to_string(header.free_thresh) +
              " and 'occupied_thresh' " + std::to_string(header.occupied_thresh) +
              " are out of range: need 0 <= free_thresh <= occupied_thresh <= 1");

  const YAML::Node negate = keys.get("negate");
  bool negate_ok = false;
  if (negate.IsScalar()) {
    try {
      const int value = negate.as<int>();
      negate_ok = value == 0 || value == 1;
      header.negate = value == 1;
    } catch (const YAML::Exception&) {
      try {
        header.negate = negate.as<bool>();
        negate_ok = true;
      } catch (const YAML::Exception&) {
      }
    }
  }
  require(negate_ok, keys.where("negate", negate) + "expected 0, 1, false or true, got '" +
                         (negate.IsScalar() ? negate.Scalar() : std::string("a collection")) + "'");

  if (keys.has("mode")) {
    const std::string mode = keys.text("mode");
    if (mode == "trinary") {
      header.mode = RosMode::trinary;
    } else if (mode == "scale") {
      header.mode = RosMode::scale;
    } else if (mode == "raw") {
      throw Error(keys.where("mode", keys.get("mode")) +
                  "mode 'raw' is not supported: its cells are raw occupancy values, which a "
                  "free/occupied/unknown grid cannot hold; save the map as trinary");
    } else {
      throw Error(keys.where("mode", keys.get("mode")) + "unknown mode '" + mode +
                  "', expected trinary, scale or raw");
    }
  }
  return header;
}

// Shortest text that reads back as the same double.
std::string number_text(double value) {
  char buffer[64];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  return std::string(buffer, result.ptr);
}

// A complete file under a temporary name beside its destination; removed unless published.
class StagedFile {
 public:
  StagedFile(fs::path destination, const std::string& bytes)
      : destination_(std::move(destination)) {
    staged_ = destination_;
    staged_ += ".staged-" + std::to_string(::getpid());
    detail::write_file_atomically(staged_, bytes.data(), bytes.size());
  }
  ~StagedFile() {
    if (published_) return;
    std::error_code ignored;
    fs::remove(staged_, ignored);
  }
  StagedFile(const StagedFile&) = delete;
  StagedFile& operator=(const StagedFile&) = delete;

  void publish() {
    std::error_code error;
    fs::rename(staged_, destination_, error);
    if (error) {
      throw Error("cannot write " + quoted(destination_) + ": cannot rename " + quoted(staged_) +
                  " to it: " + error.message());
    }
    published_ = true;
  }

 private:
  fs::path destination_;
  fs::path staged_;
  bool published_ = false;
};

// ---- Labels ------------------------------------------------------------------------------------

LabelImage labels_from(const cv::Mat& image, const std::string& name) {
  require(image.depth() == CV_16U && image.channels() == 1,
          name + ": is " + pixel_format_name(image) +
              ", expected 16-bit single-channel (labels 0..65535, 0 = no label)");
  return detail::copy_single_channel<Label>(image);
}

LabelImage rooms_from(const cv::Mat& image, const std::string& name,
                      const RoomGroundTruthParams& options) {
  require(options.min_white >= 1 && options.min_white <= 255,
          name + ": min_white must be in 1..255, got " + std::to_string(options.min_white));
  require_8bit(image, name);
  const GrayImage gray = to_gray(image);
  Image<std::uint8_t> white(gray.width(), gray.height());
  for (std::size_t i = 0; i < gray.size(); ++i) {
    white.pixels()[i] = gray.pixels()[i] >= options.min_white ? 1 : 0;
  }
  return label_connected_components(white, {options.connectivity, options.min_room_pixels});
}

// hue in [0, 1) (a fraction of the circle), saturation and value in [0, 1].
Rgb8 hsv_to_rgb(double hue, double saturation, double value) {
  const double sector = hue * 6.0;
  const int i = static_cast<int>(sector) % 6;
  const double f = sector - std::floor(sector);
  const double p = value * (1 - saturation), q = value * (1 - saturation * f),
               t = value * (1 - saturation * (1 - f));
  // (r, g, b) in each sixth of the hue circle.
  const std::array<std::array<double, 3>, 6> sectors = {
      {{value, t, p}, {q, value, p}, {p, value, t}, {p, q, value}, {t, p, value}, {value, p, q}}};
  const std::array<double, 3>& rgb = sectors[i];
  const auto byte = [](double c) { return static_cast<std::uint8_t>(std::lround(c * 255.0)); };
  return {byte(rgb[0]), byte(rgb[1]), byte(rgb[2])};
}

}  // namespace

OccupancyGrid read_ros_map(const fs::path& yaml_path) {
  const RosMapHeader header = read_ros_header(yaml_path);
  const std::string name = "ROS map YAML " + quoted(yaml_path) + ": image " + quoted(header.image);
  const cv::Mat image = decode_image(header.image, name);
  require_8bit(image, name);

  OccupancyGrid grid;
  grid.resolution = header.resolution;
  grid.origin = header.origin;
  grid.cells = Image<CellState>(image.cols, image.rows);
  const int channels = image.channels();
  const bool has_alpha = channels == 2 || channels == 4;
  // map_server's quirk: trinary averages alpha in with the colours, scale leaves it out.
  const int averaged = header.mode == RosMode::scale && has_alpha ? channels - 1 : channels;
  for (int y = 0; y < image.rows; ++y) {
    const std::uint8_t* row = image.ptr<std::uint8_t>(y);
    for (int x = 0; x < image.cols; ++x) {
      const std::uint8_t* pixel = row + static_cast<std::ptrdiff_t>(x) * channels;
      int sum = 0;
      for (int c = 0; c < averaged; ++c) sum += pixel[c];
      double level = static_cast<double>(sum) / averaged;
      if (header.negate) level = 255.0 - level;
      const double p = (255.0 - level) / 255.0;
      grid.cells(x, y) = p > header.occupied_thresh ? CellState::occupied
                         : p < header.free_thresh   ? CellState::free
                                                    : CellState::unknown;
    }
  }
  return grid;
}

void write_ros_map(const fs::path& yaml_path, const OccupancyGrid& grid) {
  require_writable_grid(yaml_path, grid);
  fs::path image_path = yaml_path;
  image_path.replace_extension(".pgm");
  require(image_path != yaml_path, "cannot write " + quoted(yaml_path) +
                                       ": the YAML file must not end in .pgm (the image "
                                       "is written as <stem>.pgm beside it)");

  std::string pgm = "P5\n# CREATOR: kartograf\n" + std::to_string(grid.width()) + " " +
                    std::to_string(grid.height()) + "\n255\n";
  pgm.reserve(pgm.size() + grid.cells.size());
  for (CellState cell : grid.cells.pixels()) {
    pgm.push_back(static_cast<char>(cell == CellState::occupied ? 0
                                    : cell == CellState::free   ? 254
                                                                : 205));
  }

  YAML::Emitter image_name;  // quoted only where YAML needs it
  image_name << image_path.filename().string();
  const std::string yaml = std::string("image: ") + image_name.c_str() +
                           "\nmode: trinary\nresolution: " + number_text(grid.resolution) +
                           "\norigin: [" + number_text(grid.origin.x()) + ", " +
                           number_text(grid.origin.y()) + ", " + number_text(grid.origin.z()) +
                           "]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n";

  // Both complete on disk first; then the image, then the YAML that points at it, take their
  // names. A failure before that leaves the old pair (or nothing) untouched.
  StagedFile staged_image(image_path, pgm);
  StagedFile staged_yaml(yaml_path, yaml);
  staged_image.publish();
  staged_yaml.publish();
}

GrayImage read_map_gray(const fs::path& path) {
  const std::string name = "map image " + quoted(path);
  const cv::Mat image = decode_image(path, name);
  require_8bit(image, name);
  return to_gray(image);
}

OccupancyGrid read_png_map(const fs::path& path, double resolution, int free_threshold) {
  const std::string name = "map image " + quoted(path);
  require(std::isfinite(resolution) && resolution > 0,
          name + ": the resolution must be > 0, got " + std::to_string(resolution));
  require(free_threshold >= 0 && free_threshold <= 255,
          name + ": the free threshold must be in 0..255, got " + std::to_string(free_threshold));
  const GrayImage gray = read_map_gray(path);
  OccupancyGrid grid;
  grid.resolution = resolution;
  grid.cells = Image<CellState>(gray.width(), gray.height());
  for (std::size_t i = 0; i < gray.size(); ++i) {
    grid.cells.pixels()[i] =
        gray.pixels()[i] >= free_threshold ? CellState::free : CellState::occupied;
  }
  return grid;
}

void write_png_map(const fs::path& path, const OccupancyGrid& grid) {
  require_writable_grid(path, grid);
  GrayImage gray(grid.width(), grid.height());
  for (std::size_t i = 0; i < gray.size(); ++i) {
    const CellState cell = grid.cells.pixels()[i];
    gray.pixels()[i] = cell == CellState::free ? 255 : cell == CellState::occupied ? 0 : 205;
  }
  write_png(path, gray);
}

LabelImage read_room_ground_truth_png(const fs::path& path, const RoomGroundTruthParams& options) {
  const std::string name = "room ground truth " + quoted(path);
  return rooms_from(decode_image(path, name), name, options);
}

LabelImage read_ground_truth_rooms(const fs::path& path) {
  const std::string name = "room ground truth " + quoted(path);
  const cv::Mat image = decode_image(path, name);
  if (image.depth() == CV_8U) return rooms_from(image, name, {});
  return labels_from(image, name + " (8-bit: an ipa drawing; 16-bit: labels)");
}

LabelImage read_label_png(const fs::path& path) {
  const std::string name = "label image " + quoted(path);
  return labels_from(decode_image(path, name), name);
}

void write_label_png(const fs::path& path, const LabelImage& labels) {
  write_png(path, labels);  // DepthImage and LabelImage are both 16-bit single-channel images
}

RgbImage colorize_labels(const LabelImage& labels) {
  constexpr double kGoldenRatioConjugate = 0.6180339887498949;
  RgbImage colored(labels.width(), labels.height(), Rgb8{0, 0, 0});
  for (std::size_t i = 0; i < labels.size(); ++i) {
    const Label label = labels.pixels()[i];
    if (label == kUnlabeled) continue;
    const double hue = std::fmod(label * kGoldenRatioConjugate, 1.0);
    // Alternate brightness every 8 labels so that labels with close hues still differ.
    const double value = (label / 8) % 2 == 0 ? 0.95 : 0.7;
    colored.pixels()[i] = hsv_to_rgb(hue, 0.75, value);
  }
  return colored;
}

SemanticImage read_semantic_png(const fs::path& path) {
  const std::string name = "semantic image " + quoted(path);
  const cv::Mat image = decode_image(path, name);
  require(image.depth() == CV_8U && image.channels() == 1,
          name + ": is " + pixel_format_name(image) +
              ", expected 8-bit single-channel (one SemanticClass value per pixel)");
  SemanticImage classes(image.cols, image.rows);
  for (int y = 0; y < image.rows; ++y) {
    const std::uint8_t* row = image.ptr<std::uint8_t>(y);
    for (int x = 0; x < image.cols; ++x) {
      if (row[x] >= kSemanticClassCount) {
        throw Error(name + ": pixel (" + std::to_string(x) + ", " + std::to_string(y) +
                    ") has value " + std::to_string(row[x]) + ", which is no semantic class (0.." +
                    std::to_string(kSemanticClassCount - 1) + ")");
      }
      classes(x, y) = static_cast<SemanticClass>(row[x]);
    }
  }
  return classes;
}

void write_semantic_png(const fs::path& path, const SemanticImage& classes) {
  GrayImage gray(classes.width(), classes.height());
  for (std::size_t i = 0; i < gray.size(); ++i) {
    gray.pixels()[i] = static_cast<std::uint8_t>(classes.pixels()[i]);
  }
  write_png(path, gray);
}

}  // namespace kartograf::io
