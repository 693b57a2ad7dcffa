#pragma once
// Pair rejection by colour (docs/methods.md M3 step 3): compare the hue and saturation (hsi.hpp) of
// the two points of every correspondence, and reject the pairs whose difference exceeds the mean
// difference over all pairs. Illumination-robust: intensity is ignored.
//
// Rules, identical on every backend. A pair is source i with j = target_index[i] in
// [0, target count); its colours are source_colors[i] and target_colors[j] (packed RGB, the top
// byte is ignored), looked up in the 2-byte table of hsi.hpp. Per pair:
//   dS = |s_i - s_j| (saturation codes, 0..255)                      over all pairs;
//   dH = circular |h_i - h_j| (hue codes, 0..127, 1.41 deg each)     over pairs where both have a
//        hue (grey has none: such a pair is judged on saturation alone).
// mean_S = sum dS / pairs, mean_H = sum dH / hue pairs. A pair is rejected (target_index[i] =
// kNoMatch) when dS > mean_factor * mean_S or dH > mean_factor * mean_H; the paper's rule is
// mean_factor = 1. Entries that are not pairs are left as they are.
//
// Exactness: differences are integers and the sums are sums of integers (exact in double), and the
// test dS * pairs > mean_factor * sum dS is one rounding (none for mean_factor = 1), so every
// backend makes the same decision for every pair. Against unquantised H and S the decisions differ
// only for pairs within the table's quantisation (0.7 deg, 0.002) of the threshold.
//
// Passes, on every backend (rule and kernels: kernels/color_gate/): a pass writes per-pair
// differences and per-work-group partial sums, reduce_rows adds the partials (two passes, no
// atomics: as icp_sums.hpp), a third pass applies the gate. The table
// (32 MiB) is uploaded once per ColorGate. Nothing is read back unless statistics() is called.
#include <cstdint>
#include <memory>

#include "kartograf/compute/buffer.hpp"
#include "kartograf/registration/correspondence_finder.hpp"
#include "kartograf/registration/hsi.hpp"

namespace kartograf::registration {

struct ColorGateParams {
  double mean_factor = 1.0;  // reject above mean_factor x the mean difference (paper: 1)
  bool use_hue = true;
  bool use_saturation = true;
};

struct ColorGateStatistics {
  std::uint64_t pair_count = 0;      // pairs looked at
  std::uint64_t hue_pair_count = 0;  // of those, pairs where both colours have a hue
  double mean_hue_difference_deg = 0;
  double mean_saturation_difference = 0;  // in saturation units (0..1)
  std::uint64_t rejected_count = 0;
};

// Holds the device table and scratch buffers: steady-state calls allocate nothing.
class ColorGate {
 public:
  // Throws Error for mean_factor not finite and > 0.
  ColorGate(const compute::Context& context, ColorGateParams params = {});

  // Gates the pairs of target_index in place. source_colors has one entry per source point (else
  // Error), target_colors one per target point (an index beyond it is not a pair).
  void apply(const compute::Buffer<std::uint32_t>& source_colors,
             const compute::Buffer<std::uint32_t>& target_colors,
             compute::Buffer<std::int32_t>& target_index);

  // Of the last apply() (waits for it on a device).
  ColorGateStatistics statistics() const;
  const ColorGateParams& params() const { return params_; }

 private:
  const compute::Context* context_;
  ColorGateParams params_;
  compute::Buffer<HsiCode> table_;              // hsi_table(), uploaded on first use
  compute::Buffer<std::uint32_t> differences_;  // per source point: flags | dH << 8 | dS << 16
  compute::Buffer<double> partials_;
  compute::Buffer<double> sums_;  // pairs, sum dS, hue pairs, sum dH
  compute::Buffer<std::uint32_t> rejected_;
};

// A finder that gates another finder's pairs by colour. Both clouds need colours.
class ColorGatedFinder : public CorrespondenceFinder {
 public:
  ColorGatedFinder(const compute::Context& context, std::unique_ptr<CorrespondenceFinder> inner,
                   ColorGateParams params = {});

  void prepare(const CloudView& target, int level) override;
  void find(const CloudView& source, const CloudView& target,
            const Eigen::Isometry3d& source_to_target, const AssociationParams& params,
            CorrespondenceBuffers& out) override;

  const ColorGate& gate() const { return gate_; }

 private:
  std::unique_ptr<CorrespondenceFinder> inner_;
  ColorGate gate_;
};

}  // namespace kartograf::registration
