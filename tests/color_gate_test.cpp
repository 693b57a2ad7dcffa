// The HSI table and the colour gate (docs/methods.md M3 step 3) on every backend.
// Stated tolerances: the table agrees with an independent formula (H = atan2(sqrt(3)(G-B),
// 2R-G-B)) within its quantisation (|dH| <= 180/255 deg, |dS| <= 0.5/255) for all 2^24 colours;
// gate decisions equal the quantised all-integer reference exactly (0 mismatches) on every
// backend; against unquantised double H and S they differ only for pairs whose difference lies
// within the quantisation (2 x 0.706 deg, 2 x 0.5/255) of the mean.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>
#include <string>
#include <thread>

#include "kartograf/registration/color_gate.hpp"
#include "kartograf/registration/frame_pyramid.hpp"
#include "kartograf/registration/hsi.hpp"
#include "real_data.hpp"
#include "test_support.hpp"

namespace kartograf {
namespace {

using registration::ColorGate;
using registration::ColorGateParams;
using registration::HsiCode;
using registration::kNoMatch;
using registration::kNotSelected;
using testing::BackendTest;

constexpr double kHueBin = 360.0 / 255.0;

// An independent form of eq. 1-2: the hue as an angle in the chromaticity plane.
struct ExactHs {
  bool has_hue;
  double hue_deg, saturation;
};
ExactHs exact_hs(std::uint32_t packed) {
  const double r = packed & 0xff, g = (packed >> 8) & 0xff, b = (packed >> 16) & 0xff;
  const double sum = r + g + b;
  ExactHs out{!(r == g && g == b), 0.0, sum > 0 ? (sum - 3.0 * std::min({r, g, b})) / sum : 0.0};
  if (out.has_hue) {
    out.hue_deg = std::atan2(std::sqrt(3.0) * (g - b), 2 * r - g - b) * 180.0 / std::numbers::pi;
    if (out.hue_deg < 0) out.hue_deg += 360.0;
  }
  return out;
}

double circular_deg(double a, double b) {
  const double d = std::fabs(a - b);
  return std::min(d, 360.0 - d);
}

std::uint32_t pack(int r, int g, int b) {
  return pack_rgb(
      {static_cast<std::uint8_t>(r), static_cast<std::uint8_t>(g), static_cast<std::uint8_t>(b)});
}

TEST(HsiTable, MatchesAnIndependentFormulaWithinItsQuantisation) {
  const std::span<const HsiCode> table = registration::hsi_table();
  ASSERT_EQ(table.size(), std::size_t{1} << 24);
  double worst_hue = 0, worst_saturation = 0;
  std::size_t grey_mismatches = 0;
  for (std::uint32_t packed = 0; packed < table.size(); ++packed) {
    const ExactHs exact = exact_hs(packed);
    const HsiCode code = table[packed];
    grey_mismatches += exact.has_hue == (registration::hue_code(code) == registration::kNoHue);
    worst_saturation = std::max(worst_saturation,
                                std::fabs(registration::saturation_value(code) - exact.saturation));
    if (exact.has_hue) {
      worst_hue = std::max(worst_hue, circular_deg(registration::hue_degrees(code), exact.hue_deg));
    }
  }
  EXPECT_EQ(grey_mismatches, 0u);
  EXPECT_LE(worst_hue, kHueBin / 2 + 1e-9);
  EXPECT_LE(worst_saturation, 0.5 / 255 + 1e-12);
  RecordProperty("max_hue_error_deg", testing::scientific(worst_hue));
  RecordProperty("max_saturation_error", testing::scientific(worst_saturation));
}

TEST(HsiTable, KnownColoursAndOneSharedTable) {
  const auto code = [](int r, int g, int b) {
    return registration::quantize(registration::hue_saturation(r, g, b));
  };
  EXPECT_EQ(code(255, 0, 0), 0 | 255 << 8);              // red: H 0, S 1
  EXPECT_EQ(code(0, 200, 0), 85 | 255 << 8);             // green: H 120 deg = code 85
  EXPECT_EQ(code(0, 0, 90), 170 | 255 << 8);             // blue: H 240 deg = code 170
  EXPECT_EQ(code(128, 128, 128), registration::kNoHue);  // grey: no hue, S 0
  EXPECT_EQ(code(0, 0, 0), registration::kNoHue);
  EXPECT_NEAR(registration::hue_saturation(255, 0, 255).hue_deg, 300.0, 1e-9);  // magenta
  EXPECT_NEAR(registration::hue_saturation(200, 100, 100).saturation, 0.25, 1e-12);
  // The table is built once, whichever thread asks first.
  const HsiCode* seen[2] = {};
  std::thread other([&] { seen[1] = registration::hsi_table().data(); });
  seen[0] = registration::hsi_table().data();
  other.join();
  EXPECT_EQ(seen[0], seen[1]);
  EXPECT_EQ(registration::hsi_lookup(registration::hsi_table(), 0xff000000u | pack(0, 200, 0)),
            code(0, 200, 0));  // the top byte is ignored
}

struct GateCase {
  std::vector<std::uint32_t> source_colors, target_colors;
  std::vector<std::int32_t> index;
  std::vector<bool> planted_wrong;
};

// The rule of color_gate.hpp, in integers.
struct GateReference {
  std::vector<std::int32_t> index;
  registration::ColorGateStatistics statistics;
};
GateReference reference_gate(const GateCase& c) {
  const auto table = registration::hsi_table();
  struct Pair {
    std::size_t i;
    std::uint64_t ds, dh;
    bool hue;
  };
  std::vector<Pair> pairs;
  std::uint64_t sum_s = 0, sum_h = 0, hue_pairs = 0;
  for (std::size_t i = 0; i < c.index.size(); ++i) {
    const std::int32_t j = c.index[i];
    if (j < 0 || static_cast<std::size_t>(j) >= c.target_colors.size()) continue;
    const HsiCode a = table[c.source_colors[i] & 0xffffff],
                  b = table[c.target_colors[j] & 0xffffff];
    const int sa = a >> 8, sb = b >> 8, ha = a & 0xff, hb = b & 0xff;
    Pair pair{i, static_cast<std::uint64_t>(std::abs(sa - sb)), 0, ha != 255 && hb != 255};
    if (pair.hue) {
      const int d = std::abs(ha - hb);
      pair.dh = static_cast<std::uint64_t>(std::min(d, 255 - d));
      sum_h += pair.dh;
      ++hue_pairs;
    }
    sum_s += pair.ds;
    pairs.push_back(pair);
  }
  GateReference out{c.index, {}};
  out.statistics.pair_count = pairs.size();
  out.statistics.hue_pair_count = hue_pairs;
  for (const Pair& pair : pairs) {
    if (pair.ds * pairs.size() > sum_s || (pair.hue && pair.dh * hue_pairs > sum_h)) {
      out.index[pair.i] = kNoMatch;
      ++out.statistics.rejected_count;
    }
  }
  if (!pairs.empty())
    out.statistics.mean_saturation_difference = double(sum_s) / pairs.size() / 255;
  if (hue_pairs > 0) out.statistics.mean_hue_difference_deg = double(sum_h) / hue_pairs * kHueBin;
  return out;
}

// Decisions from unquantised H and S; returns the mismatches with `gated` that are NOT within
// the quantisation of the mean (there should be none) and counts all mismatches.
std::size_t unexplained_mismatches(const GateCase& c, const std::vector<std::int32_t>& gated,
                                   std::size_t& mismatches) {
  struct Pair {
    std::size_t i;
    double ds, dh;
    bool hue;
  };
  std::vector<Pair> pairs;
  double sum_s = 0, sum_h = 0;
  std::size_t hue_pairs = 0;
  for (std::size_t i = 0; i < c.index.size(); ++i) {
    const std::int32_t j = c.index[i];
    if (j < 0 || static_cast<std::size_t>(j) >= c.target_colors.size()) continue;
    const ExactHs a = exact_hs(c.source_colors[i]), b = exact_hs(c.target_colors[j]);
    Pair pair{i, std::fabs(a.saturation - b.saturation), 0, a.has_hue && b.has_hue};
    if (pair.hue) {
      pair.dh = circular_deg(a.hue_deg, b.hue_deg);
      sum_h += pair.dh;
      ++hue_pairs;
    }
    sum_s += pair.ds;
    pairs.push_back(pair);
  }
  const double mean_s = sum_s / pairs.size(), mean_h = hue_pairs ? sum_h / hue_pairs : 0;
  const double slack_s = 2 * 0.5 / 255 + 1e-12, slack_h = 2 * kHueBin / 2 + 1e-9;
  std::size_t unexplained = 0;
  mismatches = 0;
  for (const Pair& pair : pairs) {
    const bool reject = pair.ds > mean_s || (pair.hue && pair.dh > mean_h);
    if (reject == (gated[pair.i] == kNoMatch)) continue;
    ++mismatches;
    const bool near_s = std::fabs(pair.ds - mean_s) <= 2 * slack_s;
    const bool near_h = pair.hue && std::fabs(pair.dh - mean_h) <= 2 * slack_h;
    unexplained += !(near_s || near_h);
  }
  return unexplained;
}

std::vector<std::int32_t> run_gate(const compute::Context& context, const GateCase& c,
                                   registration::ColorGateStatistics* statistics = nullptr,
                                   ColorGateParams params = {}) {
  ColorGate gate(context, params);
  const auto source = compute::Buffer<std::uint32_t>::from_host(context, c.source_colors);
  const auto target = compute::Buffer<std::uint32_t>::from_host(context, c.target_colors);
  auto index = compute::Buffer<std::int32_t>::from_host(context, c.index);
  gate.apply(source, target, index);
  if (statistics) *statistics = gate.statistics();
  return index.to_vector();
}

// Saturated colours seen under other illumination (right pairs), 20% planted pairs whose hues
// are >= 90 deg apart, some grey pairs and entries that are not pairs.
GateCase illumination_case(std::mt19937_64& rng, std::size_t count) {
  std::uniform_int_distribution<int> channel(0, 255);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const auto saturated = [&] {
    for (;;) {
      const int r = channel(rng), g = channel(rng), b = channel(rng);
      const ExactHs hs = exact_hs(pack(r, g, b));
      if (hs.saturation > 0.35 && r + g + b > 240) return pack(r, g, b);
    }
  };
  GateCase c;
  c.target_colors.resize(count + 10);
  std::vector<std::int32_t> permutation(count);
  std::iota(permutation.begin(), permutation.end(), 0);
  std::shuffle(permutation.begin(), permutation.end(), rng);
  for (std::size_t i = 0; i < count; ++i) {
    const std::uint32_t colour = saturated();
    std::uint32_t partner = colour;
    const double kind = unit(rng);
    bool wrong = false;
    if (kind < 0.2) {
      do partner = saturated();
      while (circular_deg(exact_hs(partner).hue_deg, exact_hs(colour).hue_deg) < 90);
      wrong = true;
    } else if (kind < 0.25) {
      partner = pack(100, 100, 100);  // grey: judged by saturation alone
    } else {
      const double brightness = 0.6 + 0.4 * unit(rng);
      const auto dim = [&](std::uint32_t v) {
        return static_cast<int>(std::lround(v * brightness));
      };
      partner = pack(dim(colour & 0xff), dim((colour >> 8) & 0xff), dim((colour >> 16) & 0xff));
    }
    c.source_colors.push_back(colour);
    c.target_colors[permutation[i]] = partner;
    c.index.push_back(permutation[i]);
    c.planted_wrong.push_back(wrong);
    if (i % 97 == 3) c.index.back() = kNoMatch;
    if (i % 89 == 5) c.index.back() = kNotSelected;
    if (i % 83 == 7) c.index.back() = static_cast<std::int32_t>(count + 10);  // beyond the target
  }
  return c;
}

class ColorGateTest : public BackendTest {};

TEST_P(ColorGateTest, RejectsRedMatchedToGreen) {
  GateCase c;
  for (int i = 0; i < 200; ++i) {
    const bool wrong = i % 20 == 7;
    c.source_colors.push_back(pack(200, 30, 30));
    c.target_colors.push_back(wrong ? pack(30, 200, 30) : pack(200, 30, 30));
    c.index.push_back(i);
  }
  const auto gated = run_gate(context(), c);
  for (int i = 0; i < 200; ++i) EXPECT_EQ(gated[i], i % 20 == 7 ? kNoMatch : i) << i;
}

TEST_P(ColorGateTest, MatchesTheIntegerReferenceExactlyUnderIlluminationChange) {
  const GateCase c = illumination_case(rng, 20000);
  const GateReference expected = reference_gate(c);
  registration::ColorGateStatistics statistics;
  const auto gated = run_gate(context(), c, &statistics);
  ASSERT_EQ(gated, expected.index);
  EXPECT_EQ(statistics.pair_count, expected.statistics.pair_count);
  EXPECT_EQ(statistics.hue_pair_count, expected.statistics.hue_pair_count);
  EXPECT_EQ(statistics.rejected_count, expected.statistics.rejected_count);
  EXPECT_DOUBLE_EQ(statistics.mean_hue_difference_deg, expected.statistics.mean_hue_difference_deg);
  EXPECT_DOUBLE_EQ(statistics.mean_saturation_difference,
                   expected.statistics.mean_saturation_difference);

  std::size_t wrong = 0, wrong_kept = 0, right = 0, right_kept = 0;
  for (std::size_t i = 0; i < c.index.size(); ++i) {
    if (c.index[i] < 0 || c.index[i] >= static_cast<std::int32_t>(c.target_colors.size())) {
      EXPECT_EQ(gated[i], c.index[i]) << "not a pair: left as it is";
      continue;
    }
    (c.planted_wrong[i] ? wrong : right) += 1;
    (c.planted_wrong[i] ? wrong_kept : right_kept) += gated[i] >= 0;
  }
  EXPECT_EQ(wrong_kept, 0u) << "of " << wrong << " planted wrong pairs";
  // The paper's rule also drops right pairs whose small difference exceeds the (small) mean.
  EXPECT_GE(right_kept, right * 90 / 100) << "of " << right << " right pairs";

  std::size_t mismatches = 0;
  EXPECT_EQ(unexplained_mismatches(c, gated, mismatches), 0u);
  RecordProperty("mismatches_vs_unquantised",
                 std::to_string(mismatches) + " of " + std::to_string(statistics.pair_count));
  RecordProperty("right_pairs_kept", std::to_string(right_kept) + " of " + std::to_string(right));
}

TEST_P(ColorGateTest, MatchesTheReferenceOnSevenScenesColours) {
  // Pixel (u, v) paired with its right neighbour (mostly alike), every 7th with a far pixel.
  const RgbImage image = testing::read_color(testing::data_dir() / "7scenes_redkitchen" / "frames" /
                                             "frame-000100.color.jpg");
  GateCase c;
  for (const Rgb8& pixel : image.pixels()) c.target_colors.push_back(pack_rgb(pixel));
  const auto count = static_cast<std::int32_t>(c.target_colors.size());
  for (std::int32_t i = 0; i < count; ++i) {
    c.source_colors.push_back(c.target_colors[i]);
    // 64-bit: i * 7919 overflows an int32 beyond i = 271,000 (UBSan).
    const auto far = static_cast<std::int32_t>((std::int64_t{i} * 7919 + 100000) % count);
    c.index.push_back(i % 7 == 3 ? far : std::min(i + 1, count - 1));
  }
  const GateReference expected = reference_gate(c);
  registration::ColorGateStatistics statistics;
  const auto gated = run_gate(context(), c, &statistics);
  ASSERT_EQ(gated, expected.index);
  std::size_t mismatches = 0;
  EXPECT_EQ(unexplained_mismatches(c, gated, mismatches), 0u);
  RecordProperty("rejected", std::to_string(statistics.rejected_count) + " of " +
                                 std::to_string(statistics.pair_count));
  RecordProperty("mismatches_vs_unquantised", std::to_string(mismatches));
}

TEST_P(ColorGateTest, MeanFactorAndSaturationOnly) {
  const GateCase c = illumination_case(rng, 3000);
  ColorGateParams params;
  params.mean_factor = 1.5;
  params.use_hue = false;
  const auto gated = run_gate(context(), c, nullptr, params);
  // The reference with the same rule: dS * pairs > 1.5 * sum dS, no hue test.
  const auto table = registration::hsi_table();
  const auto ds = [&](std::size_t i) {
    return std::abs(int(table[c.source_colors[i]] >> 8) -
                    int(table[c.target_colors[c.index[i]]] >> 8));
  };
  const auto is_pair = [&](std::size_t i) {
    return c.index[i] >= 0 && c.index[i] < static_cast<std::int32_t>(c.target_colors.size());
  };
  std::uint64_t pairs = 0, sum = 0;
  for (std::size_t i = 0; i < c.index.size(); ++i) {
    if (!is_pair(i)) continue;
    ++pairs;
    sum += static_cast<std::uint64_t>(ds(i));
  }
  std::size_t rejected = 0;
  for (std::size_t i = 0; i < c.index.size(); ++i) {
    if (!is_pair(i)) continue;
    const bool expected = double(ds(i)) * double(pairs) > 1.5 * double(sum);
    EXPECT_EQ(gated[i] == kNoMatch, expected) << i;
    rejected += expected;
  }
  EXPECT_GT(rejected, 0u);
}

TEST_P(ColorGateTest, RejectsBadInputs) {
  EXPECT_THROW(ColorGate(context(), ColorGateParams{0.0, true, true}), Error);
  EXPECT_THROW(ColorGate(context(), ColorGateParams{std::nan(""), true, true}), Error);
  ColorGate gate(context());
  const auto colors =
      compute::Buffer<std::uint32_t>::from_host(context(), std::vector<std::uint32_t>(10, 0));
  auto index =
      compute::Buffer<std::int32_t>::from_host(context(), std::vector<std::int32_t>(11, 0));
  EXPECT_THROW(gate.apply(colors, colors, index), Error);
  // No pairs at all: nothing changes, statistics are zero.
  auto none =
      compute::Buffer<std::int32_t>::from_host(context(), std::vector<std::int32_t>(10, kNoMatch));
  gate.apply(colors, colors, none);
  EXPECT_EQ(none.to_vector(), std::vector<std::int32_t>(10, kNoMatch));
  EXPECT_EQ(gate.statistics().pair_count, 0u);
}

KARTOGRAF_INSTANTIATE_BACKEND_TESTS(ColorGateTest);

}  // namespace
}  // namespace kartograf
