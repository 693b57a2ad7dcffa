#include "kartograf/formats/pcd.hpp"

#include <lzf.h>

#include <algorithm>
#include <array>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <optional>
#include <string_view>
#include <utility>

#include "formats/atomic_file.hpp"
#include "formats/byte_order.hpp"
#include "formats/input_file.hpp"
#include "formats/text_fields.hpp"
#include "kartograf/core/error.hpp"
#include "kartograf/core/memory_budget.hpp"

namespace kartograf::io {

namespace {

// "'<name>'": how messages name files (names are plain strings so that data in memory has one).
std::string quoted(const std::string& name) {
  return detail::quoted(std::filesystem::path(name));
}

// A point of more bytes than this is a corrupt header, not data (PCL's widest, FPFH, is 132).
constexpr std::uint64_t kMaxPointBytes = std::uint64_t{1} << 32;
// LZF encodes at most 264 bytes in one 3-byte back reference, so no valid stream expands more
// than 88 times; a larger claim is corrupt, and refusing it keeps a small file from allocating
// gigabytes before the decompressor notices.
constexpr std::uint64_t kMaxLzfRatio = 100;

// "a x b" bytes as text, without overflowing.
std::string product_text(std::uint64_t a, std::uint64_t b) {
  if (b != 0 && a > std::numeric_limits<std::uint64_t>::max() / b) return "more than 2^64";
  return std::to_string(a * b);
}

// ---------------------------------------------------------------------------------------------
// Bytes and numbers

// PCD binary data is in the writer's byte order, which is little-endian on every platform PCL
// and Open3D run on: detail::load's default.
using detail::append_little_endian;
using detail::load;

// Fields are separated by blanks; a '\r' anywhere (CRLF files) is one too.
std::vector<std::string_view> split_whitespace(std::string_view line) {
  return detail::split_fields(line, " \t\r");
}

// PCD numbers may carry a leading '+', which std::from_chars does not take.
std::string_view without_plus(std::string_view token) {
  if (token.size() > 1 && token[0] == '+') token.remove_prefix(1);
  return token;
}

// Decimal numbers as PCL writes them: "nan", "inf", exponents, a leading '+'. Parsed straight to
// Real so that floats are rounded once; a value beyond Real's range becomes 0 or infinity, as
// strtof makes it (where detail::parse_number refuses it).
template <class Real>
std::optional<Real> parse_real(std::string_view token) {
  token = without_plus(token);
  Real value = 0;
  const auto [end, error] = std::from_chars(token.data(), token.data() + token.size(), value);
  if (end != token.data() + token.size()) return std::nullopt;
  if (error == std::errc::result_out_of_range) {
    const double wide = std::strtod(std::string(token).c_str(), nullptr);
    return static_cast<Real>(wide);
  }
  if (error != std::errc()) return std::nullopt;
  return value;
}

template <class Integer>
std::optional<Integer> parse_integer(std::string_view token) {
  return detail::parse_number<Integer>(without_plus(token));
}

bool all_digits(std::string_view token) {
  return !token.empty() &&
         std::all_of(token.begin(), token.end(), [](char c) { return c >= '0' && c <= '9'; });
}

// The shortest text that reads back as the same float; NaN of any sign or payload as "nan".
// With `digits`, that many significant digits instead: 9 read back exactly even through a
// double, as PCL's reader does with denormals.
void append_float(std::string& out, float value, std::optional<int> digits = std::nullopt) {
  if (std::isnan(value)) {
    out += "nan";
    return;
  }
  std::array<char, 32> text;
  const auto result = digits ? std::to_chars(text.data(), text.data() + text.size(), value,
                                             std::chars_format::general, *digits)
                             : std::to_chars(text.data(), text.data() + text.size(), value);
  out.append(text.data(), result.ptr);
}

void append_double(std::string& out, double value) {
  std::array<char, 32> text;
  const auto result = std::to_chars(text.data(), text.data() + text.size(), value);
  out.append(text.data(), result.ptr);
}

// PCL's colour word, r << 16 | g << 8 | b: not the device layout of kartograf::pack_rgb.
std::uint32_t pack_pcl_rgb(const Rgb8& color) {
  return (std::uint32_t{color[0]} << 16) | (std::uint32_t{color[1]} << 8) | color[2];
}

Rgb8 unpack_pcl_rgb(std::uint32_t packed) {
  return {static_cast<std::uint8_t>(packed >> 16), static_cast<std::uint8_t>(packed >> 8),
          static_cast<std::uint8_t>(packed)};
}

bool is_finite(const Eigen::Vector3f& p) {
  return p.allFinite();
}

// ---------------------------------------------------------------------------------------------
// Header

struct Field {
  std::string name;
  char type = 'F';                // F (float), I (signed), U (unsigned)
  std::uint64_t size = 4;         // bytes per value
  std::uint64_t count = 1;        // values per point
  std::uint64_t offset = 0;       // bytes before this field in one binary point
  std::uint64_t first_value = 0;  // values before this field on one ascii line
};

struct Header {
  std::vector<Field> fields;
  std::uint64_t width = 0;
  std::uint64_t height = 0;
  std::uint64_t points = 0;
  Eigen::Isometry3d viewpoint = Eigen::Isometry3d::Identity();
  PcdEncoding encoding = PcdEncoding::ascii;
  std::uint64_t point_bytes = 0;   // binary: bytes per point
  std::uint64_t point_values = 0;  // ascii: values per point
};

// The fields Kartograf keeps; absent ones are null.
struct KnownFields {
  std::array<const Field*, 3> position{};
  std::array<const Field*, 3> normal{};
  const Field* color = nullptr;  // rgb or rgba
  const Field* label = nullptr;
};

enum Keyword {
  kVersion,
  kFields,
  kSize,
  kType,
  kCount,
  kWidth,
  kHeight,
  kViewpoint,
  kPoints,
  kData
};
constexpr std::array<std::string_view, 10> kKeywords = {
    "VERSION", "FIELDS", "SIZE", "TYPE", "COUNT", "WIDTH", "HEIGHT", "VIEWPOINT", "POINTS", "DATA"};

struct HeaderLine {
  std::size_t number = 0;  // 0: absent
  std::vector<std::string_view> values;
};

class PcdParser {
 public:
  PcdParser(std::span<const std::uint8_t> bytes, const std::string& name)
      : bytes_(bytes), name_(name) {}

  PcdCloud parse() {
    const Header header = parse_header();
    const KnownFields known = find_fields(header);
    PcdCloud cloud;
    cloud.width = static_cast<int>(header.width);
    cloud.height = static_cast<int>(header.height);
    cloud.viewpoint = header.viewpoint;
    switch (header.encoding) {
      case PcdEncoding::ascii:
        read_ascii(header, known, cloud);
        break;
      case PcdEncoding::binary:
        read_binary(header, known, cloud);
        break;
      case PcdEncoding::binary_compressed:
        read_compressed(header, known, cloud);
        break;
    }
    return cloud;
  }

 private:
  [[noreturn]] void fail(const std::string& problem) const {
    throw Error("PCD file " + quoted(name_) + ": " + problem);
  }
  [[noreturn]] void fail_header(std::size_t line, const std::string& problem) const {
    fail("header line " + std::to_string(line) + ": " + problem);
  }
  [[noreturn]] void fail_at_byte(std::uint64_t offset, const std::string& problem) const {
    fail("byte offset " + std::to_string(offset) + ": " + problem);
  }

  // The next line from position_ (without its newline), or nothing at the end of the bytes.
  std::optional<std::string_view> next_line() {
    return detail::next_line(bytes_, position_, line_);
  }

  std::size_t remaining() const { return bytes_.size() - position_; }

  // --- header -------------------------------------------------------------------------------

  Header parse_header() {
    std::array<HeaderLine, kKeywords.size()> lines;
    while (lines[kData].number == 0) {
      const auto line = next_line();
      if (!line) {
        fail(line_ == 0 ? "empty file, not a PCD file"
                        : "the header ends after line " + std::to_string(line_) +
                              " without a DATA line (truncated or not a PCD file)");
      }
      std::vector<std::string_view> tokens = split_whitespace(*line);
      if (tokens.empty() || tokens[0][0] == '#') continue;
      std::string_view keyword = tokens[0];
      if (keyword == "COLUMNS") keyword = "FIELDS";  // PCD v0.5
      const auto found = std::find(kKeywords.begin(), kKeywords.end(), keyword);
      if (found == kKeywords.end()) {
        fail_header(line_, "unknown keyword '" + detail::printable(tokens[0]) +
                               "' (not a PCD file, or a corrupt header)");
      }
      HeaderLine& entry = lines[static_cast<std::size_t>(found - kKeywords.begin())];
      if (entry.number != 0) {
        fail_header(line_, std::string(keyword) + " given again (first on header line " +
                               std::to_string(entry.number) + ")");
      }
      entry.number = line_;
      entry.values.assign(tokens.begin() + 1, tokens.end());
    }

    Header header;
    header.fields = parse_fields(lines);
    for (Field& field : header.fields) {
      field.offset = header.point_bytes;
      field.first_value = header.point_values;
      header.point_bytes += field.size * field.count;
      header.point_values += field.count;
      if (header.point_bytes > kMaxPointBytes) {
        fail_header(lines[kCount].number, "the fields take more than " +
                                              std::to_string(kMaxPointBytes) + " bytes per point");
      }
    }
    parse_dimensions(lines, header);
    if (lines[kViewpoint].number != 0) header.viewpoint = parse_viewpoint(lines[kViewpoint]);
    header.encoding = parse_encoding(lines[kData]);
    return header;
  }

  std::vector<Field> parse_fields(const std::array<HeaderLine, kKeywords.size()>& lines) const {
    const HeaderLine& names = lines[kFields];
    if (names.number == 0) fail("the header has no FIELDS line");
    if (names.values.empty()) fail_header(names.number, "FIELDS names no field");
    const std::size_t n = names.values.size();
    auto require_line = [&](Keyword keyword, bool required) -> const HeaderLine* {
      const HeaderLine& line = lines[keyword];
      if (line.number == 0) {
        if (required) fail("the header has no " + std::string(kKeywords[keyword]) + " line");
        return nullptr;
      }
      if (line.values.size() != n) {
        fail_header(line.number, std::string(kKeywords[keyword]) + " has " +
                                     std::to_string(line.values.size()) +
                                     " values but FIELDS (line " + std::to_string(names.number) +
                                     ") names " + std::to_string(n) + " fields");
      }
      return &line;
    };
    const HeaderLine* sizes = require_line(kSize, true);
    const HeaderLine* types = require_line(kType, true);
    const HeaderLine* counts = require_line(kCount, false);  // PCD v0.6 has none: all 1

    std::vector<Field> fields(n);
    for (std::size_t i = 0; i < n; ++i) {
      Field& field = fields[i];
      field.name = names.values[i];
      const std::string_view type = types->values[i];
      if (type != "F" && type != "I" && type != "U") {
        fail_header(types->number, "TYPE '" + detail::printable(type) + "' of field '" +
                                       detail::printable(field.name) + "' is not F, I or U");
      }
      field.type = type[0];
      const auto size = parse_integer<std::uint64_t>(sizes->values[i]);
      const bool valid_size =
          size && (field.type == 'F' ? (*size == 4 || *size == 8)
                                     : (*size == 1 || *size == 2 || *size == 4 || *size == 8));
      if (!valid_size) {
        fail_header(sizes->number, "SIZE '" + detail::printable(sizes->values[i]) + "' of field '" +
                                       detail::printable(field.name) + "' is not valid for TYPE " +
                                       field.type +
                                       (field.type == 'F' ? " (4 or 8)" : " (1, 2, 4 or 8)"));
      }
      field.size = *size;
      if (counts) {
        const auto count = parse_integer<std::uint64_t>(counts->values[i]);
        if (!count || *count == 0 || *count > std::numeric_limits<std::uint32_t>::max()) {
          fail_header(counts->number, "COUNT '" + detail::printable(counts->values[i]) +
                                          "' of field '" + detail::printable(field.name) +
                                          "' is not a positive 32-bit integer");
        }
        field.count = *count;
      }
    }
    return fields;
  }

  std::uint64_t parse_count(const HeaderLine& line, std::string_view keyword) const {
    const auto value =
        line.values.size() == 1 ? parse_integer<std::uint64_t>(line.values[0]) : std::nullopt;
    if (!value) {
      fail_header(line.number, std::string(keyword) + " must be one non-negative integer");
    }
    return *value;
  }

  void parse_dimensions(const std::array<HeaderLine, kKeywords.size()>& lines,
                        Header& header) const {
    const HeaderLine& width = lines[kWidth];
    const HeaderLine& height = lines[kHeight];
    const HeaderLine& points = lines[kPoints];
    if (width.number == 0 && points.number == 0) fail("the header has neither WIDTH nor POINTS");
    // PCD v0.5 has POINTS only: an unorganized cloud.
    header.points = points.number ? parse_count(points, "POINTS") : 0;
    header.width = width.number ? parse_count(width, "WIDTH") : header.points;
    header.height = height.number ? parse_count(height, "HEIGHT") : 1;
    constexpr std::uint64_t max_dim = static_cast<std::uint64_t>(std::numeric_limits<int>::max());
    if (header.width > max_dim)
      fail_header(width.number, "WIDTH " + std::to_string(header.width) + " is too large");
    if (header.height > max_dim) {
      fail_header(height.number, "HEIGHT " + std::to_string(header.height) + " is too large");
    }
    const std::uint64_t product = header.width * header.height;  // < 2^62: no overflow
    if (points.number == 0) header.points = product;
    if (header.points != product) {
      fail_header(points.number, "POINTS " + std::to_string(header.points) +
                                     " but WIDTH x HEIGHT = " + std::to_string(header.width) +
                                     " x " + std::to_string(header.height) + " = " +
                                     std::to_string(product));
    }
  }

  Eigen::Isometry3d parse_viewpoint(const HeaderLine& line) const {
    std::array<double, 7> v{};
    bool valid = line.values.size() == 7;
    for (std::size_t i = 0; valid && i < 7; ++i) {
      const auto value = parse_real<double>(line.values[i]);
      valid = value && std::isfinite(*value);
      if (valid) v[i] = *value;
    }
    if (!valid)
      fail_header(line.number, "VIEWPOINT must be 7 finite numbers: tx ty tz qw qx qy qz");
    const Eigen::Quaterniond q(v[3], v[4], v[5], v[6]);
    if (q.norm() < 1e-6) fail_header(line.number, "VIEWPOINT has a zero quaternion");
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.linear() = q.normalized().toRotationMatrix();
    pose.translation() = Eigen::Vector3d(v[0], v[1], v[2]);
    return pose;
  }

  PcdEncoding parse_encoding(const HeaderLine& line) const {
    if (line.values.size() == 1) {
      if (line.values[0] == "ascii") return PcdEncoding::ascii;
      if (line.values[0] == "binary") return PcdEncoding::binary;
      if (line.values[0] == "binary_compressed") return PcdEncoding::binary_compressed;
    }
    fail_header(line.number, "DATA must be ascii, binary or binary_compressed");
  }

  KnownFields find_fields(const Header& header) const {
    KnownFields known;
    auto claim = [&](const Field& field, const Field*& slot) {
      if (slot) fail("field '" + field.name + "' appears twice in FIELDS");
      if (field.count != 1) {
        fail("field '" + field.name + "' has COUNT " + std::to_string(field.count) +
             "; expected 1");
      }
      slot = &field;
    };
    constexpr std::array<std::string_view, 3> xyz = {"x", "y", "z"};
    constexpr std::array<std::string_view, 3> normal = {"normal_x", "normal_y", "normal_z"};
    for (const Field& field : header.fields) {
      for (std::size_t axis = 0; axis < 3; ++axis) {
        if (field.name == xyz[axis]) claim(field, known.position[axis]);
        if (field.name == normal[axis]) claim(field, known.normal[axis]);
      }
      if (field.name == "rgb" || field.name == "rgba") {
        if (known.color) {
          fail("fields '" + detail::printable(known.color->name) + "' and '" +
               detail::printable(field.name) + "' both hold colours");
        }
        claim(field, known.color);
        if (field.size != 4) {
          fail("field '" + field.name + "' has SIZE " + std::to_string(field.size) +
               "; a packed colour takes 4 bytes");
        }
      }
      if (field.name == "label") {
        claim(field, known.label);
        if (field.type == 'F') fail("field 'label' has TYPE F; labels are integers");
      }
    }
    for (std::size_t axis = 0; axis < 3; ++axis) {
      if (!known.position[axis]) fail("has no '" + std::string(xyz[axis]) + "' field");
    }
    const auto normals = std::count(known.normal.begin(), known.normal.end(), nullptr);
    if (normals == 1 || normals == 2) {
      fail("has some but not all of the fields normal_x, normal_y, normal_z");
    }
    return known;
  }

  // --- binary data ------------------------------------------------------------------------------

  static double number_at(const Field& field, const std::uint8_t* p) {
    switch (field.type) {
      case 'F':
        return field.size == 4 ? load<float>(p) : load<double>(p);
      case 'I':
        switch (field.size) {
          case 1:
            return load<std::int8_t>(p);
          case 2:
            return load<std::int16_t>(p);
          case 4:
            return load<std::int32_t>(p);
          default:
            return static_cast<double>(load<std::int64_t>(p));
        }
      default:
        switch (field.size) {
          case 1:
            return load<std::uint8_t>(p);
          case 2:
            return load<std::uint16_t>(p);
          case 4:
            return load<std::uint32_t>(p);
          default:
            return static_cast<double>(load<std::uint64_t>(p));
        }
    }
  }

  // A label value, or nothing when it is negative or wider than 32 bits (a double holds every
  // integer in that range exactly, and the label field is never F).
  static std::optional<std::uint32_t> label_at(const Field& field, const std::uint8_t* p) {
    const double value = number_at(field, p);
    if (value < 0 || value > std::numeric_limits<std::uint32_t>::max()) return std::nullopt;
    return static_cast<std::uint32_t>(value);
  }

  // Fills cloud from binary values; value(field, i) points at field's first value of point i and
  // where(i) says where point i is, for messages.
  template <class Value, class Where>
  void decode(const Header& header, const KnownFields& known, PcdCloud& cloud, Value value,
              Where where) const {
    const std::size_t n = static_cast<std::size_t>(header.points);
    auto vector_at = [&](const std::array<const Field*, 3>& f, std::size_t i) {
      return Eigen::Vector3f(static_cast<float>(number_at(*f[0], value(*f[0], i))),
                             static_cast<float>(number_at(*f[1], value(*f[1], i))),
                             static_cast<float>(number_at(*f[2], value(*f[2], i))));
    };
    cloud.points.resize(n);
    for (std::size_t i = 0; i < n; ++i) cloud.points[i] = vector_at(known.position, i);
    if (known.normal[0]) {
      cloud.normals.resize(n);
      for (std::size_t i = 0; i < n; ++i) cloud.normals[i] = vector_at(known.normal, i);
    }
    if (known.color) {
      cloud.colors.resize(n);
      for (std::size_t i = 0; i < n; ++i) {
        cloud.colors[i] = unpack_pcl_rgb(load<std::uint32_t>(value(*known.color, i)));
      }
    }
    if (known.label) {
      cloud.labels.resize(n);
      for (std::size_t i = 0; i < n; ++i) {
        const auto label = label_at(*known.label, value(*known.label, i));
        if (!label) fail(where(i) + ": label is negative or wider than 32 bits");
        cloud.labels[i] = *label;
      }
    }
  }

  // The cloud (and `staging_bytes` of decompressed data) must fit in memory: checked before
  // allocating, since LZF data expands up to 88 times and POINTS is the file's word.
  void require_memory(const Header& header, const KnownFields& known,
                      std::uint64_t staging_bytes) const {
    const double per_point = sizeof(Eigen::Vector3f) * (known.normal[0] ? 2.0 : 1.0) +
                             (known.color ? sizeof(Rgb8) : 0) +
                             (known.label ? sizeof(std::uint32_t) : 0);
    require_fits_in_memory(
        static_cast<double>(header.points) * per_point + static_cast<double>(staging_bytes),
        "PCD file " + quoted(name_) + " (" + std::to_string(header.points) + " points)");
  }

  std::string point_name(std::uint64_t i, std::uint64_t n) const {
    return "point " + std::to_string(i) + " (of " + std::to_string(n) + ")";
  }

  void read_binary(const Header& header, const KnownFields& known, PcdCloud& cloud) const {
    // point_bytes > 0 (x, y and z exist), so the division cannot fail and nothing overflows.
    if (header.points > remaining() / header.point_bytes) {
      fail_at_byte(position_, "truncated: POINTS " + std::to_string(header.points) + " x " +
                                  std::to_string(header.point_bytes) + " bytes per point need " +
                                  product_text(header.points, header.point_bytes) +
                                  " bytes of binary data but the file has " +
                                  std::to_string(remaining()) + " after the header");
    }
    require_memory(header, known, 0);
    const std::uint8_t* data = bytes_.data() + position_;
    const std::size_t step = static_cast<std::size_t>(header.point_bytes);
    decode(
        header, known, cloud,
        [&](const Field& f, std::size_t i) { return data + i * step + f.offset; },
        [&](std::size_t i) {
          return "byte offset " + std::to_string(position_ + i * step) + " (" +
                 point_name(i, header.points) + ")";
        });
  }

  void read_compressed(const Header& header, const KnownFields& known, PcdCloud& cloud) const {
    const std::size_t start = position_;
    if (remaining() < 8) {
      fail_at_byte(start,
                   "truncated: binary_compressed data needs an 8-byte size header, the file "
                   "has " +
                       std::to_string(remaining()) + " bytes after the header");
    }
    const std::uint64_t compressed = load<std::uint32_t>(bytes_.data() + start);
    const std::uint64_t uncompressed = load<std::uint32_t>(bytes_.data() + start + 4);
    // uncompressed < 2^32 and point_bytes <= 2^32: the product is only formed when it fits.
    if (header.points > std::numeric_limits<std::uint32_t>::max() ||
        header.points * header.point_bytes != uncompressed) {
      fail_at_byte(start + 4,
                   "LZF size mismatch: the data claims " + std::to_string(uncompressed) +
                       " bytes uncompressed but POINTS " + std::to_string(header.points) + " x " +
                       std::to_string(header.point_bytes) +
                       " bytes per point = " + product_text(header.points, header.point_bytes));
    }
    if (compressed > remaining() - 8) {
      fail_at_byte(start, "truncated: " + std::to_string(compressed) +
                              " bytes of LZF data announced, the file has " +
                              std::to_string(remaining() - 8) + " after the size header");
    }
    if (uncompressed > compressed * kMaxLzfRatio) {
      fail_at_byte(start, "LZF size mismatch: " + std::to_string(compressed) +
                              " compressed bytes cannot hold " + std::to_string(uncompressed) +
                              " bytes (LZF compresses at most 88:1)");
    }
    require_memory(header, known, uncompressed);
    std::vector<std::uint8_t> soa(static_cast<std::size_t>(uncompressed));
    if (uncompressed > 0) {
      const unsigned int produced =
          lzf_decompress(bytes_.data() + start + 8, static_cast<unsigned int>(compressed),
                         soa.data(), static_cast<unsigned int>(uncompressed));
      if (produced != uncompressed) {
        fail_at_byte(start + 8, "LZF size mismatch: the data decompresses to " +
                                    (produced == 0 ? std::string("an error (corrupt or longer than "
                                                                 "announced)")
                                                   : std::to_string(produced) + " bytes") +
                                    ", expected " + std::to_string(uncompressed));
      }
    }
    // Field by field: all values of the first field, then all of the second, ...
    const std::uint8_t* data = soa.data();
    const std::size_t n = static_cast<std::size_t>(header.points);
    decode(
        header, known, cloud,
        [&](const Field& f, std::size_t i) {
          return data + n * f.offset + i * static_cast<std::size_t>(f.size * f.count);
        },
        [&](std::size_t i) { return "compressed data, " + point_name(i, n); });
  }

  // --- ascii data -----------------------------------------------------------------------------

  void read_ascii(const Header& header, const KnownFields& known, PcdCloud& cloud) {
    // Each value takes at least one character and one separator (the last line may lack its
    // newline): a count that cannot fit is rejected before anything is allocated.
    const std::uint64_t min_bytes_per_point = 2 * header.point_values;
    if (header.points > (remaining() + 1) / min_bytes_per_point) {
      fail_at_byte(position_, "truncated: POINTS " + std::to_string(header.points) + " points of " +
                                  std::to_string(header.point_values) +
                                  " values cannot fit in the ascii data (" +
                                  std::to_string(remaining()) + " bytes after the header)");
    }
    require_memory(header, known, 0);
    const std::size_t n = static_cast<std::size_t>(header.points);
    cloud.points.resize(n);
    if (known.normal[0]) cloud.normals.resize(n);
    if (known.color) cloud.colors.resize(n);
    if (known.label) cloud.labels.resize(n);

    std::vector<std::string_view> tokens;
    for (std::size_t i = 0; i < n; ++i) {
      do {
        const auto line = next_line();
        if (!line) {
          fail("truncated: the file ends after line " + std::to_string(line_) + " but " +
               point_name(i, n) + " is missing");
        }
        tokens = split_whitespace(*line);
      } while (tokens.empty());
      if (tokens.size() != header.point_values) {
        fail_at_line(i, n,
                     std::to_string(tokens.size()) + " values, expected " +
                         std::to_string(header.point_values));
      }
      auto token = [&](const Field& f) { return tokens[static_cast<std::size_t>(f.first_value)]; };
      auto vector_at = [&](const std::array<const Field*, 3>& f) {
        return Eigen::Vector3f(ascii_number(*f[0], token(*f[0]), i, n),
                               ascii_number(*f[1], token(*f[1]), i, n),
                               ascii_number(*f[2], token(*f[2]), i, n));
      };
      cloud.points[i] = vector_at(known.position);
      if (known.normal[0]) cloud.normals[i] = vector_at(known.normal);
      if (known.color) cloud.colors[i] = ascii_color(*known.color, token(*known.color), i, n);
      if (known.label) cloud.labels[i] = ascii_label(token(*known.label), i, n);
    }
    while (const auto line = next_line()) {
      if (!split_whitespace(*line).empty()) {
        fail("line " + std::to_string(line_) + ": more data after the " +
             std::to_string(header.points) + " points of POINTS");
      }
    }
  }

  [[noreturn]] void fail_at_line(std::size_t i, std::size_t n, const std::string& problem) const {
    fail("line " + std::to_string(line_) + " (" + point_name(i, n) + "): " + problem);
  }

  float ascii_number(const Field& field, std::string_view token, std::size_t i,
                     std::size_t n) const {
    std::optional<double> value;
    if (field.type == 'F') {
      if (field.size == 4) {
        if (const auto v = parse_real<float>(token)) value = *v;
      } else {
        value = parse_real<double>(token);
      }
    } else if (field.type == 'I') {
      const auto v = parse_integer<std::int64_t>(token);
      const std::int64_t limit = field.size == 8 ? std::numeric_limits<std::int64_t>::max()
                                                 : (std::int64_t{1} << (8 * field.size - 1)) - 1;
      if (v && *v <= limit && *v >= -limit - 1) value = static_cast<double>(*v);
    } else {
      const auto v = parse_integer<std::uint64_t>(token);
      const std::uint64_t limit = field.size == 8 ? std::numeric_limits<std::uint64_t>::max()
                                                  : (std::uint64_t{1} << (8 * field.size)) - 1;
      if (v && *v <= limit) value = static_cast<double>(*v);
    }
    if (!value) {
      fail_at_line(i, n,
                   "field '" + detail::printable(field.name) + "' is '" + detail::printable(token) +
                       "', not a valid " + field.type + std::to_string(field.size) + " number");
    }
    return static_cast<float>(*value);
  }

  // PCL writes ascii rgb as the packed integer (TYPE U, or TYPE F from PCL before 1.10 and other
  // writers); older writers wrote the float whose bits hold the colour ("4.808e+06").
  Rgb8 ascii_color(const Field& field, std::string_view token, std::size_t i, std::size_t n) const {
    std::optional<std::uint32_t> bits;
    if (field.type == 'I') {
      if (const auto v = parse_integer<std::int32_t>(token))
        bits = std::bit_cast<std::uint32_t>(*v);
    } else if (field.type == 'U' || all_digits(token)) {
      bits = parse_integer<std::uint32_t>(token);
    } else if (const auto v = parse_real<float>(token)) {
      bits = std::bit_cast<std::uint32_t>(*v);
    }
    if (!bits) {
      fail_at_line(i, n,
                   "colour field '" + detail::printable(field.name) + "' is '" +
                       detail::printable(token) + "', not a packed colour");
    }
    return unpack_pcl_rgb(*bits);
  }

  std::uint32_t ascii_label(std::string_view token, std::size_t i, std::size_t n) const {
    const auto label = parse_integer<std::uint32_t>(token);
    if (!label) {
      fail_at_line(
          i, n, "label is '" + detail::printable(token) + "', not an integer from 0 to 4294967295");
    }
    return *label;
  }

  std::span<const std::uint8_t> bytes_;
  std::string name_;
  std::size_t position_ = 0;  // next unread byte
  std::size_t line_ = 0;      // 1-based number of the last line read
};

// ---------------------------------------------------------------------------------------------
// Writing

// One written field: its values as 32-bit patterns (every field Kartograf writes takes 4 bytes).
struct Column {
  std::string_view name;
  char type;  // F or U
  std::vector<std::uint32_t> bits;
};

std::vector<Column> columns_of(const PcdCloud& cloud) {
  const std::size_t n = cloud.size();
  std::vector<Column> columns;
  auto add_vectors = [&](const std::vector<Eigen::Vector3f>& values,
                         std::array<std::string_view, 3> names) {
    for (int axis = 0; axis < 3; ++axis) {
      Column column{names[axis], 'F', std::vector<std::uint32_t>(n)};
      for (std::size_t i = 0; i < n; ++i)
        column.bits[i] = std::bit_cast<std::uint32_t>(values[i][axis]);
      columns.push_back(std::move(column));
    }
  };
  add_vectors(cloud.points, {"x", "y", "z"});
  if (!cloud.normals.empty()) add_vectors(cloud.normals, {"normal_x", "normal_y", "normal_z"});
  if (!cloud.colors.empty()) {
    // A float holding the packed bits, as PCL writes it in binary. In ascii too: PCL writes rgb
    // there as TYPE U, which its own pcl_pcd2ply then turns into a corrupt PLY (PCL 1.13), while
    // TYPE F with the float's text is read right by PCL and Open3D alike.
    Column column{"rgb", 'F', std::vector<std::uint32_t>(n)};
    for (std::size_t i = 0; i < n; ++i) column.bits[i] = pack_pcl_rgb(cloud.colors[i]);
    columns.push_back(std::move(column));
  }
  if (!cloud.labels.empty()) columns.push_back({"label", 'U', cloud.labels});
  return columns;
}

std::string header_text(const PcdCloud& cloud, const std::vector<Column>& columns,
                        PcdEncoding encoding) {
  std::string fields, sizes, types, counts;
  for (const Column& column : columns) {
    fields += ' ';
    fields += column.name;
    sizes += " 4";
    types += ' ';
    types += column.type;
    counts += " 1";
  }
  const Eigen::Quaterniond q(cloud.viewpoint.linear());
  std::string viewpoint;
  for (double v : {cloud.viewpoint.translation().x(), cloud.viewpoint.translation().y(),
                   cloud.viewpoint.translation().z(), q.w(), q.x(), q.y(), q.z()}) {
    viewpoint += ' ';
    append_double(viewpoint, v);
  }
  constexpr std::array<std::string_view, 3> data = {"ascii", "binary", "binary_compressed"};
  return "# .PCD v0.7 - Point Cloud Data file format (written by kartograf)\n"
         "VERSION 0.7\n"
         "FIELDS" +
         fields + "\nSIZE" + sizes + "\nTYPE" + types + "\nCOUNT" + counts + "\nWIDTH " +
         std::to_string(cloud.width) + "\nHEIGHT " + std::to_string(cloud.height) + "\nVIEWPOINT" +
         viewpoint + "\nPOINTS " + std::to_string(cloud.size()) + "\nDATA " +
         std::string(data[static_cast<std::size_t>(encoding)]) + "\n";
}

void check_writable(const PcdCloud& cloud, const std::string& name) {
  auto fail = [&](const std::string& problem) {
    throw Error("cannot write PCD " + quoted(name) + ": " + problem);
  };
  if (cloud.width < 0 || cloud.height < 0) fail("negative WIDTH or HEIGHT");
  const std::uint64_t expected = std::uint64_t(cloud.width) * std::uint64_t(cloud.height);
  if (cloud.size() != expected) {
    fail(std::to_string(cloud.size()) + " points for WIDTH x HEIGHT = " +
         std::to_string(cloud.width) + " x " + std::to_string(cloud.height));
  }
  auto check = [&](std::size_t count, const char* what) {
    if (count != 0 && count != cloud.size()) {
      fail(std::to_string(count) + " " + what + " for " + std::to_string(cloud.size()) + " points");
    }
  };
  check(cloud.normals.size(), "normals");
  check(cloud.colors.size(), "colours");
  check(cloud.labels.size(), "labels");
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Public functions

PointImage PcdCloud::to_point_image() const {
  require(organized(), "PcdCloud::to_point_image: the cloud is not organized (HEIGHT " +
                           std::to_string(height) + ")");
  require(size() == std::size_t(width) * std::size_t(height),
          "PcdCloud::to_point_image: " + std::to_string(size()) + " points for " +
              std::to_string(width) + " x " + std::to_string(height));
  PointImage image(width, height);
  auto pixels = image.pixels();
  for (std::size_t i = 0; i < points.size(); ++i) {
    pixels[i] = is_finite(points[i]) ? Point4f(points[i].x(), points[i].y(), points[i].z(), 1.0f)
                                     : invalid_point();
  }
  return image;
}

PointCloud PcdCloud::to_point_cloud() const {
  PointCloud cloud;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!is_finite(points[i])) continue;
    cloud.points.push_back(points[i]);
    if (!normals.empty()) cloud.normals.push_back(normals[i]);
    if (!colors.empty()) cloud.colors.push_back(colors[i]);
  }
  return cloud;
}

PcdCloud parse_pcd(std::span<const std::uint8_t> bytes, const std::string& name) {
  return PcdParser(bytes, name).parse();
}

PcdCloud read_pcd(const std::filesystem::path& path) {
  const std::vector<std::uint8_t> bytes =
      detail::read_file_bytes(path, "PCD file " + quoted(path.string()));
  return parse_pcd(bytes, path.string());
}

std::vector<std::uint8_t> encode_pcd(const PcdCloud& cloud, PcdEncoding encoding,
                                     const std::string& name) {
  check_writable(cloud, name);
  const std::vector<Column> columns = columns_of(cloud);
  const std::string header = header_text(cloud, columns, encoding);
  std::vector<std::uint8_t> out(header.begin(), header.end());
  const std::size_t n = cloud.size();

  switch (encoding) {
    case PcdEncoding::ascii: {
      std::string line;
      for (std::size_t i = 0; i < n; ++i) {
        line.clear();
        for (const Column& column : columns) {
          if (!line.empty()) line += ' ';
          if (column.type == 'F') {
            const bool packed = column.name == "rgb";
            append_float(line, std::bit_cast<float>(column.bits[i]),
                         packed ? std::optional<int>(9) : std::nullopt);
          } else {
            line += std::to_string(column.bits[i]);
          }
        }
        line += '\n';
        out.insert(out.end(), line.begin(), line.end());
      }
      break;
    }
    case PcdEncoding::binary:
      out.reserve(out.size() + n * columns.size() * 4);
      for (std::size_t i = 0; i < n; ++i) {
        for (const Column& column : columns) append_little_endian(out, column.bits[i]);
      }
      break;
    case PcdEncoding::binary_compressed: {
      std::vector<std::uint8_t> soa;  // field by field, as PCL stores compressed data
      soa.reserve(n * columns.size() * 4);
      for (const Column& column : columns) {
        for (std::uint32_t bits : column.bits) append_little_endian(soa, bits);
      }
      // Incompressible data grows by at most ~3% under LZF; a larger buffer always suffices.
      const std::size_t capacity = soa.size() + soa.size() / 16 + 64;
      if (capacity > std::numeric_limits<std::uint32_t>::max()) {
        throw Error("cannot write PCD " + quoted(name) + ": " + std::to_string(soa.size()) +
                    " bytes of point data exceed binary_compressed's 4 GiB limit");
      }
      std::vector<std::uint8_t> compressed(capacity);
      unsigned int size = 0;
      if (!soa.empty()) {
        size = lzf_compress(soa.data(), static_cast<unsigned int>(soa.size()), compressed.data(),
                            static_cast<unsigned int>(capacity));
        require(size != 0, "cannot write PCD " + quoted(name) + ": LZF compression failed");
      }
      append_little_endian(out, std::uint32_t{size});
      append_little_endian(out, static_cast<std::uint32_t>(soa.size()));
      out.insert(out.end(), compressed.begin(), compressed.begin() + size);
      break;
    }
  }
  return out;
}

void write_pcd(const std::filesystem::path& path, const PcdCloud& cloud, PcdEncoding encoding) {
  const std::vector<std::uint8_t> bytes = encode_pcd(cloud, encoding, path.string());
  detail::write_file_atomically(path, bytes.data(), bytes.size());
}

PcdCloud to_pcd(const PointCloud& cloud) {
  require(cloud.normals.empty() || cloud.normals.size() == cloud.size(),
          "to_pcd: " + std::to_string(cloud.normals.size()) + " normals for " +
              std::to_string(cloud.size()) + " points");
  require(cloud.colors.empty() || cloud.colors.size() == cloud.size(),
          "to_pcd: " + std::to_string(cloud.colors.size()) + " colours for " +
              std::to_string(cloud.size()) + " points");
  require(cloud.size() <= static_cast<std::size_t>(std::numeric_limits<int>::max()),
          "to_pcd: too many points for one PCD row");
  PcdCloud pcd;
  pcd.width = static_cast<int>(cloud.size());
  pcd.height = 1;
  pcd.points = cloud.points;
  pcd.normals = cloud.normals;
  pcd.colors = cloud.colors;
  return pcd;
}

PcdCloud to_pcd(const PointImage& points, const NormalImage* normals, const RgbImage* colors) {
  auto check_size = [&](int width, int height, const char* what) {
    require(width == points.width() && height == points.height(),
            std::string("to_pcd: the ") + what + " are " + std::to_string(width) + "x" +
                std::to_string(height) + " but the points are " + std::to_string(points.width()) +
                "x" + std::to_string(points.height()));
  };
  if (normals) check_size(normals->width(), normals->height(), "normals");
  if (colors) check_size(colors->width(), colors->height(), "colours");
  PcdCloud pcd;
  pcd.width = points.width();
  pcd.height = points.height();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (const Point4f& p : points.pixels()) {
    pcd.points.push_back(is_valid(p) ? Eigen::Vector3f(p.head<3>())
                                     : Eigen::Vector3f(nan, nan, nan));
  }
  if (normals) {
    for (const Point4f& n : normals->pixels()) pcd.normals.push_back(n.head<3>());
  }
  if (colors) pcd.colors.assign(colors->pixels().begin(), colors->pixels().end());
  return pcd;
}

}  // namespace kartograf::io
