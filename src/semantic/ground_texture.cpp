#include "kartograf/semantic/ground_texture.hpp"
#include "kartograf/core/models.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <numbers>
#include <string>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <opencv2/ml.hpp>

#include "kartograf/core/error.hpp"
#include "kartograf/segmentation/lab_color.hpp"
#include "kartograf/core/random.hpp"
#include "semantic/quantile.hpp"

namespace kartograf::semantic {

std::string_view to_string(GroundClass ground) {
  switch (ground) {
    case GroundClass::pavement:
      return "pavement";
    case GroundClass::grass:
      return "grass";
    case GroundClass::inaccessible:
      return "inaccessible";
  }
  return "invalid";
}

double default_traversability(GroundClass ground) {
  switch (ground) {
    case GroundClass::pavement:
      return 1.0;
    case GroundClass::grass:
      return 0.5;
    case GroundClass::inaccessible:
      return 0.0;
  }
  throw Error("default_traversability: invalid ground class " +
              std::to_string(static_cast<int>(ground)));
}

// ---- Features ----------------------------------------------------------------------------------

namespace {

// Mean and population standard deviation of each column.
struct ColumnStats {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  Eigen::Vector3d std = Eigen::Vector3d::Zero();
};
ColumnStats column_stats(const std::vector<Eigen::Vector3d>& values) {
  ColumnStats stats;
  for (const Eigen::Vector3d& v : values) stats.mean += v;
  stats.mean /= static_cast<double>(values.size());
  for (const Eigen::Vector3d& v : values) stats.std += (v - stats.mean).cwiseAbs2();
  stats.std = (stats.std / static_cast<double>(values.size())).cwiseSqrt();
  return stats;
}

// Entropy in bits of a joint histogram of L* (8 bins over 0..100) and a*, b* (8 bins each over
// -48..48): 0 for one colour, at most 9 bits.
double lab_entropy(const std::vector<Eigen::Vector3d>& lab) {
  constexpr int kBins = 8;
  auto bin = [](double value, double low, double high) {
    return std::clamp(static_cast<int>((value - low) / (high - low) * kBins), 0, kBins - 1);
  };
  std::vector<int> counts(kBins * kBins * kBins, 0);
  for (const Eigen::Vector3d& c : lab)
    ++counts[static_cast<std::size_t>((bin(c.x(), 0, 100) * kBins + bin(c.y(), -48, 48)) * kBins +
                                      bin(c.z(), -48, 48))];
  double entropy = 0.0;
  for (int count : counts) {
    if (count == 0) continue;
    const double p = count / static_cast<double>(lab.size());
    entropy -= p * std::log2(p);
  }
  return entropy;
}

// Neighbour statistics over a grid in the fitted plane: per cell the mean height above the plane
// and the mean L*, compared between 4-neighbouring occupied cells.
struct GridStats {
  double roughness = 0.0, max_step = 0.0, gradient_energy = 0.0;
};
GridStats grid_stats(const std::vector<Eigen::Vector2d>& in_plane,
                     const std::vector<double>& heights, const std::vector<Eigen::Vector3d>& lab,
                     const GroundFeatureParams& params) {
  Eigen::Vector2d low = in_plane[0], high = in_plane[0];
  for (const Eigen::Vector2d& p : in_plane) {
    low = low.cwiseMin(p);
    high = high.cwiseMax(p);
  }
  const int side = std::clamp(
      static_cast<int>(std::sqrt(static_cast<double>(in_plane.size()) / params.points_per_cell)), 2,
      params.max_grid_side);
  const Eigen::Vector2d cell = ((high - low) / side).cwiseMax(1e-9);
  const auto cells = static_cast<std::size_t>(side * side);
  std::vector<double> height_sum(cells, 0.0), l_sum(cells, 0.0);
  std::vector<int> count(cells, 0);
  for (std::size_t i = 0; i < in_plane.size(); ++i) {
    const Eigen::Vector2d g = (in_plane[i] - low).cwiseQuotient(cell);
    const int x = std::clamp(static_cast<int>(g.x()), 0, side - 1);
    const int y = std::clamp(static_cast<int>(g.y()), 0, side - 1);
    const auto c = static_cast<std::size_t>(y * side + x);
    height_sum[c] += heights[i];
    l_sum[c] += lab[i].x();
    ++count[c];
  }
  GridStats stats;
  double dh2 = 0.0, dl2 = 0.0;
  int pairs = 0;
  auto compare = [&](std::size_t a, std::size_t b) {
    if (count[a] == 0 || count[b] == 0) return;
    const double dh = height_sum[a] / count[a] - height_sum[b] / count[b];
    const double dl = l_sum[a] / count[a] - l_sum[b] / count[b];
    dh2 += dh * dh;
    dl2 += dl * dl;
    stats.max_step = std::max(stats.max_step, std::abs(dh));
    ++pairs;
  };
  for (int y = 0; y < side; ++y)
    for (int x = 0; x < side; ++x) {
      const auto c = static_cast<std::size_t>(y * side + x);
      if (x + 1 < side) compare(c, c + 1);
      if (y + 1 < side) compare(c, c + static_cast<std::size_t>(side));
    }
  if (pairs > 0) {
    stats.roughness = std::sqrt(dh2 / pairs);
    stats.gradient_energy = dl2 / pairs;
  }
  return stats;
}

}  // namespace

GroundFeatures ground_features(const PointCloud& patch, const GroundFeatureParams& params) {
  const std::size_t n = patch.points.size();
  require(params.min_points >= 3 && params.points_per_cell > 0 && params.max_grid_side >= 2,
          "ground features: bad parameters (min_points >= 3, points_per_cell > 0, "
          "max_grid_side >= 2)");
  require(n >= static_cast<std::size_t>(params.min_points),
          "ground features: the patch has " + std::to_string(n) + " points, needs at least " +
              std::to_string(params.min_points));
  require(patch.colors.size() == n, "ground features: the patch has " + std::to_string(n) +
                                        " points but " + std::to_string(patch.colors.size()) +
                                        " colours (one per point needed)");
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < n; ++i) {
    require(patch.points[i].allFinite(),
            "ground features: point " + std::to_string(i) + " of the patch is not finite");
    centroid += patch.points[i].cast<double>();
  }
  centroid /= static_cast<double>(n);
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (const Eigen::Vector3f& p : patch.points) {
    const Eigen::Vector3d d = p.cast<double>() - centroid;
    covariance += d * d.transpose();
  }
  covariance /= static_cast<double>(n);
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance);
  // Eigenvalues ascending: the plane needs two directions of extent (1 cm std each at least).
  require(solver.eigenvalues()(1) > 1e-4,
          "ground features: the patch's points lie on a line or a spot (no ground plane)");
  Eigen::Vector3d normal = solver.eigenvectors().col(0);
  if (normal.z() < 0) normal = -normal;
  const Eigen::Vector3d axis_u = solver.eigenvectors().col(2);
  const Eigen::Vector3d axis_v = normal.cross(axis_u);

  std::vector<double> heights(n);
  std::vector<Eigen::Vector2d> in_plane(n);
  std::vector<Eigen::Vector3d> lab(n);
  double greenness = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d d = patch.points[i].cast<double>() - centroid;
    heights[i] = normal.dot(d);
    in_plane[i] = {axis_u.dot(d), axis_v.dot(d)};
    lab[i] = segmentation::rgb_to_lab(patch.colors[i]).cast<double>();
    const Rgb8& c = patch.colors[i];
    const double sum = static_cast<double>(c[0]) + c[1] + c[2];
    if (sum > 0) greenness += (2.0 * c[1] - c[0] - c[2]) / sum;
  }
  greenness /= static_cast<double>(n);

  double height_var = 0.0;
  for (double h : heights) height_var += h * h;  // the plane passes through the centroid
  const ColumnStats colour = column_stats(lab);
  const GridStats grid = grid_stats(in_plane, heights, lab, params);

  GroundFeatures f{};
  auto set = [&f](GroundFeature which, double value) {
    f[static_cast<std::size_t>(which)] = static_cast<float>(value);
  };
  set(GroundFeature::height_std, std::sqrt(height_var / static_cast<double>(n)));
  set(GroundFeature::height_range,
      detail::quantile(heights, 0.98) - detail::quantile(heights, 0.02));
  set(GroundFeature::roughness, grid.roughness);
  set(GroundFeature::max_step, grid.max_step);
  set(GroundFeature::slope,
      std::acos(std::clamp(normal.z(), -1.0, 1.0)) * 180.0 / std::numbers::pi);
  set(GroundFeature::lab_l_mean, colour.mean.x());
  set(GroundFeature::lab_a_mean, colour.mean.y());
  set(GroundFeature::lab_b_mean, colour.mean.z());
  set(GroundFeature::lab_l_std, colour.std.x());
  set(GroundFeature::lab_a_std, colour.std.y());
  set(GroundFeature::lab_b_std, colour.std.z());
  set(GroundFeature::color_entropy, lab_entropy(lab));
  set(GroundFeature::gradient_energy, grid.gradient_energy);
  set(GroundFeature::greenness, greenness);
  return f;
}

// ---- Classifier --------------------------------------------------------------------------------

struct GroundTextureClassifier::Model {
  cv::Ptr<cv::ml::RTrees> forest;
};

GroundTextureClassifier GroundTextureClassifier::train(std::span<const float> features,
                                                       std::span<const GroundClass> labels,
                                                       const TrainParams& params) {
  require(features.size() == labels.size() * kGroundFeatureCount,
          "ground texture training: " + std::to_string(features.size()) + " features for " +
              std::to_string(labels.size()) + " labels (need " +
              std::to_string(kGroundFeatureCount) + " a label)");
  require(params.tree_count >= 1 && params.max_depth >= 1 && params.min_sample_count >= 1,
          "ground texture training: tree_count, max_depth and min_sample_count must be >= 1");
  std::array<int, kGroundClassCount> per_class{};
  std::vector<int> responses;
  responses.reserve(labels.size());
  for (GroundClass label : labels) {
    const int value = static_cast<int>(label);
    require(value >= 0 && value < kGroundClassCount,
            "ground texture training: label " + std::to_string(value) + " is not a ground class");
    ++per_class[static_cast<std::size_t>(value)];
    responses.push_back(value);
  }
  for (int c = 0; c < kGroundClassCount; ++c)
    require(per_class[static_cast<std::size_t>(c)] > 0,
            "ground texture training: no sample of class " +
                std::string(to_string(static_cast<GroundClass>(c))));
  const cv::Mat samples(static_cast<int>(labels.size()), kGroundFeatureCount, CV_32F,
                        const_cast<float*>(features.data()));
  const cv::Mat response_column(static_cast<int>(labels.size()), 1, CV_32S, responses.data());
  auto model = std::make_shared<Model>();
  model->forest = cv::ml::RTrees::create();
  model->forest->setMaxDepth(params.max_depth);
  model->forest->setMinSampleCount(params.min_sample_count);
  model->forest->setUseSurrogates(false);
  model->forest->setTermCriteria(
      cv::TermCriteria(cv::TermCriteria::MAX_ITER, params.tree_count, 0.0));
  // CV_32S responses make a classification forest (categorical output).
  model->forest->train(cv::ml::TrainData::create(samples, cv::ml::ROW_SAMPLE, response_column));
  return GroundTextureClassifier(std::move(model));
}

GroundTextureClassifier GroundTextureClassifier::load(const std::filesystem::path& path) {
  const std::string name = path.string();
  require(std::filesystem::is_regular_file(path),
          "ground texture model " + name + " does not exist (train one with train_ground_texture)");
  cv::Ptr<cv::ml::RTrees> forest;
  try {
    forest = cv::ml::RTrees::load(name);
  } catch (const cv::Exception& e) {
    throw Error("ground texture model " + name + " cannot be read: " + e.what());
  }
  require(forest && !forest->empty() && forest->isTrained() && forest->isClassifier(),
          "ground texture model " + name + " holds no trained random forest classifier");
  require(forest->getVarCount() == kGroundFeatureCount,
          "ground texture model " + name + " was trained on " +
              std::to_string(forest->getVarCount()) + " features, expected " +
              std::to_string(kGroundFeatureCount));
  auto model = std::make_shared<Model>();
  model->forest = forest;
  return GroundTextureClassifier(std::move(model));
}

void GroundTextureClassifier::save(const std::filesystem::path& path) const {
  require(!empty(), "ground texture classifier: cannot save an empty model to " + path.string());
  try {
    model_->forest->save(path.string());
  } catch (const cv::Exception& e) {
    throw Error("ground texture model " + path.string() + " cannot be written: " + e.what());
  }
  require(std::filesystem::is_regular_file(path),
          "ground texture model " + path.string() + " was not written");
}

std::vector<GroundClass> GroundTextureClassifier::predict(std::span<const float> features) const {
  require(!empty(), "ground texture classifier: the model is empty (load or train one)");
  require(features.size() % kGroundFeatureCount == 0,
          "ground texture classifier: " + std::to_string(features.size()) +
              " features are not rows of " + std::to_string(kGroundFeatureCount));
  const int rows = static_cast<int>(features.size() / kGroundFeatureCount);
  std::vector<GroundClass> result;
  if (rows == 0) return result;
  const cv::Mat samples(rows, kGroundFeatureCount, CV_32F, const_cast<float*>(features.data()));
  cv::Mat out;
  model_->forest->predict(samples, out);
  result.reserve(static_cast<std::size_t>(rows));
  for (int i = 0; i < rows; ++i) {
    const int value =
        std::clamp(static_cast<int>(std::lround(out.at<float>(i, 0))), 0, kGroundClassCount - 1);
    result.push_back(static_cast<GroundClass>(value));
  }
  return result;
}

GroundClass GroundTextureClassifier::predict(const GroundFeatures& features) const {
  return predict(std::span<const float>(features))[0];
}

std::filesystem::path default_ground_texture_model_path() {
  if (const char* configured = std::getenv("KARTOGRAF_GROUND_TEXTURE_MODEL");
      configured && *configured)
    return configured;
  return models_dir() / "semantic" / "ground_texture.yml.gz";
}

// ---- Synthetic patches -------------------------------------------------------------------------

namespace {

using kartograf::Rng;
using Colour = Eigen::Vector3d;  // linear 0..255 RGB before noise and clamping
using HeightField = std::function<double(double x, double y)>;
using ColourField = std::function<Colour(double x, double y)>;

// What every generator shares: the sampling (a jittered grid over side x side metres, as a range
// sensor looking down sees it), the tilt of the whole patch, and sensor noise in depth and colour.
struct PatchSampling {
  double side = 1.0;
  int samples_per_side = 32;
  double tilt_deg = 0.0;
  double depth_noise = 0.005;  // m
  double colour_noise = 5.0;   // 0..255 units
};

PointCloud sample_patch(Rng& rng, const PatchSampling& sampling, const HeightField& height,
                        const ColourField& colour) {
  const double step = sampling.side / sampling.samples_per_side;
  const double azimuth = rng.uniform(0, 2 * std::numbers::pi);
  const Eigen::Matrix3d tilt =
      Eigen::AngleAxisd(sampling.tilt_deg * std::numbers::pi / 180.0,
                        Eigen::Vector3d(std::cos(azimuth), std::sin(azimuth), 0))
          .toRotationMatrix();
  PointCloud patch;
  for (int j = 0; j < sampling.samples_per_side; ++j)
    for (int i = 0; i < sampling.samples_per_side; ++i) {
      const double x = (i + rng.uniform()) * step - sampling.side / 2;
      const double y = (j + rng.uniform()) * step - sampling.side / 2;
      Eigen::Vector3d p = tilt * Eigen::Vector3d(x, y, height(x, y));
      p.z() += rng.normal(0, sampling.depth_noise);
      patch.points.push_back(p.cast<float>());
      const Colour c = colour(x, y);
      Rgb8 rgb;
      for (int k = 0; k < 3; ++k)
        rgb[static_cast<std::size_t>(k)] = static_cast<std::uint8_t>(
            std::clamp(std::lround(c[k] + rng.normal(0, sampling.colour_noise)), 0L, 255L));
      patch.colors.push_back(rgb);
    }
  return patch;
}

// Base colours.
Colour grey(Rng& rng, double low, double high) {
  const double v = rng.uniform(low, high);
  return {v * rng.uniform(0.97, 1.03), v, v * rng.uniform(0.95, 1.05)};
}
Colour brown(Rng& rng) {
  const double v = rng.uniform(90, 170);
  return {v, v * rng.uniform(0.78, 0.9), v * rng.uniform(0.6, 0.75)};
}
Colour green(Rng& rng, double low, double high) {
  const double g = rng.uniform(low, high);
  return {g * rng.uniform(0.45, 0.8), g, g * rng.uniform(0.2, 0.5)};
}
Colour tinted(Rng& rng) {
  const double v = rng.uniform(60, 200);
  return {v * rng.uniform(0.7, 1.4), v, v * rng.uniform(0.6, 1.2)};
}
Colour brick_red(Rng& rng) {
  const double r = rng.uniform(120, 190);
  return {r, r * rng.uniform(0.45, 0.6), r * rng.uniform(0.35, 0.5)};
}

// A smooth random field in about [-1, 1]: a few random plane waves.
HeightField smooth_field(Rng& rng, int waves, double min_wavelength, double max_wavelength) {
  struct Wave {
    double kx, ky, phase, weight;
  };
  std::vector<Wave> list;
  for (int w = 0; w < waves; ++w) {
    const double k = 2 * std::numbers::pi / rng.uniform(min_wavelength, max_wavelength);
    const double angle = rng.uniform(0, 2 * std::numbers::pi);
    list.push_back({k * std::cos(angle), k * std::sin(angle), rng.uniform(0, 2 * std::numbers::pi),
                    rng.uniform(0.5, 1.0)});
  }
  double total = 0;
  for (const Wave& w : list) total += w.weight;
  return [list, total](double x, double y) {
    double sum = 0;
    for (const Wave& w : list) sum += w.weight * std::sin(w.kx * x + w.ky * y + w.phase);
    return sum / total * 1.6;
  };
}

// Per-point randomness that does not depend on sampling order: a hash of the position.
double position_noise(std::uint64_t key, double x, double y, std::uint64_t stream) {
  const auto ix = static_cast<std::uint64_t>(std::llround(x * 1e4) + (1LL << 40));
  const auto iy = static_cast<std::uint64_t>(std::llround(y * 1e4) + (1LL << 40));
  return hash_uniform(hash_key(key, ix, iy), stream);
}

PatchSampling sampling_for(Rng& rng, GroundPatchStyle style) {
  PatchSampling s;
  if (style == GroundPatchStyle::training) {
    s.side = rng.uniform(0.6, 1.0);
    s.samples_per_side = rng.uniform_int(24, 36);
    s.depth_noise = rng.uniform(0.002, 0.015);  // Kinect-like at 1-3 m
    s.colour_noise = rng.uniform(3, 8);
  } else {
    s.side = rng.uniform(0.8, 1.2);
    s.samples_per_side = rng.uniform_int(20, 44);
    s.depth_noise = rng.uniform(0.003, 0.012);
    s.colour_noise = rng.uniform(2, 12);
  }
  return s;
}

// Pavement: a plane with slabs or bricks separated by darker joints.
PointCloud pavement_patch(Rng& rng, GroundPatchStyle style) {
  PatchSampling s = sampling_for(rng, style);
  const std::uint64_t key = rng.bits();
  const bool held_out = style == GroundPatchStyle::held_out;
  s.tilt_deg = rng.uniform(0, held_out ? 8 : 6);
  Colour base;
  const int material = rng.uniform_int(0, 2);
  // Training colours span greys, browns and tinted stone so that colour alone does not tell
  // pavement from obstacles; the held-out set has red bricks, dark asphalt and light concrete.
  if (!held_out)
    base = material == 0 ? grey(rng, 45, 215) : material == 1 ? tinted(rng) : brown(rng);
  else
    base = material == 0 ? brick_red(rng) : material == 1 ? grey(rng, 40, 80) : grey(rng, 170, 215);
  const bool asphalt = held_out && material == 1;  // dark, no joints
  // Slabs (training): square, axis-aligned; bricks (held out): running bond, rotated.
  const double length = held_out ? rng.uniform(0.18, 0.3) : rng.uniform(0.2, 0.5);
  const double width = held_out ? rng.uniform(0.08, 0.15) : length;
  const double joint = rng.uniform(0.008, 0.02);
  const double joint_dark = rng.uniform(0.5, 0.75);
  const double angle = held_out ? rng.uniform(0, std::numbers::pi) : 0.0;
  const double unit_variation = rng.uniform(0.02, 0.08);
  const double unit_lift = rng.uniform(0.0, 0.004);  // m: slabs settle unevenly
  struct Unit {
    long row, column;
    double u_in_unit, v_in_unit;
  };
  auto unit_of = [=](double x, double y) {
    const double u = std::cos(angle) * x + std::sin(angle) * y + 10.0;
    const double v = -std::sin(angle) * x + std::cos(angle) * y + 10.0;
    const long row = static_cast<long>(std::floor(v / width));
    const double shift = held_out && (row % 2 != 0) ? length / 2 : 0.0;
    const long column = static_cast<long>(std::floor((u + shift) / length));
    return Unit{row, column, u + shift - column * length, v - row * width};
  };
  auto unit_random = [key](const Unit& unit, std::uint64_t stream) {
    return hash_uniform(hash_key(key, static_cast<std::uint64_t>(unit.row + 1000),
                                               static_cast<std::uint64_t>(unit.column + 1000)),
                               stream);
  };
  auto in_joint = [=](const Unit& unit) {
    return !asphalt && (unit.u_in_unit < joint || unit.v_in_unit < joint);
  };
  const HeightField height = [=](double x, double y) {
    const Unit unit = unit_of(x, y);
    if (in_joint(unit)) return -0.003;
    return asphalt ? 0.0 : unit_lift * (unit_random(unit, 1) - 0.5);
  };
  const ColourField colour = [=](double x, double y) -> Colour {
    const Unit unit = unit_of(x, y);
    if (in_joint(unit)) return base * joint_dark;
    const double speckle = asphalt ? 0.06 * (position_noise(key, x, y, 3) - 0.5) : 0.0;
    return base * (1.0 + unit_variation * (2 * unit_random(unit, 2) - 1) + speckle);
  };
  return sample_patch(rng, s, height, colour);
}

// Grass: blades at random heights over a bumpy ground, green with light and shade per blade and
// some dry or bare spots.
PointCloud grass_patch(Rng& rng, GroundPatchStyle style) {
  PatchSampling s = sampling_for(rng, style);
  const std::uint64_t key = rng.bits();
  const bool held_out = style == GroundPatchStyle::held_out;
  s.tilt_deg = rng.uniform(0, held_out ? 12 : 10);
  const double blade = held_out ? rng.uniform(0.025, 0.09) : rng.uniform(0.02, 0.08);
  const double bump = blade * rng.uniform(0.2, 0.5);
  // Training: bumps from short waves; held out: longer tussocks.
  const HeightField ground =
      held_out ? smooth_field(rng, 4, 0.25, 0.6) : smooth_field(rng, 6, 0.1, 0.4);
  const HeightField dry_field = smooth_field(rng, 3, 0.3, 0.8);
  const Colour base = held_out ? green(rng, 70, 130) : green(rng, 90, 170);
  const Colour dry = held_out ? Colour(150, 140, 80) : Colour(120, 95, 60);
  const double dry_level = rng.uniform(0.6, 1.2);  // the field exceeds it on dry spots
  const double shade = rng.uniform(0.2, 0.4);
  const HeightField height = [=](double x, double y) {
    return bump * ground(x, y) + blade * position_noise(key, x, y, 1);
  };
  const ColourField colour = [=](double x, double y) -> Colour {
    const double light = 1.0 + shade * (2 * position_noise(key, x, y, 2) - 1);
    const Colour c = dry_field(x, y) > dry_level ? dry : base;
    // Tips are lighter than the shaded blades below them.
    return c * light * (0.85 + 0.3 * position_noise(key, x, y, 1));
  };
  return sample_patch(rng, s, height, colour);
}

// A surface colour for obstacles and slopes: any of the ground materials.
ColourField surface_colour(Rng& rng, bool held_out) {
  const int kind = rng.uniform_int(0, 3);
  const Colour base = kind == 0   ? grey(rng, 60, 200)
                      : kind == 1 ? brown(rng)
                      : kind == 2 ? green(rng, 80, 160)
                                  : (held_out ? brick_red(rng) : tinted(rng));
  const double texture = rng.uniform(0.0, 0.3);
  const std::uint64_t key = rng.bits();
  return [=](double x, double y) -> Colour {
    return base * (1.0 + texture * (2 * position_noise(key, x, y, 4) - 1));
  };
}

// Inaccessible: a steep slope, a step (kerb), rubble (boxes or stones) or a post.
PointCloud inaccessible_patch(Rng& rng, GroundPatchStyle style) {
  PatchSampling s = sampling_for(rng, style);
  const bool held_out = style == GroundPatchStyle::held_out;
  const int kind = rng.uniform_int(0, held_out ? 3 : 2);
  const ColourField surface = surface_colour(rng, held_out);
  const double roughness = rng.uniform(0.0, 0.03);
  const std::uint64_t key = rng.bits();
  auto rough = [=](double x, double y) { return roughness * position_noise(key, x, y, 5); };
  if (kind == 0) {  // steep slope
    s.tilt_deg = held_out ? rng.uniform(22, 50) : rng.uniform(20, 40);
    return sample_patch(rng, s, rough, surface);
  }
  s.tilt_deg = rng.uniform(0, held_out ? 8 : 6);
  if (kind == 1) {  // a step: training straight across x; held out a kerb at any angle
    const double rise = held_out ? rng.uniform(0.12, 0.25) : rng.uniform(0.1, 0.4);
    const double angle = held_out ? rng.uniform(0, std::numbers::pi) : 0.0;
    const double offset = rng.uniform(-0.25, 0.25) * s.side;
    const ColourField top = surface_colour(rng, held_out);
    const HeightField height = [=](double x, double y) {
      const bool up = std::cos(angle) * x + std::sin(angle) * y > offset;
      return (up ? rise : 0.0) + rough(x, y);
    };
    const ColourField colour = [=](double x, double y) {
      return std::cos(angle) * x + std::sin(angle) * y > offset ? top(x, y) : surface(x, y);
    };
    return sample_patch(rng, s, height, colour);
  }
  struct Block {
    Eigen::Vector2d centre;
    double size, rise;
    Colour colour;
  };
  std::vector<Block> blocks;
  const int count = kind == 3 ? 1 : rng.uniform_int(held_out ? 4 : 5, held_out ? 12 : 15);
  for (int b = 0; b < count; ++b) {
    Block block;
    block.centre = {rng.uniform(-0.5, 0.5) * s.side, rng.uniform(-0.5, 0.5) * s.side};
    if (kind == 3) {  // a post or pole
      block.size = rng.uniform(0.06, 0.2);
      block.rise = rng.uniform(0.4, 1.0);
    } else {
      block.size = held_out ? rng.uniform(0.05, 0.2) : rng.uniform(0.05, 0.25);
      block.rise = held_out ? rng.uniform(0.05, 0.25) : rng.uniform(0.05, 0.3);
    }
    block.colour = rng.bernoulli(0.5) ? grey(rng, 60, 200) : brown(rng);
    blocks.push_back(block);
  }
  // Training rubble: boxes; held out: rounded stones (spherical caps) and posts (discs).
  const bool round = held_out;
  auto block_height = [=](const Block& block, double x, double y) {
    const Eigen::Vector2d d = Eigen::Vector2d(x, y) - block.centre;
    if (!round) return d.cwiseAbs().maxCoeff() < block.size / 2 ? block.rise : -1.0;
    const double r = d.norm() / (block.size / 2);
    if (r >= 1) return -1.0;
    return kind == 3 ? block.rise : block.rise * std::sqrt(1 - r * r);
  };
  const HeightField height = [=](double x, double y) {
    double h = rough(x, y);
    for (const Block& block : blocks) h = std::max(h, block_height(block, x, y));
    return h;
  };
  const ColourField colour = [=](double x, double y) {
    double best = rough(x, y);
    Colour c = surface(x, y);
    for (const Block& block : blocks)
      if (const double h = block_height(block, x, y); h > best) {
        best = h;
        c = block.colour;
      }
    return c;
  };
  return sample_patch(rng, s, height, colour);
}

}  // namespace

PointCloud synthesize_ground_patch(GroundClass ground, GroundPatchStyle style, std::uint64_t seed) {
  Rng rng(
      hash_key(seed, static_cast<std::uint64_t>(ground), static_cast<std::uint64_t>(style)));
  switch (ground) {
    case GroundClass::pavement:
      return pavement_patch(rng, style);
    case GroundClass::grass:
      return grass_patch(rng, style);
    case GroundClass::inaccessible:
      return inaccessible_patch(rng, style);
  }
  throw Error("synthesize_ground_patch: invalid ground class " +
              std::to_string(static_cast<int>(ground)));
}

GroundSamples synthesize_ground_samples(int per_class, GroundPatchStyle style, std::uint64_t seed,
                                        const GroundFeatureParams& params) {
  require(per_class >= 0,
          "synthesize_ground_samples: per_class must be >= 0, got " + std::to_string(per_class));
  GroundSamples samples;
  for (int c = 0; c < kGroundClassCount; ++c)
    for (int i = 0; i < per_class; ++i) {
      const auto ground = static_cast<GroundClass>(c);
      const GroundFeatures f = ground_features(
          synthesize_ground_patch(
              ground, style,
              hash_key(seed, 0x67726f756e64ULL, static_cast<std::uint64_t>(i))),
          params);
      samples.features.insert(samples.features.end(), f.begin(), f.end());
      samples.labels.push_back(ground);
    }
  return samples;
}

}  // namespace kartograf::semantic
