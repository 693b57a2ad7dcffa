#include "kartograf/semantic/cascade_training.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <random>
#include <sstream>
#include <thread>

#include "kartograf/core/error.hpp"
#include "semantic/haar_pyramid.hpp"

namespace kartograf::semantic {
namespace {

constexpr int kBins = 256;

// The stage's samples as one byte matrix: bins[f * samples + s] is feature f's bin for sample s.
struct BinnedFeatures {
  std::vector<std::uint8_t> bins;
  std::vector<float> minimum, bin_width;
};

BinnedFeatures bin_features(const std::vector<HaarFeature>& features,
                            const std::vector<IntegralImage>& samples,
                            const std::vector<double>& inverse_norms) {
  const std::size_t n = samples.size();
  BinnedFeatures out;
  out.bins.resize(features.size() * n);
  out.minimum.resize(features.size());
  out.bin_width.resize(features.size());
  std::vector<float> values(n);
  for (std::size_t f = 0; f < features.size(); ++f) {
    for (std::size_t s = 0; s < n; ++s) {
      values[s] = static_cast<float>(haar_value(features[f], samples[s], 0, 0) * inverse_norms[s]);
    }
    const auto [lo, hi] = std::minmax_element(values.begin(), values.end());
    const float width = (*hi - *lo) / kBins;
    out.minimum[f] = *lo;
    out.bin_width[f] = width;
    std::uint8_t* row = out.bins.data() + f * n;
    for (std::size_t s = 0; s < n; ++s) {
      const int b = width > 0 ? static_cast<int>((values[s] - *lo) / width) : 0;
      row[s] = static_cast<std::uint8_t>(std::clamp(b, 0, kBins - 1));
    }
  }
  return out;
}

struct StumpChoice {
  std::size_t feature = 0;
  int last_left_bin = -1;  // bins <= this go left
  double left = 0, right = 0, score = -1;
};

// The gentle-AdaBoost stump minimising the weighted squared error over features [begin, end):
// maximises Sl^2 / Wl + Sr^2 / Wr (S: sum of w y, W: sum of w on a side).
StumpChoice best_stump(const BinnedFeatures& binned, std::size_t samples, std::size_t begin,
                       std::size_t end, const std::vector<double>& weights,
                       const std::vector<double>& labels) {
  StumpChoice best;
  double hw[kBins], hwy[kBins];
  double total_w = 0, total_wy = 0;
  for (std::size_t s = 0; s < samples; ++s)
    total_w += weights[s], total_wy += weights[s] * labels[s];
  for (std::size_t f = begin; f < end; ++f) {
    if (binned.bin_width[f] <= 0) continue;
    std::fill(hw, hw + kBins, 0.0);
    std::fill(hwy, hwy + kBins, 0.0);
    const std::uint8_t* row = binned.bins.data() + f * samples;
    for (std::size_t s = 0; s < samples; ++s) {
      hw[row[s]] += weights[s];
      hwy[row[s]] += weights[s] * labels[s];
    }
    double wl = 0, sl = 0;
    for (int b = 0; b < kBins - 1; ++b) {
      wl += hw[b], sl += hwy[b];
      const double wr = total_w - wl, sr = total_wy - sl;
      if (wl <= 1e-12 || wr <= 1e-12) continue;
      const double score = sl * sl / wl + sr * sr / wr;
      if (score > best.score) best = {f, b, sl / wl, sr / wr, score};
    }
  }
  return best;
}

// Candidate negatives: windows of `image` that the cascade so far lets through, at most `limit`
// of them, chosen at random.
void mine_windows(const HaarCascade& cascade, const TrainingBackground& background,
                  const DetectionParams& scan, double max_iou, int limit, std::mt19937_64& rng,
                  std::vector<GrayImage>& out) {
  struct Candidate {
    std::size_t level;
    int x, y;
  };
  const std::vector<PyramidLevel> levels = build_pyramid(background.image, cascade.window, scan);
  auto overlaps_object = [&](const PyramidLevel& level, int x, int y) {
    const int side = static_cast<int>(std::lround(cascade.window * level.scale));
    const Detection box{static_cast<int>(std::lround(x * level.scale)),
                        static_cast<int>(std::lround(y * level.scale)),
                        side,
                        side,
                        0,
                        1};
    return std::any_of(
        background.objects.begin(), background.objects.end(),
        [&](const Detection& o) { return intersection_over_union(box, o) >= max_iou; });
  };
  std::vector<Candidate> candidates;
  for (std::size_t l = 0; l < levels.size(); ++l) {
    const IntegralImage& integral = levels[l].integral;
    for (int y = 0; y + cascade.window <= integral.height(); y += scan.step) {
      for (int x = 0; x + cascade.window <= integral.width(); x += scan.step) {
        if (evaluate_window(cascade, integral, x, y) == static_cast<int>(cascade.stages.size()) &&
            !overlaps_object(levels[l], x, y)) {
          candidates.push_back({l, x, y});
        }
      }
    }
  }
  std::shuffle(candidates.begin(), candidates.end(), rng);
  if (static_cast<int>(candidates.size()) > limit)
    candidates.resize(static_cast<std::size_t>(limit));
  for (const Candidate& c : candidates) {
    out.push_back(crop(levels[c.level].image, c.x, c.y, cascade.window));
  }
}

void check_inputs(const std::vector<GrayImage>& positives,
                  const std::vector<TrainingBackground>& backgrounds,
                  const CascadeTrainingParams& p) {
  require(p.window >= 4 && p.max_stages >= 1 && p.max_stumps_per_stage >= 1 && p.min_hit_rate > 0 &&
              p.min_hit_rate <= 1 && p.max_false_alarm > 0 && p.max_false_alarm < 1 &&
              p.negatives_per_stage >= 1 && p.max_windows_per_background >= 1 &&
              p.min_stddev >= 0 && p.negative_max_iou > 0 && p.negative_max_iou <= 1,
          "train_cascade: parameters out of range (window >= 4, stages/stumps/negatives >= 1, "
          "0 < min_hit_rate <= 1, 0 < max_false_alarm < 1, 0 < negative_max_iou <= 1)");
  require(!positives.empty(), "train_cascade: no positive examples");
  require(!backgrounds.empty(), "train_cascade: no background images");
  for (std::size_t i = 0; i < positives.size(); ++i) {
    require(positives[i].width() == p.window && positives[i].height() == p.window,
            "train_cascade: positive " + std::to_string(i) + " is " +
                std::to_string(positives[i].width()) + "x" + std::to_string(positives[i].height()) +
                ", not " + std::to_string(p.window) + "x" + std::to_string(p.window));
  }
  for (std::size_t i = 0; i < backgrounds.size(); ++i) {
    require(backgrounds[i].image.width() >= p.window && backgrounds[i].image.height() >= p.window,
            "train_cascade: background " + std::to_string(i) + " is smaller than the window");
  }
}

// Keeps only the features that stumps use, renumbering the stumps.
void compact_features(HaarCascade& cascade) {
  std::map<int, int> renumber;
  std::vector<HaarFeature> used;
  for (CascadeStage& stage : cascade.stages) {
    for (WeakStump& s : stage.stumps) {
      auto [it, inserted] = renumber.try_emplace(s.feature, static_cast<int>(used.size()));
      if (inserted) used.push_back(cascade.features[static_cast<std::size_t>(s.feature)]);
      s.feature = it->second;
    }
  }
  cascade.features = std::move(used);
}

// Negatives for the next stage: windows every earlier stage lets through, mined from the
// backgrounds in a new random order, at most negatives_per_stage of them.
std::vector<GrayImage> mine_negatives(const HaarCascade& cascade,
                                      const std::vector<TrainingBackground>& backgrounds,
                                      std::vector<std::size_t>& background_order,
                                      const DetectionParams& scan,
                                      const CascadeTrainingParams& params, std::mt19937_64& rng) {
  std::vector<GrayImage> negatives;
  std::shuffle(background_order.begin(), background_order.end(), rng);
  for (std::size_t i : background_order) {
    if (static_cast<int>(negatives.size()) >= params.negatives_per_stage) break;
    mine_windows(cascade, backgrounds[i], scan, params.negative_max_iou,
                 params.max_windows_per_background, rng, negatives);
  }
  if (static_cast<int>(negatives.size()) > params.negatives_per_stage) {
    negatives.resize(static_cast<std::size_t>(params.negatives_per_stage));
  }
  return negatives;
}

// One stage's samples (np positives then nn negatives) as binned features, with their labels
// (+1 / -1), boosting weights and the stage's scores so far.
struct StageSamples {
  std::size_t np, nn, n;
  std::vector<double> labels, weights, scores;
  BinnedFeatures binned;
};

// Labels +1 / -1, weights half and half, scores 0.
StageSamples make_stage_samples(const HaarCascade& cascade, const std::vector<GrayImage>& positives,
                                const std::vector<GrayImage>& negatives) {
  const std::size_t np = positives.size(), nn = negatives.size(), n = np + nn;
  StageSamples out{
      np, nn, n, std::vector<double>(n), std::vector<double>(n), std::vector<double>(n, 0.0), {}};
  std::vector<IntegralImage> samples;
  std::vector<double> inverse_norms;
  samples.reserve(n);
  for (std::size_t s = 0; s < n; ++s) {
    samples.emplace_back(s < np ? positives[s] : negatives[s - np]);
    inverse_norms.push_back(1.0 / window_normaliser(cascade, samples.back(), 0, 0));
    out.labels[s] = s < np ? 1.0 : -1.0;
    out.weights[s] = s < np ? 0.5 / static_cast<double>(np) : 0.5 / static_cast<double>(nn);
  }
  out.binned = bin_features(cascade.features, samples, inverse_norms);
  return out;
}

// The best stump over all `features`: their two halves on two threads.
StumpChoice best_stump_in_parallel(const StageSamples& s, std::size_t features) {
  const std::size_t half = features / 2;
  StumpChoice second;
  std::thread worker(
      [&] { second = best_stump(s.binned, s.n, half, features, s.weights, s.labels); });
  StumpChoice best = best_stump(s.binned, s.n, 0, half, s.weights, s.labels);
  worker.join();
  if (second.score > best.score) best = second;
  return best;
}

// Adds the stump's response to every sample's score and reweights the samples (sum 1).
void apply_stump(StageSamples& s, const StumpChoice& best) {
  const std::uint8_t* row = s.binned.bins.data() + best.feature * s.n;
  double total = 0;
  for (std::size_t i = 0; i < s.n; ++i) {
    const double h = row[i] <= best.last_left_bin ? best.left : best.right;
    s.scores[i] += h;
    s.weights[i] *= std::exp(-s.labels[i] * h);
    total += s.weights[i];
  }
  for (double& w : s.weights) w /= total;
}

// A trained stage with its false alarm and hit rate on the stage's samples.
struct StageResult {
  CascadeStage stage;
  double false_alarm = 1, hit_rate = 1;
};

// Sets the stage's threshold to keep min_hit_rate of the positives, and the false alarm it leaves.
void set_threshold(const StageSamples& s, const CascadeTrainingParams& params,
                   StageResult& result) {
  std::vector<double> positive_scores(s.np);
  std::copy_n(s.scores.begin(), s.np, positive_scores.begin());
  std::sort(positive_scores.begin(), positive_scores.end(), std::greater<>());
  const std::size_t keep = std::clamp<std::size_t>(
      static_cast<std::size_t>(std::ceil(params.min_hit_rate * static_cast<double>(s.np))), 1,
      s.np);
  result.stage.threshold = static_cast<float>(positive_scores[keep - 1] - 1e-6);
  std::size_t passing = 0;
  for (std::size_t i = s.np; i < s.n; ++i) passing += s.scores[i] >= result.stage.threshold;
  result.false_alarm = static_cast<double>(passing) / static_cast<double>(s.nn);
  result.hit_rate = static_cast<double>(keep) / static_cast<double>(s.np);
}

// Gentle AdaBoost: stumps until the stage's false alarm is low enough (or max_stumps_per_stage).
StageResult train_stage(const HaarCascade& cascade, StageSamples& samples,
                        const CascadeTrainingParams& params) {
  StageResult result;
  while (static_cast<int>(result.stage.stumps.size()) < params.max_stumps_per_stage) {
    const StumpChoice best = best_stump_in_parallel(samples, cascade.features.size());
    if (best.score < 0) break;  // no feature separates anything
    const std::size_t f = best.feature;
    const BinnedFeatures& binned = samples.binned;
    result.stage.stumps.push_back(
        {static_cast<int>(f), binned.minimum[f] + binned.bin_width[f] * (best.last_left_bin + 1),
         static_cast<float>(best.left), static_cast<float>(best.right)});
    apply_stump(samples, best);
    set_threshold(samples, params, result);
    if (result.false_alarm <= params.max_false_alarm) break;
  }
  return result;
}

// The positives the stage passes (those it rejects the detector would never see again).
std::vector<GrayImage> passing_positives(std::vector<GrayImage>& positives,
                                         const std::vector<double>& scores, float threshold) {
  std::vector<GrayImage> kept;
  for (std::size_t s = 0; s < positives.size(); ++s) {
    if (scores[s] >= threshold) kept.push_back(std::move(positives[s]));
  }
  return kept;
}

std::string stage_line(int stage_index, const StageResult& result, std::size_t negatives,
                       std::size_t positives_left) {
  std::ostringstream line;
  line << "stage " << stage_index << ": " << result.stage.stumps.size() << " stumps, false alarm "
       << result.false_alarm << " on " << negatives << " negatives, hit rate " << result.hit_rate
       << " (" << positives_left << " positives left)";
  return line.str();
}

// A cascade without stages, with every feature of its window.
HaarCascade empty_cascade(const CascadeTrainingParams& params) {
  HaarCascade cascade;
  cascade.object_class = params.object_class;
  cascade.window = params.window;
  cascade.min_stddev = params.min_stddev;
  cascade.features = enumerate_haar_features(params.window, params.feature_position_step,
                                             params.feature_size_step);
  return cascade;
}

}  // namespace

HaarCascade train_cascade(const std::vector<GrayImage>& positives,
                          const std::vector<TrainingBackground>& backgrounds,
                          const CascadeTrainingParams& params, CascadeTrainingReport* report,
                          const std::function<void(const std::string&)>& log) {
  check_inputs(positives, backgrounds, params);
  const auto start = std::chrono::steady_clock::now();
  HaarCascade cascade = empty_cascade(params);
  CascadeTrainingReport local;
  CascadeTrainingReport& rep = report ? *report : local;
  rep = {};
  rep.features_considered = static_cast<int>(cascade.features.size());
  DetectionParams scan = params.scan;
  scan.min_size = std::max(scan.min_size, params.window);
  std::mt19937_64 rng(params.seed);
  std::vector<std::size_t> background_order(backgrounds.size());
  for (std::size_t i = 0; i < backgrounds.size(); ++i) background_order[i] = i;

  std::vector<GrayImage> current_positives = positives;
  for (int stage_index = 0; stage_index < params.max_stages; ++stage_index) {
    const std::vector<GrayImage> negatives =
        mine_negatives(cascade, backgrounds, background_order, scan, params, rng);
    if (negatives.size() < 20) {
      rep.ran_out_of_negatives = true;
      if (log)
        log("stage " + std::to_string(stage_index) + ": only " + std::to_string(negatives.size()) +
            " negative windows left; stopping");
      break;
    }
    StageSamples samples = make_stage_samples(cascade, current_positives, negatives);
    const StageResult result = train_stage(cascade, samples, params);
    cascade.stages.push_back(result.stage);
    rep.stumps_per_stage.push_back(static_cast<int>(result.stage.stumps.size()));
    rep.stage_false_alarm.push_back(result.false_alarm);
    rep.stage_hit_rate.push_back(result.hit_rate);
    current_positives =
        passing_positives(current_positives, samples.scores, result.stage.threshold);
    if (log) log(stage_line(stage_index, result, samples.nn, current_positives.size()));
    if (current_positives.empty()) break;
  }
  compact_features(cascade);
  rep.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  require(!cascade.stages.empty(),
          "train_cascade: no stage could be trained (too few background windows?)");
  return cascade;
}

}  // namespace kartograf::semantic
