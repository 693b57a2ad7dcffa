#include "kartograf/eval/clock_offset.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "kartograf/core/error.hpp"
#include "kartograf/core/se3.hpp"

namespace kartograf::eval {

namespace {

// The search's grids: every 5 ms over the range, then every 0.5 ms around the best of those.
constexpr double kCoarseStep = 0.005;
constexpr double kFineStep = 0.0005;

double angle_deg(const Eigen::Isometry3d& from, const Eigen::Isometry3d& to) {
  return se3::rotation_angle(from.inverse() * to) * 180.0 / M_PI;
}

// A step of the sparser trajectory: its span and how far the body turned over it.
struct Step {
  double t0, t1, angle_deg;
};

// The sparser trajectory's steps and the denser trajectory, read at a step's times plus `sign`
// times the offset. Steps come from the sparser one because interpolating it would compare its
// mean rate over a sample interval with the other's rate at a moment in it (turning up or down to
// speed, a 10 Hz odometry against 30 Hz frames measured 13 ms off).
struct StepsAndReference {
  std::vector<Step> steps;
  const Trajectory* reference = nullptr;
  double sign = 1;
};

double median_interval(const Trajectory& t) {
  std::vector<double> intervals;
  for (std::size_t i = 1; i < t.size(); ++i)
    intervals.push_back(t[i].timestamp - t[i - 1].timestamp);
  if (intervals.empty()) return 0;
  std::nth_element(intervals.begin(), intervals.begin() + intervals.size() / 2, intervals.end());
  return intervals[intervals.size() / 2];
}

// The steps whose span, read at any offset of [from, to], lies inside the reference's time span.
StepsAndReference steps_of(const Trajectory& frames, const Trajectory& other, double from,
                           double to) {
  const bool frames_sparser = median_interval(frames) >= median_interval(other);
  StepsAndReference out{{}, frames_sparser ? &other : &frames, frames_sparser ? 1.0 : -1.0};
  const Trajectory& base = frames_sparser ? frames : other;
  if (out.reference->empty()) return out;
  // Read times t + sign * offset for offsets in [from, to] stay inside the reference's span.
  const double low = std::min(out.sign * from, out.sign * to);
  const double high = std::max(out.sign * from, out.sign * to);
  const double first = out.reference->front().timestamp - low;
  const double last = out.reference->back().timestamp - high;
  for (std::size_t i = 1; i < base.size(); ++i) {
    const StampedPose& a = base[i - 1];
    const StampedPose& b = base[i];
    if (b.timestamp <= a.timestamp || a.timestamp < first || b.timestamp > last) continue;
    out.steps.push_back({a.timestamp, b.timestamp, angle_deg(a.pose, b.pose)});
  }
  return out;
}

// The steps' mean squared rotation disagreement [deg^2] with the reference read at the offset,
// each capped at outlier_deg^2 (also where the reference has no pose).
class Disagreement {
 public:
  Disagreement(const StepsAndReference& steps, double outlier_deg)
      : steps_(&steps), cap_(outlier_deg * outlier_deg) {}

  double operator()(double offset) const {
    const double shift = steps_->sign * offset;
    double sum = 0;
    for (const Step& s : steps_->steps) {
      const auto a = pose_at(*steps_->reference, s.t0 + shift);
      const auto b = pose_at(*steps_->reference, s.t1 + shift);
      const double r = a && b ? s.angle_deg - angle_deg(*a, *b) : INFINITY;
      sum += std::min(r * r, cap_);
    }
    return sum / static_cast<double>(steps_->steps.size());
  }

 private:
  const StepsAndReference* steps_;
  double cap_;
};

// The offset of [from, to] on a grid of `step` where the disagreement is least.
double grid_minimum(const Disagreement& cost, double from, double to, double step) {
  double best = from, best_cost = INFINITY;
  const auto count = static_cast<int>(std::lround((to - from) / step));
  for (int k = 0; k <= count; ++k) {
    const double offset = from + k * step;
    const double c = cost(offset);
    if (c < best_cost) best = offset, best_cost = c;
  }
  return best;
}

// Least-squares parabola c(centre + u) = A u^2 + B u + C over the fine grid within one coarse step
// of `centre`: its vertex (kept within that window) and curvature A (<= 0: flat or a maximum).
std::pair<double, double> parabola_vertex(const Disagreement& cost, double centre) {
  Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
  Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
  const auto half = static_cast<int>(std::lround(kCoarseStep / kFineStep));
  for (int k = -half; k <= half; ++k) {
    const double u = k * kFineStep;
    const Eigen::Vector3d row(u * u, u, 1.0);
    normal += row * row.transpose();
    rhs += row * cost(centre + u);
  }
  const Eigen::Vector3d abc = normal.ldlt().solve(rhs);
  if (!(abc(0) > 0)) return {centre, 0.0};
  const double vertex = std::clamp(-abc(1) / (2 * abc(0)), -kCoarseStep, kCoarseStep);
  return {centre + vertex, abc(0)};
}

void check_search(const ClockOffsetSearch& s) {
  const auto positive = [](double v) { return std::isfinite(v) && v > 0; };
  require(positive(s.half_range_s) && positive(s.outlier_deg) && positive(s.max_sigma_s) &&
              std::isfinite(s.given_s),
          "clock offset: half_range_s, outlier_deg and max_sigma_s must be finite and > 0, and "
          "given_s finite (got " +
              std::to_string(s.half_range_s) + ", " + std::to_string(s.outlier_deg) + ", " +
              std::to_string(s.max_sigma_s) + ", " + std::to_string(s.given_s) + ")");
}

}  // namespace

ClockOffsetEstimate estimate_clock_offset(const Trajectory& frames, const Trajectory& other,
                                          const ClockOffsetSearch& search) {
  check_search(search);
  ClockOffsetEstimate estimate;
  const double from = search.given_s - search.half_range_s,
               to = search.given_s + search.half_range_s;
  const StepsAndReference steps = steps_of(frames, other, from, to);
  estimate.steps = steps.steps.size();
  if (steps.steps.empty()) return estimate;
  const Disagreement cost(steps, search.outlier_deg);
  const double coarse = grid_minimum(cost, from, to, kCoarseStep);
  const double fine = grid_minimum(cost, coarse - kCoarseStep, coarse + kCoarseStep, kFineStep);
  const auto [offset, curvature] = parabola_vertex(cost, fine);
  estimate.offset_s = offset;
  const double least = cost(offset);
  estimate.rms_deg = std::sqrt(least);
  estimate.given_rms_deg = std::sqrt(cost(search.given_s));
  // Near the vertex c(t) = least + curvature (t - offset)^2 with curvature the steps' mean squared
  // rate of disagreement: the least-squares error of the offset is sqrt(least / (n curvature)).
  if (curvature > 0)
    estimate.sigma_s = std::sqrt(least / (static_cast<double>(estimate.steps) * curvature));
  const bool inside = std::fabs(offset - search.given_s) <= search.half_range_s - kCoarseStep;
  estimate.observable = inside && estimate.sigma_s <= search.max_sigma_s;
  return estimate;
}

}  // namespace kartograf::eval
