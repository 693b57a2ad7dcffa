#include "peer_report.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <map>
#include <numbers>
#include <ostream>
#include <set>
#include <sstream>

#include "kartograf/core/se3.hpp"

namespace kartograf::peer {
namespace {

const char* input_name(InputKind input) {
  switch (input) {
    case InputKind::rgbd:
      return "RGB-D frames";
    case InputKind::cloud_full:
      return "full clouds";
    default:
      return "~20k clouds";
  }
}

}  // namespace

std::string fixed(double value, int digits) {
  std::ostringstream text;
  text << std::fixed << std::setprecision(digits) << value;
  return text.str();
}

std::string ratio(double numerator, double denominator) {
  if (!(denominator > 0)) return "-";
  return fixed(numerator / denominator, numerator / denominator < 10 ? 2 : 0) + "x";
}

double median(std::vector<double> values) {
  if (values.empty()) return 0;
  std::sort(values.begin(), values.end());
  const std::size_t middle = values.size() / 2;
  return values.size() % 2 ? values[middle] : 0.5 * (values[middle - 1] + values[middle]);
}

PairOutcome score(const FramePair& pair, const Estimate& estimate, std::vector<double> seconds,
                  std::vector<double> cpu_seconds) {
  PairOutcome outcome;
  outcome.pair = &pair;
  outcome.calls = static_cast<int>(seconds.size());
  outcome.seconds = median(std::move(seconds));
  outcome.cpu_seconds = median(std::move(cpu_seconds));
  outcome.estimate = estimate;
  const Eigen::Isometry3d error = pair.truth.inverse() * estimate.source_to_target;
  outcome.rotation_error_deg = se3::rotation_angle(error) * 180.0 / std::numbers::pi;
  outcome.translation_error_mm = 1000.0 * error.translation().norm();
  return outcome;
}

double MethodOutcome::median_seconds() const {
  std::vector<double> seconds;
  for (const PairOutcome& pair : pairs) seconds.push_back(pair.seconds);
  return median(std::move(seconds));
}

double MethodOutcome::median_cpu_seconds() const {
  std::vector<double> seconds;
  for (const PairOutcome& pair : pairs) seconds.push_back(pair.cpu_seconds);
  return median(std::move(seconds));
}

void print_pair_table(std::ostream& out, const std::vector<MethodOutcome>& outcomes) {
  struct Times {
    double wall = 0, cpu = 0;
  };
  std::map<std::string, Times> kartograf_times;
  std::set<int> gaps;
  for (const MethodOutcome& outcome : outcomes) {
    if (outcome.method->library == "kartograf") {
      kartograf_times[outcome.method->name] = {outcome.median_seconds(),
                                               outcome.median_cpu_seconds()};
    }
    for (const PairOutcome& pair : outcome.pairs) gaps.insert(pair.pair->gap());
  }
  const auto ratios = [&kartograf_times](const Times& times, const std::string& baseline) {
    const auto found = kartograf_times.find(baseline);
    if (found == kartograf_times.end()) return std::string("-");
    return ratio(times.wall, found->second.wall) + " / " + ratio(times.cpu, found->second.cpu);
  };

  out << "| method | input | threads | wall ms | CPU ms | frames/s | ratio to same-input Kartograf "
         "(wall / CPU) | ratio to Kartograf odometry (wall / CPU) |";
  for (const int gap : gaps) {
    out << " rot err gap " << gap << " (deg) | trans err gap " << gap << " (mm) |";
  }
  out << " worst rot (deg) | worst trans (mm) | failed |\n|---|---|---|---:|---:|---:|---:|---:|";
  for (std::size_t i = 0; i < gaps.size(); ++i) out << "---:|---:|";
  out << "---:|---:|---:|\n";

  for (const MethodOutcome& outcome : outcomes) {
    const Method& method = *outcome.method;
    const Times times{outcome.median_seconds(), outcome.median_cpu_seconds()};
    out << "| " << method.name << " | " << input_name(method.input) << " | " << method.threads
        << " | " << fixed(1000 * times.wall, 1) << " | " << fixed(1000 * times.cpu, 1) << " | "
        << fixed(1 / times.wall, 1) << " | " << ratios(times, method.compared_with) << " | "
        << (method.library == "kartograf" ? "-" : ratios(times, kKartografOdometry)) << " |";
    for (const int gap : gaps) {
      std::vector<double> rotation, translation;
      for (const PairOutcome& pair : outcome.pairs) {
        if (pair.pair->gap() != gap) continue;
        rotation.push_back(pair.rotation_error_deg);
        translation.push_back(pair.translation_error_mm);
      }
      out << " " << fixed(median(rotation), 3) << " | " << fixed(median(translation), 1) << " |";
    }
    double worst_rotation = 0, worst_translation = 0;
    int failed = 0;
    for (const PairOutcome& pair : outcome.pairs) {
      worst_rotation = std::max(worst_rotation, pair.rotation_error_deg);
      worst_translation = std::max(worst_translation, pair.translation_error_mm);
      failed += pair.estimate.success ? 0 : 1;
    }
    out << " " << fixed(worst_rotation, 3) << " | " << fixed(worst_translation, 1) << " | "
        << failed << "/" << outcome.pairs.size() << " |\n";
  }
}

void print_pair_details(std::ostream& out, const std::vector<MethodOutcome>& outcomes) {
  for (const MethodOutcome& outcome : outcomes) {
    for (const PairOutcome& pair : outcome.pairs) {
      const Eigen::Isometry3d& truth = pair.pair->truth;
      out << outcome.method->name << " | " << pair.pair->label() << " | motion "
          << fixed(se3::rotation_angle(truth) * 180.0 / std::numbers::pi, 2) << " deg "
          << fixed(1000 * truth.translation().norm(), 1) << " mm | error "
          << fixed(pair.rotation_error_deg, 3) << " deg " << fixed(pair.translation_error_mm, 1)
          << " mm | " << fixed(1000 * pair.seconds, 1) << " ms x" << pair.calls
          << (pair.estimate.success ? "" : " | reported failure") << "\n";
    }
  }
}

void print_chain_table(std::ostream& out, const std::vector<ChainOutcome>& outcomes) {
  out << "| data set | method | threads | frames | median ms/frame | ATE RMSE (cm) | "
         "RPE 1 frame trans RMSE (mm) | RPE 1 frame rot RMSE (deg) | failed frames |\n"
         "|---|---|---|---:|---:|---:|---:|---:|---:|\n";
  for (const ChainOutcome& chain : outcomes) {
    out << "| " << chain.dataset << " | " << chain.method << " | " << chain.threads << " | "
        << chain.frames << " | " << fixed(chain.median_ms, 1) << " | "
        << fixed(100 * chain.ate_rmse_m, 2) << " | " << fixed(chain.rpe_translation_rmse_mm, 2)
        << " | " << fixed(chain.rpe_rotation_rmse_deg, 3) << " | " << chain.failures << " |\n";
  }
}

}  // namespace kartograf::peer
