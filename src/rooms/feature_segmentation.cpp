#include "kartograf/rooms/feature_segmentation.hpp"
#include "kartograf/core/models.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <exception>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/ml.hpp>

#include "compute/cpu_parallel.hpp"
#include "kartograf/compute/context.hpp"
#include "kartograf/core/connected_components.hpp"
#include "kartograf/core/error.hpp"
#include "kartograf/rooms/laser_scan_device.hpp"

namespace kartograf::rooms {

struct RoomClassifier::Model {
  cv::Ptr<cv::ml::Boost> boost;
};

namespace {

using Clock = std::chrono::steady_clock;
constexpr int kFeatureCount = static_cast<int>(kLaserFeatureCount);

using Cell = ScanCell;

// Cells per device dispatch: the scans of a batch (360 beams: 23 MB of ranges) stay well within
// what every driver binds.
constexpr std::size_t kDeviceBatchCells = 16384;
constexpr std::size_t kHostBatchCells = 512;

// The features of a scan at every cell, rows in the order of `cells`. The scans run on `context`
// (DeviceLaserScanner: the same scans, bit for bit, on every backend) in batches; the features on
// threads over chunks of cells (KARTOGRAF_CPU_THREADS, src/compute/cpu_parallel.hpp).
std::vector<float> features_at(const compute::Context& context, const LaserScanner& scanner,
                               const std::vector<Cell>& cells, const LaserFeatureParams& params) {
  const auto beams = static_cast<std::size_t>(scanner.beams());
  std::vector<float> features(cells.size() * kLaserFeatureCount);
  DeviceLaserScanner device(context, scanner);
  // Where device memory is host memory (the CPU, CPU-hosted drivers), batches small enough that
  // the ranges stay in cache between the scan and the features.
  const std::size_t batch =
      context.device_info().unified_memory ? kHostBatchCells : kDeviceBatchCells;
  for (std::size_t begin = 0; begin < cells.size(); begin += batch) {
    const std::size_t count = std::min(batch, cells.size() - begin);
    const std::vector<double> ranges =
        device.scan_ranges(std::span(cells).subspan(begin, count), count);
    compute::detail::for_each_chunk(
        count, count * beams, [&](std::size_t first, std::size_t last, std::size_t) {
          for (std::size_t i = first; i < last; ++i) {
            const LaserFeatures f =
                laser_scan_features(std::span(ranges).subspan(i * beams, beams), params);
            std::copy(
                f.begin(), f.end(),
                features.begin() + static_cast<std::ptrdiff_t>((begin + i) * kLaserFeatureCount));
          }
        });
  }
  return features;
}

bool on_lattice(int col, int row, int stride) {
  return col % stride == 0 && row % stride == 0;
}

// Each lattice cell's score averaged with those of the lattice cells within `radius` lattice steps
// (a box): single cells that disagree with their surroundings (furniture) lose their vote.
std::vector<float> smoothed(const std::vector<Cell>& cells, const std::vector<float>& scores,
                            int stride, int radius) {
  if (radius <= 0 || cells.empty()) return scores;
  int columns = 0, rows = 0;
  for (const Cell& c : cells) {
    columns = std::max(columns, c.col / stride + 1);
    rows = std::max(rows, c.row / stride + 1);
  }
  std::vector<int> index(static_cast<std::size_t>(columns) * static_cast<std::size_t>(rows), -1);
  const auto at = [&](int u, int v) -> int& {
    return index[static_cast<std::size_t>(v) * static_cast<std::size_t>(columns) +
                 static_cast<std::size_t>(u)];
  };
  for (std::size_t i = 0; i < cells.size(); ++i)
    at(cells[i].col / stride, cells[i].row / stride) = static_cast<int>(i);
  std::vector<float> result(scores.size());
  for (std::size_t i = 0; i < cells.size(); ++i) {
    const int u = cells[i].col / stride, v = cells[i].row / stride;
    double sum = 0;
    int count = 0;
    for (int dv = -radius; dv <= radius; ++dv) {
      for (int du = -radius; du <= radius; ++du) {
        if (u + du < 0 || v + dv < 0 || u + du >= columns || v + dv >= rows) continue;
        const int j = at(u + du, v + dv);
        if (j < 0) continue;
        sum += scores[static_cast<std::size_t>(j)];
        ++count;
      }
    }
    result[i] = static_cast<float>(sum / count);
  }
  return result;
}

// The cells of class `place` farther than `margin` cells from any cell of another class or an
// obstacle (the grid's edge counts as one): regions joined only through doorways or thin slivers
// along walls fall apart.
Image<std::uint8_t> core_of(const Image<PlaceClass>& places, PlaceClass place, double margin) {
  const int width = places.width(), height = places.height();
  cv::Mat mask(height + 2, width + 2, CV_8UC1, cv::Scalar(0));
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x)
      mask.at<std::uint8_t>(y + 1, x + 1) = places(x, y) == place ? 255 : 0;
  }
  cv::Mat distance;
  cv::distanceTransform(mask, distance, cv::DIST_L2, cv::DIST_MASK_PRECISE, CV_32F);
  Image<std::uint8_t> core(width, height, 0);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) core(x, y) = distance.at<float>(y + 1, x + 1) > margin;
  }
  return core;
}

}  // namespace

// ---- RoomClassifier ----------------------------------------------------------------------------

RoomClassifier RoomClassifier::train(std::span<const float> features, std::span<const int> labels,
                                     int weak_count, int max_depth) {
  require(features.size() == labels.size() * kLaserFeatureCount,
          "room classifier training: " + std::to_string(features.size()) + " features for " +
              std::to_string(labels.size()) + " labels (expected " +
              std::to_string(kLaserFeatureCount) + " per label)");
  require(weak_count >= 1 && max_depth >= 1,
          "room classifier training: weak_count and max_depth must be >= 1");
  std::size_t rooms = 0, hallways = 0;
  for (const int label : labels) {
    require(label == 1 || label == -1,
            "room classifier training: labels must be +1 (room) or -1 (hallway), got " +
                std::to_string(label));
    (label > 0 ? rooms : hallways) += 1;
  }
  require(rooms > 0 && hallways > 0,
          "room classifier training: needs room and hallway samples, got " + std::to_string(rooms) +
              " rooms and " + std::to_string(hallways) + " hallways");
  const int rows = static_cast<int>(labels.size());
  const cv::Mat samples(rows, kFeatureCount, CV_32F, const_cast<float*>(features.data()));
  const cv::Mat responses(rows, 1, CV_32S, const_cast<int*>(labels.data()));
  auto model = std::make_shared<Model>();
  model->boost = cv::ml::Boost::create();
  model->boost->setBoostType(cv::ml::Boost::DISCRETE);
  model->boost->setWeakCount(weak_count);
  model->boost->setWeightTrimRate(0);
  model->boost->setMaxDepth(max_depth);
  model->boost->setUseSurrogates(false);
  model->boost->train(cv::ml::TrainData::create(samples, cv::ml::ROW_SAMPLE, responses));
  return RoomClassifier(std::move(model));
}

RoomClassifier RoomClassifier::load(const std::filesystem::path& path) {
  const std::string name = path.string();
  require(
      std::filesystem::is_regular_file(path),
      "room classifier model " + name + " does not exist (train one with train_room_classifier)");
  cv::Ptr<cv::ml::Boost> boost;
  try {
    boost = cv::ml::Boost::load(name);
  } catch (const cv::Exception& e) {
    throw Error("room classifier model " + name + " cannot be read: " + e.what());
  }
  require(boost && !boost->empty() && boost->isTrained() && boost->isClassifier(),
          "room classifier model " + name + " holds no trained boosted classifier");
  require(boost->getVarCount() == kFeatureCount,
          "room classifier model " + name + " was trained on " +
              std::to_string(boost->getVarCount()) + " features, expected " +
              std::to_string(kLaserFeatureCount));
  auto model = std::make_shared<Model>();
  model->boost = boost;
  return RoomClassifier(std::move(model));
}

void RoomClassifier::save(const std::filesystem::path& path) const {
  require(!empty(), "room classifier: cannot save an empty model to " + path.string());
  try {
    model_->boost->save(path.string());
  } catch (const cv::Exception& e) {
    throw Error("room classifier model " + path.string() + " cannot be written: " + e.what());
  }
  require(std::filesystem::is_regular_file(path),
          "room classifier model " + path.string() + " was not written");
}

std::vector<float> RoomClassifier::scores(std::span<const float> features) const {
  require(!empty(), "room classifier: the model is empty (load or train one)");
  require(features.size() % kLaserFeatureCount == 0,
          "room classifier: " + std::to_string(features.size()) + " features are not rows of " +
              std::to_string(kLaserFeatureCount));
  const int rows = static_cast<int>(features.size() / kLaserFeatureCount);
  std::vector<float> result(static_cast<std::size_t>(rows));
  if (rows == 0) return result;
  const cv::Mat samples(rows, kFeatureCount, CV_32F, const_cast<float*>(features.data()));
  cv::Mat out;
  model_->boost->predict(samples, out, cv::ml::StatModel::RAW_OUTPUT);
  for (int i = 0; i < rows; ++i) result[static_cast<std::size_t>(i)] = out.at<float>(i, 0);
  return result;
}

float RoomClassifier::score(const LaserFeatures& features) const {
  return scores(features)[0];
}

// ---- Training ----------------------------------------------------------------------------------

RoomTrainingMap room_training_map(const std::string& name, const OccupancyGrid& drawn,
                                  const OccupancyGrid& white, PlaceClass white_class) {
  require(drawn.width() == white.width() && drawn.height() == white.height(),
          "room training map " + name + ": the two readings differ in size");
  require(white_class == PlaceClass::room || white_class == PlaceClass::hallway,
          "room training map " + name + ": white cells must be rooms or hallways");
  const PlaceClass grey_class =
      white_class == PlaceClass::room ? PlaceClass::hallway : PlaceClass::room;
  RoomTrainingMap result{name, drawn,
                         Image<PlaceClass>(drawn.width(), drawn.height(), PlaceClass::none)};
  for (std::size_t i = 0; i < drawn.cells.size(); ++i) {
    const bool free = drawn.cells.data()[i] == CellState::free;
    const bool is_white = white.cells.data()[i] == CellState::free;
    require(free || !is_white,
            "room training map " + name + ": a white cell outside the free space");
    if (free) result.places.data()[i] = is_white ? white_class : grey_class;
  }
  return result;
}

RoomClassifier train_room_classifier(const compute::Context& context,
                                     const std::vector<RoomTrainingMap>& maps,
                                     const ClassifierTrainingParams& params) {
  require(!maps.empty(), "room classifier training: no training maps");
  require(params.sample_stride >= 1, "room classifier training: sample_stride must be >= 1");
  std::vector<float> features;
  std::vector<int> labels;
  for (const RoomTrainingMap& training : maps) {
    check_map(training.map, "room training map " + training.name);
    require(training.places.width() == training.map.width() &&
                training.places.height() == training.map.height(),
            "room training map " + training.name + ": the classes differ from the map in size");
    const LaserScanner scanner(training.map, params.scan);
    std::vector<Cell> cells;
    for (int row = 0; row < training.map.height(); ++row) {
      for (int col = 0; col < training.map.width(); ++col) {
        const PlaceClass place = training.places(col, row);
        if (place == PlaceClass::none || training.map.cells(col, row) != CellState::free ||
            !on_lattice(col, row, params.sample_stride))
          continue;
        cells.push_back({col, row});
        labels.push_back(place == PlaceClass::room ? 1 : -1);
      }
    }
    const std::vector<float> map_features = features_at(context, scanner, cells, params.features);
    features.insert(features.end(), map_features.begin(), map_features.end());
  }
  return RoomClassifier::train(features, labels, params.weak_count, params.max_depth);
}

// ---- Segmentation ------------------------------------------------------------------------------

Image<PlaceClass> classify_places(const compute::Context& context, const OccupancyGrid& map,
                                  const RoomClassifier& classifier,
                                  const FeatureSegmentationParams& params) {
  check_map(map, "feature-based room segmentation");
  require(!classifier.empty(), "feature-based room segmentation: the room classifier is empty");
  require(params.sample_stride >= 1, "feature-based room segmentation: sample_stride must be >= 1");
  const int width = map.width(), height = map.height();
  std::vector<Cell> cells;
  for (int row = 0; row < height; ++row) {
    for (int col = 0; col < width; ++col) {
      if (map.cells(col, row) == CellState::free && on_lattice(col, row, params.sample_stride))
        cells.push_back({col, row});
    }
  }
  const LaserScanner scanner(map, params.scan);
  const std::vector<float> scores =
      smoothed(cells, classifier.scores(features_at(context, scanner, cells, params.features)),
               params.sample_stride, params.smoothing_radius);
  // Classes as labels 1 (room) and 2 (hallway), grown over the free cells between the lattice's.
  LabelImage classes(width, height, 0);
  for (std::size_t i = 0; i < cells.size(); ++i) {
    classes(cells[i].col, cells[i].row) =
        static_cast<Label>(scores[i] > 0 ? PlaceClass::room : PlaceClass::hallway);
  }
  grow_rooms(classes, map);
  Image<PlaceClass> places(width, height, PlaceClass::none);
  for (std::size_t i = 0; i < classes.size(); ++i)
    places.data()[i] = static_cast<PlaceClass>(classes.data()[i]);
  return places;
}

std::filesystem::path default_room_classifier_path() {
  if (const char* configured = std::getenv("KARTOGRAF_ROOM_MODEL"); configured && *configured)
    return configured;
  return models_dir() / "rooms" / "room_hallway_boost.yml.gz";
}

RoomSegmentation segment_feature_based(const compute::Context& context, const OccupancyGrid& map,
                                       const RoomClassifier& classifier,
                                       const FeatureSegmentationParams& params) {
  const Clock::time_point start = Clock::now();
  check_map(map, "feature-based room segmentation");
  params.region_area.check("feature-based room segmentation");
  const Image<PlaceClass> places = classify_places(context, map, classifier, params);
  const int width = map.width(), height = map.height();
  const double cell_area = map.resolution * map.resolution;
  LabelImage rooms(width, height, 0);
  Label next = 0;
  for (const PlaceClass place : {PlaceClass::room, PlaceClass::hallway}) {
    const Image<std::uint8_t> mask = core_of(places, place, params.core_margin_m / map.resolution);
    const LabelImage regions = label_connected_components(mask, {Connectivity::eight, 1});
    Label count = 0;
    for (const Label l : regions.pixels()) count = std::max(count, l);
    std::vector<int> cells(static_cast<std::size_t>(count) + 1, 0);
    for (const Label l : regions.pixels()) ++cells[l];
    std::vector<Label> room_of(cells.size(), 0);
    for (std::size_t l = 1; l < cells.size(); ++l) {
      if (params.region_area.contains(cells[l] * cell_area) && next < 65535) room_of[l] = ++next;
    }
    for (std::size_t i = 0; i < rooms.size(); ++i) {
      if (const Label room = room_of[regions.data()[i]]) rooms.data()[i] = room;
    }
  }
  grow_rooms(rooms, map);
  return finish_segmentation(std::move(rooms), map, "feature", start);
}

}  // namespace kartograf::rooms
