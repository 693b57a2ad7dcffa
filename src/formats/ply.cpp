#include "kartograf/formats/ply.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "formats/atomic_file.hpp"
#include "formats/byte_order.hpp"
#include "formats/input_file.hpp"
#include "formats/text_fields.hpp"
#include "kartograf/core/error.hpp"
#include "kartograf/core/memory_budget.hpp"

namespace kartograf::io {

namespace {

using detail::append_little_endian;
using detail::load;
using detail::quoted;

// ---------------------------------------------------------------------------------------------
// Writing

std::string vertex_header(std::size_t count, bool with_normals, bool with_colors,
                          PlyEncoding encoding) {
  std::string header = std::string("ply\nformat ") +
                       (encoding == PlyEncoding::ascii ? "ascii" : "binary_little_endian") +
                       " 1.0\n"
                       "comment written by kartograf\n"
                       "element vertex " +
                       std::to_string(count) +
                       "\n"
                       "property float x\n"
                       "property float y\n"
                       "property float z\n";
  if (with_normals) header += "property float nx\nproperty float ny\nproperty float nz\n";
  if (with_colors) header += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  header += "end_header\n";
  return header;
}

// Streams vertices to the file in blocks so that memory stays small for large clouds.
class VertexWriter {
 public:
  VertexWriter(const std::filesystem::path& path, std::size_t count, bool with_normals,
               bool with_colors, PlyEncoding encoding)
      : file_(path), with_normals_(with_normals), with_colors_(with_colors), encoding_(encoding) {
    file_.write(vertex_header(count, with_normals, with_colors, encoding));
  }

  void add(const Eigen::Vector3f& point, const Eigen::Vector3f& normal, const Rgb8& color) {
    if (encoding_ == PlyEncoding::ascii) {
      add_text(point, normal, color);
    } else {
      add_binary(point, normal, color);
    }
    if (buffer_.size() >= kBlockBytes) flush();
  }

  void commit() {
    flush();
    file_.commit();
  }

 private:
  static constexpr std::size_t kBlockBytes = 1 << 20;

  // Floats in their shortest form that reads back exactly.
  void add_text(const Eigen::Vector3f& point, const Eigen::Vector3f& normal, const Rgb8& color) {
    line_.clear();
    auto put = [&](auto value) {
      std::array<char, 32> text;
      line_.append(text.data(), std::to_chars(text.data(), text.data() + text.size(), value).ptr);
      line_ += ' ';
    };
    for (int i = 0; i < 3; ++i) put(point[i]);
    if (with_normals_) {
      for (int i = 0; i < 3; ++i) put(normal[i]);
    }
    if (with_colors_) {
      for (std::uint8_t channel : color) put(int{channel});
    }
    line_.back() = '\n';
    buffer_.insert(buffer_.end(), line_.begin(), line_.end());
  }

  void add_binary(const Eigen::Vector3f& point, const Eigen::Vector3f& normal, const Rgb8& color) {
    for (int i = 0; i < 3; ++i) append_little_endian(buffer_, point[i]);
    if (with_normals_) {
      for (int i = 0; i < 3; ++i) append_little_endian(buffer_, normal[i]);
    }
    if (with_colors_) buffer_.insert(buffer_.end(), color.begin(), color.end());
  }

  void flush() {
    file_.write(buffer_.data(), buffer_.size());
    buffer_.clear();
  }

  detail::AtomicFileWriter file_;
  std::vector<std::uint8_t> buffer_;  // the next block: vertices in little-endian binary or text
  bool with_normals_;
  bool with_colors_;
  PlyEncoding encoding_;
  std::string line_;  // ascii: the vertex being formatted
};

bool is_finite(const Eigen::Vector3f& v) {
  return v.allFinite();
}

Eigen::Vector3f normal_or_zero(const Point4f& normal) {
  const Eigen::Vector3f n = normal.head<3>();
  return is_finite(n) ? n : Eigen::Vector3f::Zero();
}

template <class Pixel>
void require_same_size(const std::filesystem::path& path, const PointImage& points,
                       const Image<Pixel>& other, const char* what) {
  require(other.width() == points.width() && other.height() == points.height(),
          "cannot write " + quoted(path) + ": " + what + " are " + std::to_string(other.width()) +
              "x" + std::to_string(other.height()) + " but the points are " +
              std::to_string(points.width()) + "x" + std::to_string(points.height()));
}

// ---------------------------------------------------------------------------------------------
// Reading

enum class Scalar { int8, uint8, int16, uint16, int32, uint32, float32, float64 };

std::optional<Scalar> parse_scalar(std::string_view name) {
  if (name == "char" || name == "int8") return Scalar::int8;
  if (name == "uchar" || name == "uint8") return Scalar::uint8;
  if (name == "short" || name == "int16") return Scalar::int16;
  if (name == "ushort" || name == "uint16") return Scalar::uint16;
  if (name == "int" || name == "int32") return Scalar::int32;
  if (name == "uint" || name == "uint32") return Scalar::uint32;
  if (name == "float" || name == "float32") return Scalar::float32;
  if (name == "double" || name == "float64") return Scalar::float64;
  return std::nullopt;
}

std::string_view name_of(Scalar type) {
  switch (type) {
    case Scalar::int8:
      return "char";
    case Scalar::uint8:
      return "uchar";
    case Scalar::int16:
      return "short";
    case Scalar::uint16:
      return "ushort";
    case Scalar::int32:
      return "int";
    case Scalar::uint32:
      return "uint";
    case Scalar::float32:
      return "float";
    case Scalar::float64:
      return "double";
  }
  return "?";
}

std::size_t size_of(Scalar type) {
  switch (type) {
    case Scalar::int8:
    case Scalar::uint8:
      return 1;
    case Scalar::int16:
    case Scalar::uint16:
      return 2;
    case Scalar::int32:
    case Scalar::uint32:
    case Scalar::float32:
      return 4;
    case Scalar::float64:
      return 8;
  }
  return 0;
}

bool is_integer(Scalar type) {
  return type != Scalar::float32 && type != Scalar::float64;
}

// Range of an integer type, for validating ascii values.
std::pair<double, double> integer_range(Scalar type) {
  switch (type) {
    case Scalar::int8:
      return {-128.0, 127.0};
    case Scalar::uint8:
      return {0.0, 255.0};
    case Scalar::int16:
      return {-32768.0, 32767.0};
    case Scalar::uint16:
      return {0.0, 65535.0};
    case Scalar::int32:
      return {-2147483648.0, 2147483647.0};
    case Scalar::uint32:
      return {0.0, 4294967295.0};
    default:
      return {-std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
  }
}

struct Property {
  std::string name;
  Scalar type = Scalar::float32;
  std::optional<Scalar> list_count_type;  // set for "property list <count> <item> <name>"
};

struct Element {
  std::string name;
  std::uint64_t count = 0;
  std::vector<Property> properties;
};

enum class Format { ascii, binary_little_endian, binary_big_endian };

struct Header {
  Format format = Format::ascii;
  std::vector<Element> elements;
  std::size_t body_offset = 0;  // first byte after "end_header\n"
  std::size_t lines = 0;        // header lines, so that body line numbers count from the file start
};

// Fields are separated by spaces and tabs (a line's final '\r' is stripped first).
std::vector<std::string_view> split_whitespace(std::string_view line) {
  return detail::split_fields(line, " \t");
}

std::string_view strip_carriage_return(std::string_view line) {
  if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  return line;
}

double load_scalar(Scalar type, const std::uint8_t* bytes, std::endian order) {
  switch (type) {
    case Scalar::int8:
      return load<std::int8_t>(bytes, order);
    case Scalar::uint8:
      return load<std::uint8_t>(bytes, order);
    case Scalar::int16:
      return load<std::int16_t>(bytes, order);
    case Scalar::uint16:
      return load<std::uint16_t>(bytes, order);
    case Scalar::int32:
      return load<std::int32_t>(bytes, order);
    case Scalar::uint32:
      return load<std::uint32_t>(bytes, order);
    case Scalar::float32:
      return load<float>(bytes, order);
    case Scalar::float64:
      return load<double>(bytes, order);
  }
  return 0;
}

// Which vertex properties hold what the PointCloud needs.
struct VertexFields {
  std::array<int, 3> position{-1, -1, -1};
  std::array<int, 3> normal{-1, -1, -1};
  std::array<int, 3> color{-1, -1, -1};
  bool has_normals() const { return normal[0] >= 0; }
  bool has_colors() const { return color[0] >= 0; }
};

class PlyReader {
 public:
  PlyReader(const std::filesystem::path& path, std::span<const std::uint8_t> bytes)
      : path_(path), bytes_(bytes) {}

  PointCloud read() {
    header_ = parse_header();
    position_ = header_.body_offset;
    line_ = header_.lines;
    for (const Element& element : header_.elements) {
      if (element.name == "vertex") return read_vertices(element);
      skip_element(element);
    }
    fail("has no 'vertex' element");
  }

 private:
  [[noreturn]] void fail(const std::string& problem) const {
    throw Error("PLY file " + quoted(path_) + ": " + problem);
  }
  [[noreturn]] void fail_header(std::size_t line, const std::string& problem) const {
    fail("header line " + std::to_string(line) + ": " + problem);
  }
  [[noreturn]] void fail_at_line(const std::string& problem) const {
    fail("line " + std::to_string(line_) + ": " + problem);
  }
  [[noreturn]] void fail_at_byte(std::size_t offset, const std::string& problem) const {
    fail("byte offset " + std::to_string(offset) + ": " + problem);
  }

  bool binary() const { return header_.format != Format::ascii; }
  std::endian byte_order() const {
    return header_.format == Format::binary_big_endian ? std::endian::big : std::endian::little;
  }

  // The next line from position_ (without its newline), or nothing at the end of the file.
  std::optional<std::string_view> next_line() {
    const auto line = detail::next_line(bytes_, position_, line_);
    if (!line) return std::nullopt;
    return strip_carriage_return(*line);
  }

  Header parse_header() {
    Header header;
    position_ = 0;
    line_ = 0;
    bool saw_format = false;
    const auto first = next_line();
    if (!first || *first != "ply") fail("not a PLY file (the first line is not 'ply')");
    while (true) {
      const auto line = next_line();
      if (!line) fail("the header has no 'end_header' line (truncated or not a PLY file)");
      const std::vector<std::string_view> tokens = split_whitespace(*line);
      if (tokens.empty()) continue;
      const std::string_view keyword = tokens[0];
      if (keyword == "end_header") break;
      if (keyword == "comment" || keyword == "obj_info") continue;
      if (keyword == "format") {
        if (tokens.size() != 3) fail_header(line_, "expected 'format <type> 1.0'");
        if (tokens[1] == "ascii") {
          header.format = Format::ascii;
        } else if (tokens[1] == "binary_little_endian") {
          header.format = Format::binary_little_endian;
        } else if (tokens[1] == "binary_big_endian") {
          header.format = Format::binary_big_endian;
        } else {
          fail_header(line_, "unknown format '" + detail::printable(tokens[1]) + "'");
        }
        if (tokens[2] != "1.0") {
          fail_header(line_, "unsupported PLY version '" + detail::printable(tokens[2]) + "'");
        }
        saw_format = true;
      } else if (keyword == "element") {
        if (tokens.size() != 3) fail_header(line_, "expected 'element <name> <count>'");
        Element element;
        element.name = tokens[1];
        const auto count = detail::parse_number<std::uint64_t>(tokens[2]);
        if (!count) {
          fail_header(line_, "element count '" + detail::printable(tokens[2]) +
                                 "' is not a non-negative integer");
        }
        element.count = *count;
        header.elements.push_back(std::move(element));
      } else if (keyword == "property") {
        if (header.elements.empty()) fail_header(line_, "property before any element");
        header.elements.back().properties.push_back(parse_property(tokens));
      } else {
        fail_header(line_, "unknown keyword '" + detail::printable(keyword) + "'");
      }
    }
    if (!saw_format) fail("the header has no 'format' line");
    header.body_offset = position_;
    header.lines = line_;
    return header;
  }

  Property parse_property(const std::vector<std::string_view>& tokens) const {
    auto scalar = [&](std::string_view name) {
      const auto type = parse_scalar(name);
      if (!type) fail_header(line_, "unknown property type '" + detail::printable(name) + "'");
      return *type;
    };
    Property property;
    if (tokens.size() == 5 && tokens[1] == "list") {
      property.list_count_type = scalar(tokens[2]);
      if (!is_integer(*property.list_count_type)) {
        fail_header(line_, "list count type must be an integer type");
      }
      property.type = scalar(tokens[3]);
      property.name = tokens[4];
    } else if (tokens.size() == 3) {
      property.type = scalar(tokens[1]);
      property.name = tokens[2];
    } else {
      fail_header(line_,
                  "expected 'property <type> <name>' or "
                  "'property list <count type> <item type> <name>'");
    }
    return property;
  }

  VertexFields find_fields(const Element& vertex) const {
    VertexFields fields;
    auto find = [&](std::string_view name) {
      for (std::size_t i = 0; i < vertex.properties.size(); ++i) {
        if (vertex.properties[i].name == name) {
          if (vertex.properties[i].list_count_type) {
            fail("vertex property '" + detail::printable(name) + "' is a list, expected a scalar");
          }
          return static_cast<int>(i);
        }
      }
      return -1;
    };
    // All three or none: a cloud with a missing coordinate is corrupt, not partial.
    auto find_triple = [&](std::array<std::string_view, 3> names, std::array<int, 3>& out,
                           bool required) {
      for (int i = 0; i < 3; ++i) out[i] = find(names[i]);
      const int found = static_cast<int>(
          std::count_if(out.begin(), out.end(), [](int index) { return index >= 0; }));
      if (found == 3 || (found == 0 && !required)) return;
      for (int i = 0; i < 3; ++i) {
        if (out[i] < 0) fail("vertex element has no '" + std::string(names[i]) + "' property");
      }
    };
    find_triple({"x", "y", "z"}, fields.position, true);
    find_triple({"nx", "ny", "nz"}, fields.normal, false);
    find_triple({"red", "green", "blue"}, fields.color, false);
    for (int index : fields.color) {
      if (index >= 0 && vertex.properties[index].type != Scalar::uint8) {
        const Property& property = vertex.properties[index];
        fail("vertex property '" + property.name + "' is " + std::string(name_of(property.type)) +
             "; only uchar colours are supported");
      }
    }
    return fields;
  }

  PointCloud read_vertices(const Element& vertex) {
    const VertexFields fields = find_fields(vertex);
    PointCloud cloud;
    // A corrupt count must not allocate: every vertex takes at least 2 bytes ("0\n" or a uchar).
    const std::size_t remaining = bytes_.size() - position_;
    const std::size_t reservation =
        static_cast<std::size_t>(std::min<std::uint64_t>(vertex.count, remaining / 2 + 1));
    const double vertex_bytes = sizeof(Eigen::Vector3f) * (fields.has_normals() ? 2.0 : 1.0) +
                                (fields.has_colors() ? sizeof(Rgb8) : 0);
    require_fits_in_memory(
        static_cast<double>(reservation) * vertex_bytes,
        "PLY file " + quoted(path_) + " (" + std::to_string(vertex.count) + " vertices)");
    cloud.points.reserve(reservation);
    if (fields.has_normals()) cloud.normals.reserve(reservation);
    if (fields.has_colors()) cloud.colors.reserve(reservation);

    std::vector<double> values(vertex.properties.size());
    for (std::uint64_t i = 0; i < vertex.count; ++i) {
      read_instance(vertex, i, values);
      auto vector_at = [&](const std::array<int, 3>& index) {
        return Eigen::Vector3f(static_cast<float>(values[index[0]]),
                               static_cast<float>(values[index[1]]),
                               static_cast<float>(values[index[2]]));
      };
      cloud.points.push_back(vector_at(fields.position));
      if (fields.has_normals()) cloud.normals.push_back(vector_at(fields.normal));
      if (fields.has_colors()) {
        cloud.colors.push_back({static_cast<std::uint8_t>(values[fields.color[0]]),
                                static_cast<std::uint8_t>(values[fields.color[1]]),
                                static_cast<std::uint8_t>(values[fields.color[2]])});
      }
    }
    return cloud;
  }

  void skip_element(const Element& element) {
    // An element without properties occupies no bytes; do not walk a possibly huge count.
    if (element.properties.empty()) return;
    std::vector<double> values(element.properties.size());
    for (std::uint64_t i = 0; i < element.count; ++i) read_instance(element, i, values);
  }

  std::string instance_name(const Element& element, std::uint64_t index) const {
    return detail::printable(element.name) + " index " + std::to_string(index) + " (of " +
           std::to_string(element.count) + ")";
  }

  // Reads one instance of element into values (one per property; lists are skipped).
  void read_instance(const Element& element, std::uint64_t index, std::vector<double>& values) {
    if (binary()) {
      read_binary_instance(element, index, values);
    } else {
      read_ascii_instance(element, index, values);
    }
  }

  void read_binary_instance(const Element& element, std::uint64_t index,
                            std::vector<double>& values) {
    const std::size_t start = position_;
    auto take = [&](std::size_t bytes) {
      if (bytes > bytes_.size() - position_) {
        fail_at_byte(start, "truncated: " + instance_name(element, index) +
                                " extends past the end of the file (" +
                                std::to_string(bytes_.size()) + " bytes)");
      }
      const std::uint8_t* data = bytes_.data() + position_;
      position_ += bytes;
      return data;
    };
    for (std::size_t p = 0; p < element.properties.size(); ++p) {
      const Property& property = element.properties[p];
      if (property.list_count_type) {
        const double count = load_scalar(*property.list_count_type,
                                         take(size_of(*property.list_count_type)), byte_order());
        if (count < 0) {
          fail_at_byte(start, instance_name(element, index) + ": list '" +
                                  detail::printable(property.name) + "' has negative length " +
                                  std::to_string(count));
        }
        const double bytes = count * static_cast<double>(size_of(property.type));
        take(bytes > static_cast<double>(bytes_.size()) ? bytes_.size() + 1
                                                        : static_cast<std::size_t>(bytes));
        values[p] = 0;
      } else {
        values[p] = load_scalar(property.type, take(size_of(property.type)), byte_order());
      }
    }
  }

  void read_ascii_instance(const Element& element, std::uint64_t index,
                           std::vector<double>& values) {
    std::optional<std::string_view> line;
    std::vector<std::string_view> tokens;
    do {
      line = next_line();
      if (!line) {
        fail("truncated: the file ends after line " + std::to_string(line_) + " but " +
             instance_name(element, index) + " is missing");
      }
      tokens = split_whitespace(*line);
    } while (tokens.empty());

    std::size_t next = 0;
    auto number = [&](Scalar type, const std::string& what) {
      if (next >= tokens.size()) {
        fail_at_line(instance_name(element, index) + ": too few values (missing " + what + ")");
      }
      const std::string_view token = tokens[next++];
      const auto parsed = detail::parse_number<double>(token);
      if (!parsed) {
        fail_at_line(instance_name(element, index) + ": " + what + " is '" +
                     detail::printable(token) + "', not a number");
      }
      const double value = *parsed;
      if (is_integer(type)) {
        const auto [low, high] = integer_range(type);
        if (value != std::floor(value) || value < low || value > high) {
          fail_at_line(instance_name(element, index) + ": " + what + " is '" +
                       detail::printable(token) + "', not a valid " + std::string(name_of(type)));
        }
      }
      return value;
    };
    for (std::size_t p = 0; p < element.properties.size(); ++p) {
      const Property& property = element.properties[p];
      if (property.list_count_type) {
        const double count = number(*property.list_count_type,
                                    "length of '" + detail::printable(property.name) + "'");
        if (count < 0 || count > static_cast<double>(tokens.size())) {
          fail_at_line(instance_name(element, index) + ": list '" +
                       detail::printable(property.name) + "' has impossible length " +
                       std::string(tokens[next - 1]));
        }
        for (std::size_t k = 0; k < static_cast<std::size_t>(count); ++k) {
          number(property.type, "item of '" + property.name + "'");
        }
        values[p] = 0;
      } else {
        values[p] = number(property.type, "'" + property.name + "'");
      }
    }
    if (next != tokens.size()) {
      fail_at_line(instance_name(element, index) + ": " + std::to_string(tokens.size()) +
                   " values, expected " + std::to_string(next));
    }
  }

  std::filesystem::path path_;
  std::span<const std::uint8_t> bytes_;
  Header header_;
  std::size_t position_ = 0;  // byte offset of the next unread byte
  std::size_t line_ = 0;      // 1-based number of the last line read (ascii and header)
};

}  // namespace

void write_ply(const std::filesystem::path& path, const PointImage& points,
               const NormalImage* normals, const RgbImage* colors, PlyEncoding encoding) {
  if (normals) require_same_size(path, points, *normals, "the normals");
  if (colors) require_same_size(path, points, *colors, "the colours");
  const auto all_points = points.pixels();
  const std::size_t count = static_cast<std::size_t>(
      std::count_if(all_points.begin(), all_points.end(),
                    [](const Point4f& p) { return is_finite(Eigen::Vector3f(p.head<3>())); }));

  VertexWriter writer(path, count, normals != nullptr, colors != nullptr, encoding);
  const Rgb8 no_color{0, 0, 0};
  for (std::size_t i = 0; i < all_points.size(); ++i) {
    const Eigen::Vector3f point = all_points[i].head<3>();
    if (!is_finite(point)) continue;
    writer.add(point, normals ? normal_or_zero(normals->pixels()[i]) : Eigen::Vector3f::Zero(),
               colors ? colors->pixels()[i] : no_color);
  }
  writer.commit();
}

void write_ply(const std::filesystem::path& path, const PointCloud& cloud, PlyEncoding encoding) {
  auto check_count = [&](std::size_t count, const char* what) {
    require(count == 0 || count == cloud.size(), "cannot write " + quoted(path) + ": " +
                                                     std::to_string(count) + " " + what + " for " +
                                                     std::to_string(cloud.size()) + " points");
  };
  check_count(cloud.normals.size(), "normals");
  check_count(cloud.colors.size(), "colours");
  const std::size_t count =
      static_cast<std::size_t>(std::count_if(cloud.points.begin(), cloud.points.end(), is_finite));

  VertexWriter writer(path, count, cloud.has_normals(), cloud.has_colors(), encoding);
  const Rgb8 no_color{0, 0, 0};
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (!is_finite(cloud.points[i])) continue;
    const Eigen::Vector3f normal = cloud.has_normals() && is_finite(cloud.normals[i])
                                       ? cloud.normals[i]
                                       : Eigen::Vector3f::Zero();
    writer.add(cloud.points[i], normal, cloud.has_colors() ? cloud.colors[i] : no_color);
  }
  writer.commit();
}

PointCloud read_ply(const std::filesystem::path& path) {
  const std::vector<std::uint8_t> bytes = detail::read_file_bytes(path, "PLY file " + quoted(path));
  return PlyReader(path, bytes).read();
}

PointCloud parse_ply(std::span<const std::uint8_t> bytes, const std::string& name) {
  return PlyReader(std::filesystem::path(name), bytes).read();
}

}  // namespace kartograf::io
