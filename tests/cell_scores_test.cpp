// The cells mode's pixel scores (kernels/cell_scores), which the device backends use for the
// pixels the assignment scores, on every backend against the CPU backend's run of the same rule
// and against plane_score's rule in double.
// Stated tolerance: the choices and squared distances equal the CPU's bit for bit (the rule has no
// fused multiply-add); the choices equal the double rule's except at near ties (the best two
// scores, or the best score and 1, within 1e-4 of each other, relatively).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "kartograf/compute/buffer.hpp"
#include "kartograf/compute/kernel.hpp"
#include "kernels/cell_scores/cell_scores.h"
#include "test_support.hpp"

namespace kartograf {
namespace {

using testing::BackendTest;

constexpr int kWidth = 48, kHeight = 36, kJobSide = 8;
constexpr float kFocal = 40;
constexpr kernels::CellScoresParams kParams{kWidth, 0, 0.01f, 0.004f, 0.5f};

// Planes facing the camera at 1.5 to 3.5 m, each point on the plane of its 12-pixel column band
// with noise of about the allowance; a tenth of the pixels without a point.
struct ScoreScene {
  std::vector<Eigen::Vector4f> planes;  // n, offset
  std::vector<Eigen::Vector4f> points;
  std::vector<std::uint32_t> jobs, candidates;
  std::size_t pixels = 0;
};

ScoreScene make_scene(std::mt19937& rng) {
  std::uniform_real_distribution<float> tilt(-0.5f, 0.5f), depth(1.5f, 3.5f), unit(0, 1);
  std::normal_distribution<float> noise(0.0f, 0.01f);
  ScoreScene s;
  for (int k = 0; k < 8; ++k) {
    const Eigen::Vector3f n = Eigen::Vector3f(tilt(rng), tilt(rng), -1.0f).normalized();
    s.planes.emplace_back(n.x(), n.y(), n.z(), -n.z() * depth(rng));
  }
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x) {
      const Eigen::Vector3f ray((x - kWidth / 2) / kFocal, (y - kHeight / 2) / kFocal, 1.0f);
      const Eigen::Vector4f& plane = s.planes[static_cast<std::size_t>(x / 12)];
      const float t = -plane.w() / plane.head<3>().dot(ray) + noise(rng);
      s.points.emplace_back(unit(rng) < 0.1f ? Eigen::Vector4f::Constant(NAN)
                                             : Eigen::Vector4f(t * ray.x(), t * ray.y(), t, 1));
    }
  }
  // Jobs of 8 x 8 pixels (the last row cut), with their band's plane and up to 3 others.
  for (int y0 = 0; y0 < kHeight; y0 += kJobSide) {
    for (int x0 = 0; x0 < kWidth; x0 += kJobSide) {
      const int y1 = std::min(kHeight, y0 + kJobSide), x1 = x0 + kJobSide;
      std::vector<std::uint32_t> own = {static_cast<std::uint32_t>(x0 / 12)};
      for (int k = 0; k < 3; ++k) {
        const auto other = static_cast<std::uint32_t>(rng() % s.planes.size());
        if (std::find(own.begin(), own.end(), other) == own.end()) own.push_back(other);
      }
      const std::uint32_t words[KG_CELL_JOB_WORDS] = {std::uint32_t(x0),
                                                      std::uint32_t(y0),
                                                      std::uint32_t(x1),
                                                      std::uint32_t(y1),
                                                      std::uint32_t(s.candidates.size()),
                                                      std::uint32_t(own.size()),
                                                      std::uint32_t(s.pixels)};
      s.jobs.insert(s.jobs.end(), words, words + KG_CELL_JOB_WORDS);
      s.candidates.insert(s.candidates.end(), own.begin(), own.end());
      s.pixels += static_cast<std::size_t>((x1 - x0) * (y1 - y0));
    }
  }
  return s;
}

struct Scores {
  std::vector<std::uint32_t> choices;
  std::vector<float> distances;
};

Scores score(const compute::Context& context, const ScoreScene& s) {
  using compute::Buffer;
  const auto points = Buffer<Eigen::Vector4f>::from_host(context, s.points);
  const auto jobs = Buffer<std::uint32_t>::from_host(context, s.jobs);
  const auto candidates = Buffer<std::uint32_t>::from_host(context, s.candidates);
  const auto planes = Buffer<Eigen::Vector4f>::from_host(context, s.planes);
  Buffer<std::uint32_t> choices(context, s.pixels);
  Buffer<float> distances(context, s.pixels);
  kernels::CellScoresParams params = kParams;
  params.job_count = static_cast<std::uint32_t>(s.jobs.size() / KG_CELL_JOB_WORDS);
  const compute::KernelSpec kernel{"cell_scores", KG_CELL_SCORES_LOCAL_X};
  compute::dispatch(context, kernel, {points, jobs, candidates, planes, choices, distances}, params,
                    {compute::groups_for(params.job_count, kernel.local_x)});
  return {choices.to_vector(), distances.to_vector()};
}

// plane_score's rule in double for the point against the planes `first` .. `first + count` of
// the candidates; `tie`: the answer is within 1e-4 of another.
std::uint32_t reference_choice(const ScoreScene& s, const Eigen::Vector4f& q, std::size_t first,
                               std::size_t count, bool& tie) {
  tie = false;
  if (std::isnan(q.x())) return KG_CELL_NO_CHOICE;
  const Eigen::Vector3d p = q.head<3>().cast<double>();
  std::vector<double> scores;
  for (std::size_t k = 0; k < count; ++k) {
    const Eigen::Vector4d plane = s.planes[s.candidates[first + k]].cast<double>();
    const double along = plane.head<3>().dot(p);
    const double facing = std::max(std::fabs(along) / p.norm(), double(kParams.min_facing));
    const double base = kParams.distance_base + kParams.distance_per_z2 * p.z() * p.z();
    scores.push_back(std::fabs(along + plane.w()) / (base * facing));
  }
  const auto best = std::min_element(scores.begin(), scores.end()) - scores.begin();
  for (std::size_t k = 0; k < count; ++k) {
    if (k != std::size_t(best) && std::fabs(scores[k] - scores[best]) <= 1e-4 * scores[best])
      tie = true;
  }
  tie = tie || std::fabs(scores[best] - 1.0) <= 1e-4;
  return scores[best] < 1.0 ? static_cast<std::uint32_t>(best) : KG_CELL_NO_CHOICE;
}

class CellScoresTest : public BackendTest {};

TEST_P(CellScoresTest, MatchesTheCpuAndTheRuleInDouble) {
  std::mt19937 rng(29);
  for (int round = 0; round < 3; ++round) {
    const ScoreScene s = make_scene(rng);
    const Scores got = score(context(), s);
    const Scores cpu = score(compute::Context::cpu(), s);
    EXPECT_EQ(got.choices, cpu.choices);
    EXPECT_EQ(got.distances, cpu.distances);
    std::size_t chosen = 0, none = 0, mismatches = 0, ties = 0;
    for (std::size_t j = 0; j < s.jobs.size() / KG_CELL_JOB_WORDS; ++j) {
      const std::uint32_t* w = s.jobs.data() + j * KG_CELL_JOB_WORDS;
      std::size_t slot = w[6];
      for (std::uint32_t y = w[1]; y < w[3]; ++y) {
        for (std::uint32_t x = w[0]; x < w[2]; ++x, ++slot) {
          bool tie = false;
          const std::uint32_t want = reference_choice(s, s.points[y * kWidth + x], w[4], w[5], tie);
          ties += tie;
          if (!tie && got.choices[slot] != want) ++mismatches;
          (got.choices[slot] == KG_CELL_NO_CHOICE ? none : chosen) += 1;
        }
      }
    }
    EXPECT_EQ(mismatches, 0u) << "round " << round << " (" << ties << " near ties skipped)";
    // Both outcomes are exercised.
    EXPECT_GT(chosen, s.pixels / 2);
    EXPECT_GT(none, s.pixels / 20);
  }
}

KARTOGRAF_INSTANTIATE_BACKEND_TESTS(CellScoresTest);

}  // namespace
}  // namespace kartograf
