#pragma once
// Scores of the plane part of the peer benchmark and the Markdown tables it prints (pasted into
// docs/benchmarks.md). Every method's output is scored from its label image and plane normals
// only, so the libraries are judged by the same rules.
#include <cstdint>
#include <iosfwd>
#include <optional>
#include <vector>

#include "kartograf/eval/plane_metrics.hpp"
#include "plane_methods.hpp"

namespace kartograf::peer {

// One method's planes on one frame.
struct PlaneScore {
  int planes = 0;             // planes with at least one pixel
  double coverage = 0;        // fraction of the valid pixels in a plane
  double large_coverage = 0;  // ... in a plane over 1 % of the image
  // synthetic frames: ground-truth planes over 1 % of the image (the test's rule) and those of
  // them correctly detected (SegComp, overlap >= 80 % both ways), with each one's normal error
  // (sign-free angle); the SegComp counts over every ground-truth plane.
  int large_truth = 0;
  int detected = 0;
  std::vector<double> normal_errors_deg;
  eval::SegCompResult segcomp;
  // mOSD frames: the best plane's intersection over union with the table.
  std::optional<double> table_iou;
};
PlaneScore score_planes(const PlaneFrame& frame, const PlaneOutput& output);
// FNV-1a over the label image: whether two backends gave the same labels, without keeping them.
std::uint64_t labels_hash(const LabelImage& labels);

struct PlaneFrameOutcome {
  const PlaneFrame* frame = nullptr;
  double seconds = 0;      // median wall time of the frame's calls
  double cpu_seconds = 0;  // median process CPU time
  TimeParts parts_ms;      // each part's median over the calls
  PlaneScore score;
  std::uint64_t labels_hash = 0;
};

struct PlaneMethodOutcome {
  const PlaneMethod* method = nullptr;
  std::vector<PlaneFrameOutcome> frames;
};

// Per method: median wall and CPU time per frame over all frames, frames/s, the ratios to
// Kartograf's CPU row, the parts of the time, and the quality columns.
void print_plane_table(std::ostream& out, const std::vector<PlaneMethodOutcome>& outcomes);
// Per method and data set: median wall time, planes per frame, and the synthetic SegComp counts;
// for Kartograf's device rows, on how many frames their labels equal the CPU backend's.
void print_plane_dataset_table(std::ostream& out, const std::vector<PlaneMethodOutcome>& outcomes);
// The speed acceptance line of issue 5: Kartograf's CPU time for segmentation + fit + merge (the
// stages lab, growing, moments and merging; without the pixel refinement and the output), beside
// the whole extract().
void print_kartograf_stage_line(std::ostream& out, const std::vector<PlaneMethodOutcome>& outcomes);
// Every frame's time, plane count and scores, one line per method and frame.
void print_plane_details(std::ostream& out, const std::vector<PlaneMethodOutcome>& outcomes);

}  // namespace kartograf::peer
