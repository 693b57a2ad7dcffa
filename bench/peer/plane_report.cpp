#include "plane_report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <map>
#include <numbers>
#include <ostream>
#include <string>

#include "peer_report.hpp"

namespace kartograf::peer {
namespace {

double angle_deg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const double cosine = std::min(1.0, std::abs(a.normalized().dot(b.normalized())));
  return std::acos(cosine) * 180.0 / std::numbers::pi;
}

std::map<Label, std::int64_t> region_sizes(const LabelImage& labels) {
  std::map<Label, std::int64_t> sizes;
  for (const Label label : labels.pixels()) {
    if (label != kUnlabeled) ++sizes[label];
  }
  return sizes;
}

void score_synthetic(const PlaneFrame& frame, const PlaneOutput& output, PlaneScore& score) {
  score.segcomp = eval::compare_plane_segmentations(frame.truth, output.labels, {0.8},
                                                    frame.truth_normals, output.normals);
  for (const auto& [label, pixels] : region_sizes(frame.truth)) {
    if (pixels * 100 <= static_cast<std::int64_t>(frame.truth.size())) continue;
    ++score.large_truth;
    for (const auto& [truth, predicted] : score.segcomp.correct_pairs) {
      if (truth != label) continue;
      ++score.detected;
      const auto normal = output.normals.find(predicted);
      if (normal != output.normals.end()) {
        score.normal_errors_deg.push_back(angle_deg(frame.truth_normals.at(truth), normal->second));
      }
    }
  }
}

double best_table_iou(const PlaneFrame& frame, const PlaneOutput& output) {
  std::map<Label, std::int64_t> overlap, size;
  std::int64_t table = 0;
  for (std::size_t i = 0; i < output.labels.size(); ++i) {
    const bool on_table = frame.truth.data()[i] != kUnlabeled;
    table += on_table;
    const Label label = output.labels.data()[i];
    if (label == kUnlabeled) continue;
    ++size[label];
    overlap[label] += on_table;
  }
  double best = 0;
  for (const auto& [label, common] : overlap) {
    best = std::max(best, double(common) / double(table + size[label] - common));
  }
  return best;
}

// The median over a method's frames (of one data set, or all) of a per-frame value.
double median_over(const PlaneMethodOutcome& outcome,
                   const std::function<double(const PlaneFrameOutcome&)>& value,
                   std::optional<PlaneDataset> dataset = std::nullopt) {
  std::vector<double> values;
  for (const PlaneFrameOutcome& frame : outcome.frames) {
    if (!dataset || frame.frame->dataset == *dataset) values.push_back(value(frame));
  }
  return median(std::move(values));
}

bool has_frames(const PlaneMethodOutcome& outcome, PlaneDataset dataset) {
  return std::any_of(outcome.frames.begin(), outcome.frames.end(),
                     [dataset](const PlaneFrameOutcome& f) { return f.frame->dataset == dataset; });
}

// "normals 31.2 + segment 9.8": each part's median over frames; parts that took no time (a
// stage the backend does not run) are left out.
std::string parts_text(const PlaneMethodOutcome& outcome) {
  if (outcome.frames.empty()) return "-";
  std::string text;
  for (std::size_t p = 0; p < outcome.frames.front().parts_ms.size(); ++p) {
    const double ms = median_over(outcome, [p](const PlaneFrameOutcome& f) {
      return p < f.parts_ms.size() ? f.parts_ms[p].second : 0.0;
    });
    if (ms < 0.005) continue;
    text += (text.empty() ? "" : " + ") + outcome.frames.front().parts_ms[p].first + " " +
            fixed(ms, ms < 10 ? 2 : 1);
  }
  return text.empty() ? "-" : text;
}

struct SyntheticTotals {
  int large = 0, detected = 0;
  std::vector<double> normal_errors_deg;
  eval::SegCompResult segcomp;  // summed over frames
};

SyntheticTotals synthetic_totals(const PlaneMethodOutcome& outcome) {
  SyntheticTotals totals;
  for (const PlaneFrameOutcome& frame : outcome.frames) {
    if (frame.frame->dataset != PlaneDataset::synthetic) continue;
    const PlaneScore& s = frame.score;
    totals.large += s.large_truth;
    totals.detected += s.detected;
    totals.normal_errors_deg.insert(totals.normal_errors_deg.end(), s.normal_errors_deg.begin(),
                                    s.normal_errors_deg.end());
    totals.segcomp.ground_truth_regions += s.segcomp.ground_truth_regions;
    totals.segcomp.predicted_regions += s.segcomp.predicted_regions;
    totals.segcomp.correct += s.segcomp.correct;
    totals.segcomp.over_segmented += s.segcomp.over_segmented;
    totals.segcomp.under_segmented += s.segcomp.under_segmented;
    totals.segcomp.missed += s.segcomp.missed;
    totals.segcomp.noise += s.segcomp.noise;
  }
  return totals;
}

std::string table_iou_text(const PlaneMethodOutcome& outcome) {
  std::vector<double> ious;
  for (const PlaneFrameOutcome& frame : outcome.frames) {
    if (frame.score.table_iou) ious.push_back(*frame.score.table_iou);
  }
  if (ious.empty()) return "-";
  double sum = 0;
  for (const double iou : ious) sum += iou;
  return fixed(sum / double(ious.size()), 3) + " (" +
         fixed(*std::min_element(ious.begin(), ious.end()), 3) + ")";
}

const PlaneMethodOutcome* kartograf_reference(const std::vector<PlaneMethodOutcome>& outcomes) {
  for (const PlaneMethodOutcome& outcome : outcomes) {
    if (outcome.method->name == kKartografPlanes) return &outcome;
  }
  return nullptr;
}

// "28 of 28": frames (in the same order for every method) whose labels hash alike.
std::string identical_labels_text(const PlaneMethodOutcome& outcome,
                                  const PlaneMethodOutcome& reference) {
  int same = 0;
  for (std::size_t f = 0; f < outcome.frames.size() && f < reference.frames.size(); ++f) {
    same += outcome.frames[f].labels_hash == reference.frames[f].labels_hash;
  }
  return std::to_string(same) + " of " + std::to_string(outcome.frames.size());
}

double wall(const PlaneFrameOutcome& f) {
  return f.seconds;
}
double cpu(const PlaneFrameOutcome& f) {
  return f.cpu_seconds;
}
double plane_count(const PlaneFrameOutcome& f) {
  return f.score.planes;
}

}  // namespace

PlaneScore score_planes(const PlaneFrame& frame, const PlaneOutput& output) {
  PlaneScore score;
  const std::map<Label, std::int64_t> sizes = region_sizes(output.labels);
  const auto large = [&](Label label) {
    return sizes.at(label) * 100 > static_cast<std::int64_t>(output.labels.size());
  };
  std::int64_t valid = 0, covered = 0, covered_large = 0;
  for (std::size_t i = 0; i < output.labels.size(); ++i) {
    if (!is_valid(frame.points.data()[i])) continue;
    ++valid;
    const Label label = output.labels.data()[i];
    covered += label != kUnlabeled;
    covered_large += label != kUnlabeled && large(label);
  }
  score.planes = static_cast<int>(sizes.size());
  score.coverage = valid > 0 ? double(covered) / double(valid) : 0;
  score.large_coverage = valid > 0 ? double(covered_large) / double(valid) : 0;
  if (frame.dataset == PlaneDataset::synthetic) score_synthetic(frame, output, score);
  if (frame.dataset == PlaneDataset::mosd) score.table_iou = best_table_iou(frame, output);
  return score;
}

std::uint64_t labels_hash(const LabelImage& labels) {
  std::uint64_t hash = 14695981039346656037ull;
  for (const Label label : labels.pixels()) {
    hash = (hash ^ label) * 1099511628211ull;
  }
  return hash;
}

void print_plane_table(std::ostream& out, const std::vector<PlaneMethodOutcome>& outcomes) {
  const PlaneMethodOutcome* reference = kartograf_reference(outcomes);
  const double reference_wall = reference ? median_over(*reference, wall) : 0;
  const double reference_cpu = reference ? median_over(*reference, cpu) : 0;
  out << "| method | threads | wall ms | CPU ms | frames/s | ratio to Kartograf (cpu) (wall / "
         "CPU) | parts of the wall time (ms) | synthetic: planes > 1 % correctly detected | "
         "synthetic: median normal error (deg) | mOSD: table IoU mean (min) | 7-Scenes: planes "
         "per frame | 7-Scenes: valid pixels in a plane | 7-Scenes: ... in a plane > 1 % |\n"
         "|---|---|---:|---:|---:|---:|---|---:|---:|---:|---:|---:|---:|\n";
  for (const PlaneMethodOutcome& outcome : outcomes) {
    const double wall_s = median_over(outcome, wall);
    const double cpu_s = median_over(outcome, cpu);
    const SyntheticTotals synthetic = synthetic_totals(outcome);
    const bool seven_scenes = has_frames(outcome, PlaneDataset::seven_scenes);
    out << "| " << outcome.method->name << " | " << outcome.method->threads << " | "
        << fixed(1000 * wall_s, 1) << " | " << fixed(1000 * cpu_s, 1) << " | "
        << fixed(1 / wall_s, 1) << " | "
        << (outcome.method->name == kKartografPlanes
                ? std::string("-")
                : ratio(wall_s, reference_wall) + " / " + ratio(cpu_s, reference_cpu))
        << " | " << parts_text(outcome) << " | ";
    if (synthetic.large > 0) {
      out << synthetic.detected << " of " << synthetic.large << " ("
          << fixed(100.0 * synthetic.detected / synthetic.large, 1) << " %) | "
          << (synthetic.normal_errors_deg.empty() ? std::string("-")
                                                  : fixed(median(synthetic.normal_errors_deg), 2))
          << " | ";
    } else {
      out << "- | - | ";
    }
    out << table_iou_text(outcome) << " | ";
    if (seven_scenes) {
      const auto share = [&](double PlaneScore::*field) {
        return fixed(
            100 * median_over(
                      outcome, [field](const PlaneFrameOutcome& f) { return f.score.*field; },
                      PlaneDataset::seven_scenes),
            1);
      };
      out << fixed(median_over(outcome, plane_count, PlaneDataset::seven_scenes), 1) << " | "
          << share(&PlaneScore::coverage) << " % | " << share(&PlaneScore::large_coverage)
          << " % |\n";
    } else {
      out << "- | - | - |\n";
    }
  }
}

void print_plane_dataset_table(std::ostream& out, const std::vector<PlaneMethodOutcome>& outcomes) {
  out << "| method |";
  for (const PlaneDataset dataset : kPlaneDatasets)
    out << " " << to_string(dataset) << ": wall ms |";
  for (const PlaneDataset dataset : kPlaneDatasets)
    out << " " << to_string(dataset) << ": planes/frame |";
  out << " synthetic SegComp T = 0.8, all ground-truth planes: correct / over / under / missed / "
         "noise | frames with labels identical to Kartograf (cpu) |\n|---|";
  for (std::size_t i = 0; i < 2 * std::size(kPlaneDatasets); ++i) out << "---:|";
  out << "---|---:|\n";
  const PlaneMethodOutcome* reference = kartograf_reference(outcomes);
  for (const PlaneMethodOutcome& outcome : outcomes) {
    out << "| " << outcome.method->name << " |";
    for (const PlaneDataset dataset : kPlaneDatasets) {
      out << " "
          << (has_frames(outcome, dataset) ? fixed(1000 * median_over(outcome, wall, dataset), 1)
                                           : "-")
          << " |";
    }
    for (const PlaneDataset dataset : kPlaneDatasets) {
      out << " "
          << (has_frames(outcome, dataset) ? fixed(median_over(outcome, plane_count, dataset), 1)
                                           : "-")
          << " |";
    }
    const eval::SegCompResult s = synthetic_totals(outcome).segcomp;
    out << " " << s.correct << " / " << s.over_segmented << " / " << s.under_segmented << " / "
        << s.missed << " / " << s.noise << " | "
        << (reference && outcome.method->library == "kartograf"
                ? identical_labels_text(outcome, *reference)
                : std::string("-"))
        << " |\n";
  }
}

void print_kartograf_stage_line(std::ostream& out,
                                const std::vector<PlaneMethodOutcome>& outcomes) {
  const PlaneMethodOutcome* reference = kartograf_reference(outcomes);
  if (!reference) return;
  const double stages_s = median_over(*reference, [](const PlaneFrameOutcome& f) {
    double ms = 0;
    for (const auto& [name, part_ms] : f.parts_ms) {
      if (name == "lab" || name == "growing" || name == "moments" || name == "merging") {
        ms += part_ms;
      }
    }
    return ms / 1000;
  });
  const double whole_s = median_over(*reference, wall);
  out << "\nKartograf (cpu), segmentation + fit + merge (lab + growing with the moments + merging, "
         "per frame the sum of the stage medians; PlaneExtractionTimings): median "
      << fixed(1000 * stages_s, 1) << " ms = " << fixed(1 / stages_s, 0)
      << " frames/s; the whole extract() with pixel refinement and output: "
      << fixed(1000 * whole_s, 1) << " ms = " << fixed(1 / whole_s, 0) << " frames/s.\n";
}

void print_plane_details(std::ostream& out, const std::vector<PlaneMethodOutcome>& outcomes) {
  for (const PlaneMethodOutcome& outcome : outcomes) {
    for (const PlaneFrameOutcome& frame : outcome.frames) {
      const PlaneScore& s = frame.score;
      out << outcome.method->name << " | " << frame.frame->name << " | "
          << fixed(1000 * frame.seconds, 1) << " ms | " << s.planes << " planes, "
          << fixed(100 * s.coverage, 1) << " % of valid pixels";
      if (s.large_truth > 0) out << " | " << s.detected << " of " << s.large_truth << " detected";
      if (s.table_iou) out << " | table IoU " << fixed(*s.table_iou, 4);
      out << "\n";
    }
  }
}

}  // namespace kartograf::peer
