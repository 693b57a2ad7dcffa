// The Voronoi random field's trained model: boosted place classifiers, their calibration and the
// pairwise compatibility (voronoi_random_field.hpp).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <string>

#include <opencv2/core.hpp>
#include <opencv2/ml.hpp>

#include "kartograf/core/error.hpp"
#include "kartograf/core/models.hpp"
#include "kartograf/rooms/voronoi_random_field.hpp"

namespace kartograf::rooms {

namespace {

constexpr int kFeatures = static_cast<int>(kVrfFeatureCount);
constexpr std::array<const char*, kPlaceLabels> kClassifierNames = {"room", "hallway", "doorway"};
using Calibration =
    Eigen::Matrix<double, kPlaceLabels, kPlaceLabels + 1>;  // logits = W [scores; 1]

}  // namespace

struct VrfModel::Model {
  std::array<cv::Ptr<cv::ml::Boost>, kPlaceLabels> classifiers;
  Calibration calibration = Calibration::Zero();
  Eigen::Matrix3d compatibility = Eigen::Matrix3d::Zero();
  double pairwise_weight = 1.0;
};

namespace {

// Rows of features with their labels (PlaceLabel) and the map they come from.
struct Samples {
  std::vector<float> features;
  std::vector<int> labels;
  std::vector<int> maps;
  std::size_t size() const { return labels.size(); }
};

// The nodes of one training map at the model's spacing: for the compatibility and the pairwise
// weight. label -1: unlabelled.
struct FieldSample {
  std::vector<VrfFeatures> features;
  std::vector<int> labels;
  std::vector<std::pair<int, int>> edges;
};

cv::Ptr<cv::ml::Boost> train_one_vs_rest(const Samples& samples, int positive,
                                         const std::vector<std::size_t>& rows,
                                         const VrfTrainingParams& params) {
  cv::Mat x(static_cast<int>(rows.size()), kFeatures, CV_32F),
      y(static_cast<int>(rows.size()), 1, CV_32S);
  int positives = 0;
  for (std::size_t r = 0; r < rows.size(); ++r) {
    std::copy_n(samples.features.begin() + static_cast<std::ptrdiff_t>(rows[r] * kVrfFeatureCount),
                kFeatures, x.ptr<float>(static_cast<int>(r)));
    const bool is = samples.labels[rows[r]] == positive;
    y.at<int>(static_cast<int>(r)) = is ? 1 : -1;
    positives += is;
  }
  require(positives > 0 && positives < static_cast<int>(rows.size()),
          std::string("VRF training: the ") + kClassifierNames[static_cast<std::size_t>(positive)] +
              " classifier needs samples of its class and of the others");
  cv::Ptr<cv::ml::Boost> boost = cv::ml::Boost::create();
  boost->setBoostType(cv::ml::Boost::DISCRETE);
  boost->setWeakCount(params.weak_count);
  boost->setWeightTrimRate(0);
  boost->setMaxDepth(params.max_depth);
  boost->setUseSurrogates(false);
  boost->train(cv::ml::TrainData::create(x, cv::ml::ROW_SAMPLE, y));
  return boost;
}

// Raw scores of the three classifiers, rows of kPlaceLabels.
std::vector<double> raw_scores(const std::array<cv::Ptr<cv::ml::Boost>, kPlaceLabels>& classifiers,
                               const float* features, std::size_t rows) {
  std::vector<double> scores(rows * kPlaceLabels);
  if (rows == 0) return scores;
  const cv::Mat x(static_cast<int>(rows), kFeatures, CV_32F, const_cast<float*>(features));
  for (std::size_t c = 0; c < kPlaceLabels; ++c) {
    cv::Mat out;
    classifiers[c]->predict(x, out, cv::ml::StatModel::RAW_OUTPUT);
    for (std::size_t r = 0; r < rows; ++r)
      scores[r * kPlaceLabels + c] = out.at<float>(static_cast<int>(r), 0);
  }
  return scores;
}

LabelScores log_softmax(const Eigen::Vector3d& logits) {
  const double top = logits.maxCoeff();
  const double log_sum = top + std::log((logits.array() - top).exp().sum());
  return {logits[0] - log_sum, logits[1] - log_sum, logits[2] - log_sum};
}

Eigen::Vector3d logits_of(const Calibration& w, const double* scores) {
  const Eigen::Vector4d x(scores[0], scores[1], scores[2], 1.0);
  return w * x;
}

// Multinomial logistic regression of the labels on the scores (gradient descent with momentum on
// standardised scores, a little L2).
Calibration fit_calibration(const std::vector<double>& scores, const std::vector<int>& labels) {
  const std::size_t n = labels.size();
  Eigen::Vector3d scale = Eigen::Vector3d::Ones();
  for (std::size_t c = 0; c < kPlaceLabels; ++c) {
    double sum2 = 0;
    for (std::size_t r = 0; r < n; ++r)
      sum2 += scores[r * kPlaceLabels + c] * scores[r * kPlaceLabels + c];
    scale[static_cast<int>(c)] = n > 0 && sum2 > 0 ? std::sqrt(sum2 / static_cast<double>(n)) : 1.0;
  }
  Calibration w = Calibration::Zero(), velocity = Calibration::Zero();
  for (int c = 0; c < kPlaceLabels; ++c) w(c, c) = 1.0;
  for (int iteration = 0; iteration < 600; ++iteration) {
    Calibration gradient = Calibration::Zero();
    for (std::size_t r = 0; r < n; ++r) {
      const Eigen::Vector4d x(scores[r * 3] / scale[0], scores[r * 3 + 1] / scale[1],
                              scores[r * 3 + 2] / scale[2], 1.0);
      const LabelScores lp = log_softmax(w * x);
      for (int c = 0; c < kPlaceLabels; ++c)
        gradient.row(c) +=
            (std::exp(lp[static_cast<std::size_t>(c)]) - (labels[r] == c ? 1.0 : 0.0)) *
            x.transpose();
    }
    gradient /= static_cast<double>(std::max<std::size_t>(n, 1));
    gradient.leftCols<kPlaceLabels>() += 1e-4 * w.leftCols<kPlaceLabels>();
    velocity = 0.9 * velocity - 0.5 * gradient;
    w += velocity;
  }
  for (int k = 0; k < kPlaceLabels; ++k) w.col(k) /= scale[k];  // back to raw scores
  return w;
}

// Pointwise mutual information of the labels at the two ends of an edge (add-one counts).
Eigen::Matrix3d label_compatibility(const std::vector<FieldSample>& fields) {
  Eigen::Matrix3d counts = Eigen::Matrix3d::Ones();
  for (const FieldSample& f : fields) {
    for (const auto& [a, b] : f.edges) {
      const int la = f.labels[static_cast<std::size_t>(a)],
                lb = f.labels[static_cast<std::size_t>(b)];
      if (la < 0 || lb < 0) continue;
      counts(la, lb) += 1;
      counts(lb, la) += 1;
    }
  }
  const double total = counts.sum();
  const Eigen::Vector3d marginal = counts.rowwise().sum() / total;
  Eigen::Matrix3d pmi;
  for (int a = 0; a < kPlaceLabels; ++a)
    for (int b = 0; b < kPlaceLabels; ++b)
      pmi(a, b) = std::log(counts(a, b) / total / (marginal[a] * marginal[b]));
  return pmi;
}

// The pairwise weight of largest pseudo-likelihood of the labelled nodes given their labelled
// neighbours, from held-out unaries (a grid over [0, 3]).
double pseudo_likelihood_weight(const std::vector<std::vector<LabelScores>>& unaries,
                                const std::vector<FieldSample>& fields,
                                const Eigen::Matrix3d& compatibility) {
  double best_weight = 0, best = -std::numeric_limits<double>::infinity();
  for (int step = 0; step <= 60; ++step) {
    const double weight = 0.05 * step;
    double total = 0;
    for (std::size_t m = 0; m < fields.size(); ++m) {
      const FieldSample& f = fields[m];
      std::vector<LabelScores> local = unaries[m];
      for (const auto& [a, b] : f.edges) {
        const int la = f.labels[static_cast<std::size_t>(a)],
                  lb = f.labels[static_cast<std::size_t>(b)];
        for (int l = 0; l < kPlaceLabels; ++l) {
          if (lb >= 0)
            local[static_cast<std::size_t>(a)][static_cast<std::size_t>(l)] +=
                weight * compatibility(l, lb);
          if (la >= 0)
            local[static_cast<std::size_t>(b)][static_cast<std::size_t>(l)] +=
                weight * compatibility(l, la);
        }
      }
      for (std::size_t i = 0; i < local.size(); ++i) {
        if (f.labels[i] < 0) continue;
        const LabelScores lp = log_softmax(Eigen::Vector3d(local[i][0], local[i][1], local[i][2]));
        total += lp[static_cast<std::size_t>(f.labels[i])];
      }
    }
    if (total > best) best = total, best_weight = weight;
  }
  return best_weight;
}

std::vector<float> flat(const std::vector<VrfFeatures>& features) {
  std::vector<float> out;
  out.reserve(features.size() * kVrfFeatureCount);
  for (const VrfFeatures& f : features) out.insert(out.end(), f.begin(), f.end());
  return out;
}

int label_at(const VrfTrainingMap& m, const Eigen::Vector2i& cell) {
  return static_cast<int>(m.labels(cell.x(), cell.y())) - 1;
}

}  // namespace

VrfTrainingMap vrf_training_map(std::string name, const Image<std::uint8_t>& drawing,
                                double resolution) {
  require(std::isfinite(resolution) && resolution > 0,
          "VRF training map " + name + ": resolution must be > 0");
  require(!drawing.empty(), "VRF training map " + name + " is empty");
  VrfTrainingMap result;
  result.name = std::move(name);
  result.map.resolution = resolution;
  result.map.cells = Image<CellState>(drawing.width(), drawing.height(), CellState::occupied);
  result.labels = Image<std::uint8_t>(drawing.width(), drawing.height(), 0);
  for (int y = 0; y < drawing.height(); ++y) {
    for (int x = 0; x < drawing.width(); ++x) {
      const int v = drawing(x, y);
      if (v == 0) continue;
      result.map.cells(x, y) = CellState::free;
      if (v == 77) result.labels(x, y) = 1 + static_cast<int>(PlaceLabel::room);
      if (v == 115) result.labels(x, y) = 1 + static_cast<int>(PlaceLabel::hallway);
      if (v == 179) result.labels(x, y) = 1 + static_cast<int>(PlaceLabel::doorway);
    }
  }
  return result;
}

namespace {
// The classifiers' samples (every sample_stride-th node of each map with its room-type label) and
// each map's sparse field (the nodes and edges the random field is fitted on). Throws Error for a
// bad map, labels of another size, or a class no map has a sample of.
void collect_training_data(const std::vector<VrfTrainingMap>& maps, const VrfTrainingParams& params,
                           Samples& samples, std::vector<FieldSample>& fields) {
  for (std::size_t m = 0; m < maps.size(); ++m) {
    const VrfTrainingMap& training = maps[m];
    check_map(training.map, "VRF training map " + training.name);
    require(training.labels.width() == training.map.width() &&
                training.labels.height() == training.map.height(),
            "VRF training map " + training.name + ": the labels differ from the map in size");
    const OccupancyGrid work =
        params.furniture ? without_furniture(training.map, *params.furniture) : training.map;
    VrfNodeParams dense_params = params.nodes;
    dense_params.node_spacing = params.sample_stride;
    const VrfNodeGraph dense = vrf_node_graph(work, dense_params);
    const std::vector<VrfFeatures> dense_features = vrf_node_features(work, dense);
    for (std::size_t i = 0; i < dense.nodes.size(); ++i) {
      const int label = label_at(training, dense.nodes[i].cell);
      if (label < 0) continue;
      samples.features.insert(samples.features.end(), dense_features[i].begin(),
                              dense_features[i].end());
      samples.labels.push_back(label);
      samples.maps.push_back(static_cast<int>(m));
    }
    const VrfNodeGraph sparse = vrf_node_graph(work, params.nodes);
    FieldSample field{vrf_node_features(work, sparse), {}, sparse.edges};
    for (const VrfNode& node : sparse.nodes) field.labels.push_back(label_at(training, node.cell));
    fields.push_back(std::move(field));
  }
  for (int c = 0; c < kPlaceLabels; ++c) {
    require(std::count(samples.labels.begin(), samples.labels.end(), c) > 0,
            std::string("VRF training: no ") + kClassifierNames[static_cast<std::size_t>(c)] +
                " sample in the maps");
  }
}
}  // namespace

VrfModel VrfModel::train(const std::vector<VrfTrainingMap>& maps, const VrfTrainingParams& params) {
  require(params.folds >= 1 && static_cast<int>(maps.size()) >= params.folds,
          "VRF training: needs at least `folds` (" + std::to_string(params.folds) +
              ") training maps, got " + std::to_string(maps.size()));
  require(params.weak_count >= 1 && params.max_depth >= 1 && params.sample_stride >= 1,
          "VRF training: weak_count, max_depth and sample_stride must be >= 1");
  Samples samples;
  std::vector<FieldSample> fields;
  collect_training_data(maps, params, samples, fields);

  auto model = std::make_shared<Model>();
  const auto train_all = [&](const std::vector<std::size_t>& rows) {
    std::array<cv::Ptr<cv::ml::Boost>, kPlaceLabels> classifiers;
    for (int c = 0; c < kPlaceLabels; ++c)
      classifiers[static_cast<std::size_t>(c)] = train_one_vs_rest(samples, c, rows, params);
    return classifiers;
  };
  // Held-out scores: each fold of maps scored by classifiers trained on the others.
  std::vector<double> held_scores;
  std::vector<int> held_labels;
  std::vector<std::vector<double>> field_scores(maps.size());
  for (int fold = 0; fold < params.folds; ++fold) {
    std::vector<std::size_t> train_rows, test_rows;
    for (std::size_t r = 0; r < samples.size(); ++r)
      (params.folds == 1 || samples.maps[r] % params.folds != fold ? train_rows : test_rows)
          .push_back(r);
    if (params.folds == 1) test_rows = train_rows;
    const auto classifiers = train_all(train_rows);
    std::vector<float> rows;
    for (const std::size_t r : test_rows) {
      rows.insert(
          rows.end(), samples.features.begin() + static_cast<std::ptrdiff_t>(r * kVrfFeatureCount),
          samples.features.begin() + static_cast<std::ptrdiff_t>((r + 1) * kVrfFeatureCount));
      held_labels.push_back(samples.labels[r]);
    }
    const std::vector<double> s = raw_scores(classifiers, rows.data(), test_rows.size());
    held_scores.insert(held_scores.end(), s.begin(), s.end());
    for (std::size_t m = 0; m < maps.size(); ++m) {
      if (params.folds != 1 && static_cast<int>(m) % params.folds != fold) continue;
      const std::vector<float> f = flat(fields[m].features);
      field_scores[m] = raw_scores(classifiers, f.data(), fields[m].features.size());
    }
  }
  model->calibration = fit_calibration(held_scores, held_labels);
  model->compatibility = label_compatibility(fields);
  std::vector<std::vector<LabelScores>> unaries(maps.size());
  for (std::size_t m = 0; m < maps.size(); ++m) {
    for (std::size_t i = 0; i < fields[m].labels.size(); ++i)
      unaries[m].push_back(
          log_softmax(logits_of(model->calibration, &field_scores[m][i * kPlaceLabels])));
  }
  model->pairwise_weight = pseudo_likelihood_weight(unaries, fields, model->compatibility);
  std::vector<std::size_t> all(samples.size());
  for (std::size_t r = 0; r < all.size(); ++r) all[r] = r;
  model->classifiers = train_all(all);
  return VrfModel(std::move(model));
}

std::vector<LabelScores> VrfModel::unary(std::span<const VrfFeatures> features) const {
  require(!empty(), "VRF model: the model is empty (load or train one)");
  const std::vector<float> rows = flat(std::vector<VrfFeatures>(features.begin(), features.end()));
  const std::vector<double> scores = raw_scores(model_->classifiers, rows.data(), features.size());
  std::vector<LabelScores> result(features.size());
  for (std::size_t i = 0; i < features.size(); ++i)
    result[i] = log_softmax(logits_of(model_->calibration, &scores[i * kPlaceLabels]));
  return result;
}

const Eigen::Matrix3d& VrfModel::compatibility() const {
  require(!empty(), "VRF model: the model is empty (load or train one)");
  return model_->compatibility;
}

double VrfModel::trained_pairwise_weight() const {
  require(!empty(), "VRF model: the model is empty (load or train one)");
  return model_->pairwise_weight;
}

void VrfModel::save(const std::filesystem::path& path) const {
  const std::string name = path.string();
  require(!empty(), "VRF model: cannot save an empty model to " + name);
  try {
    cv::FileStorage fs(name, cv::FileStorage::WRITE);
    require(fs.isOpened(), "VRF model " + name + " cannot be written");
    fs << "kartograf_vrf_model" << 1;
    fs << "feature_count" << kFeatures;
    cv::Mat calibration(kPlaceLabels, kPlaceLabels + 1, CV_64F),
        compatibility(kPlaceLabels, kPlaceLabels, CV_64F);
    for (int r = 0; r < kPlaceLabels; ++r) {
      for (int c = 0; c <= kPlaceLabels; ++c)
        calibration.at<double>(r, c) = model_->calibration(r, c);
      for (int c = 0; c < kPlaceLabels; ++c)
        compatibility.at<double>(r, c) = model_->compatibility(r, c);
    }
    fs << "calibration" << calibration << "compatibility" << compatibility;
    fs << "pairwise_weight" << model_->pairwise_weight;
    for (std::size_t c = 0; c < kPlaceLabels; ++c) {
      fs << kClassifierNames[c] << "{";
      model_->classifiers[c]->write(fs);
      fs << "}";
    }
  } catch (const cv::Exception& e) {
    throw Error("VRF model " + name + " cannot be written: " + e.what());
  }
  require(std::filesystem::is_regular_file(path), "VRF model " + name + " was not written");
}

VrfModel VrfModel::load(const std::filesystem::path& path) {
  const std::string name = path.string();
  require(std::filesystem::is_regular_file(path),
          "VRF model " + name + " does not exist (train one with train_vrf)");
  auto model = std::make_shared<Model>();
  try {
    cv::FileStorage fs(name, cv::FileStorage::READ);
    require(fs.isOpened() && !fs["kartograf_vrf_model"].empty(),
            "VRF model " + name + " is not a Kartograf VRF model");
    require(static_cast<int>(fs["feature_count"]) == kFeatures,
            "VRF model " + name + " was trained on " +
                std::to_string(static_cast<int>(fs["feature_count"])) + " features, expected " +
                std::to_string(kFeatures));
    cv::Mat calibration, compatibility;
    fs["calibration"] >> calibration;
    fs["compatibility"] >> compatibility;
    require(calibration.rows == kPlaceLabels && calibration.cols == kPlaceLabels + 1 &&
                compatibility.rows == kPlaceLabels && compatibility.cols == kPlaceLabels &&
                calibration.type() == CV_64F && compatibility.type() == CV_64F,
            "VRF model " + name + ": calibration or compatibility has the wrong size");
    for (int r = 0; r < kPlaceLabels; ++r) {
      for (int c = 0; c <= kPlaceLabels; ++c)
        model->calibration(r, c) = calibration.at<double>(r, c);
      for (int c = 0; c < kPlaceLabels; ++c)
        model->compatibility(r, c) = compatibility.at<double>(r, c);
    }
    model->pairwise_weight = static_cast<double>(fs["pairwise_weight"]);
    for (std::size_t c = 0; c < kPlaceLabels; ++c) {
      cv::Ptr<cv::ml::Boost> boost = cv::ml::Boost::create();
      boost->read(fs[kClassifierNames[c]]);
      require(!boost->empty() && boost->isTrained() && boost->getVarCount() == kFeatures,
              std::string("VRF model ") + name + " holds no trained " + kClassifierNames[c] +
                  " classifier");
      model->classifiers[c] = boost;
    }
  } catch (const cv::Exception& e) {
    throw Error("VRF model " + name + " cannot be read: " + e.what());
  }
  return VrfModel(std::move(model));
}

std::filesystem::path default_vrf_model_path() {
  if (const char* configured = std::getenv("KARTOGRAF_VRF_MODEL"); configured && *configured)
    return configured;
  return models_dir() / "rooms" / "vrf_model.yml.gz";
}

}  // namespace kartograf::rooms
