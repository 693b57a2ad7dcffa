#pragma once
// Results of the peer benchmark and the Markdown tables it prints (pasted into docs/benchmarks.md).
#include <cstddef>
#include <iosfwd>
#include <string>
#include <vector>

#include "peer_methods.hpp"

namespace kartograf::peer {

// One method on one pair: the median wall-clock and process CPU time of its timed calls, and the
// error of its estimate against the ground truth, E = truth^-1 * estimate. CPU time (all threads
// of the process) shows what a call costs when other work shares the cores; wall time is what a
// caller waits.
struct PairOutcome {
  const FramePair* pair = nullptr;
  double seconds = 0;
  double cpu_seconds = 0;
  int calls = 0;
  Estimate estimate;
  double rotation_error_deg = 0;
  double translation_error_mm = 0;
};
PairOutcome score(const FramePair& pair, const Estimate& estimate, std::vector<double> seconds,
                  std::vector<double> cpu_seconds);

struct MethodOutcome {
  const Method* method = nullptr;
  std::vector<PairOutcome> pairs;
  double median_seconds() const;      // over pairs (each pair's median)
  double median_cpu_seconds() const;  // likewise
};

double median(std::vector<double> values);
// value with `digits` decimals; "a / b" as "1.23x" (no decimals from 10x on), "-" when b <= 0.
std::string fixed(double value, int digits);
std::string ratio(double numerator, double denominator);

// Per method: median wall and CPU time, frames/s, the ratios (this time / the compared Kartograf
// method's, and / Kartograf odometry's; wall and CPU), and the median rotation and translation
// errors per frame gap, and the worst; for one dataset's pairs.
void print_pair_table(std::ostream& out, const std::vector<MethodOutcome>& outcomes);
// Every pair's errors and wall time, one line per method and pair (for looking into outliers).
void print_pair_details(std::ostream& out, const std::vector<MethodOutcome>& outcomes);

// A chained trajectory: frame k aligned to k - 1 from the identity, poses composed from the
// ground truth of frame 0.
struct ChainOutcome {
  std::string dataset;
  std::string method;
  std::string threads;
  std::size_t frames = 0;
  double median_ms = 0;  // per tracked frame
  double ate_rmse_m = 0;
  double rpe_translation_rmse_mm = 0;  // 1 frame apart
  double rpe_rotation_rmse_deg = 0;
  std::size_t failures = 0;  // frames the method reported as failed (identity used)
};
void print_chain_table(std::ostream& out, const std::vector<ChainOutcome>& outcomes);

}  // namespace kartograf::peer
