#include "kartograf/synth/trajectory.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "kartograf/core/error.hpp"
#include "kartograf/core/random.hpp"

namespace kartograf::synth {

namespace {

constexpr double kDegree = std::numbers::pi / 180.0;
constexpr double kSampleStep = 0.001;  // metres: the tour's speed profile is tabulated this finely
constexpr double kMaxSpeedChange = 0.002;  // metres per frame, per frame (1.8 m/s^2 at 30 Hz)
constexpr double kSafety = 0.97;           // plan slightly inside the limits (finite differences)

// The look-around offset on [0, 1]: left, then right, zero with zero slope at both ends.
double look_shape(double x) {
  static const double peak = [] {
    double m = 0;
    for (int i = 0; i <= 1000; ++i) {
      const double y = i / 1000.0;
      m = std::max(
          m, std::sin(2 * std::numbers::pi * y) * std::pow(std::sin(std::numbers::pi * y), 2));
    }
    return m;
  }();
  return std::sin(2 * std::numbers::pi * x) * std::pow(std::sin(std::numbers::pi * x), 2) / peak;
}

// One full turn to the left on [0, 1], with zero turn rate at both ends.
double turn_shape(double x) {
  return 2 * std::numbers::pi * x - std::sin(2 * std::numbers::pi * x);
}

struct Interval {
  double begin, end;
};

// The obstacles (furniture, door leaves) in or near `room`.
std::vector<Rect2> obstacles_near(const World& world, const Room& room) {
  std::vector<Rect2> obstacles;
  for (const Rect2& r : world.obstacle_footprints()) {
    if (r.overlaps(room.rect.expanded(0.5))) obstacles.push_back(r);
  }
  return obstacles;
}

// Distance from p to the walls of `room` and to the obstacles (furniture, door leaves).
double clearance(const Room& room, const std::vector<Rect2>& obstacles, const Eigen::Vector2d& p) {
  double c = std::min((p - room.rect.min).minCoeff(), (room.rect.max - p).minCoeff());
  for (const Rect2& r : obstacles) c = std::min(c, r.distance(p));
  return c;
}

// Virtual length [m] of one turn in place: the tour's parameter runs over the route's length plus
// this much per stop, so the speed profile below limits turning speed and its changes too.
constexpr double kTurnLength = 2.0;

// The camera along the route, by a parameter u that runs over the route's length plus, in a
// survey, kTurnLength per stop (u advances while the robot turns in place). Heading: the direction
// of travel plus, inside each room (between the straight stretches at its doorways), a look to
// the left and to the right; or, in a survey, one full turn in place at the most open point of
// each room's and corridor pass's stretch of route.
class TourPlan {
 public:
  TourPlan(const World& world, double look_around_deg, bool survey)
      : path_(route_path(world)), amplitude_(look_around_deg * kDegree) {
    const auto& s = path_.vertex_positions();
    std::vector<std::size_t> doors;
    for (std::size_t i = 0; i < world.route.size(); ++i) {
      if (world.route[i].straight_margin > 0) doors.push_back(i);
    }
    const double length = path_.length();
    for (std::size_t k = 0; k < doors.size(); ++k) {
      const std::size_t i = doors[k], j = doors[(k + 1) % doors.size()];
      double begin = s[i] + world.route[i].straight_margin;
      double end = s[j] - world.route[j].straight_margin;
      if (end < begin - 1e-9) end += length;  // wraps past the start
      if (end - begin < 0.5) continue;
      const Label room = world.room_at(path_.position(0.5 * (begin + end)));
      if (!room) continue;
      if (survey) {
        stops_.push_back(most_open_route_position(world, world.room(room), begin, end));
      } else if (world.room(room).kind == RoomKind::room) {
        looks_.push_back({begin, end});
      }
    }
    std::sort(stops_.begin(), stops_.end());
  }

  const RoutePath& path() const { return path_; }
  double length() const { return path_.length() + kTurnLength * stops_.size(); }

  // Route position at u, and how far (0..1) through a turn in place it is (0 while moving).
  double route_position(double u, double* turned = nullptr, int* turns_done = nullptr) const {
    double offset = 0;
    int done = 0;
    for (double stop : stops_) {
      if (u < stop + offset) break;
      if (u < stop + offset + kTurnLength) {
        if (turned) *turned = (u - stop - offset) / kTurnLength;
        if (turns_done) *turns_done = done;
        return stop;
      }
      offset += kTurnLength;
      ++done;
    }
    if (turned) *turned = 0;
    if (turns_done) *turns_done = done;
    return u - offset;
  }

  double yaw(double u) const {
    double turned = 0;
    int turns_done = 0;
    const double s = route_position(u, &turned, &turns_done);
    double yaw = path_.heading(s) + 2 * std::numbers::pi * turns_done + turn_shape(turned);
    for (const Interval& look : looks_) {
      for (double shift : {0.0, path_.length()}) {  // an interval may wrap past the end
        const double x = (s + shift - look.begin) / (look.end - look.begin);
        if (x > 0 && x < 1) yaw += amplitude_ * look_shape(x);
      }
    }
    return yaw;
  }

  // Whether [u0, u1] contains the start or the end of a turn in place (the robot stands still
  // there).
  bool starts_or_ends_turn(double u0, double u1) const {
    double offset = 0;
    for (double stop : stops_) {
      for (double edge : {stop + offset, stop + offset + kTurnLength}) {
        if (edge >= u0 && edge <= u1) return true;
      }
      offset += kTurnLength;
    }
    return false;
  }

 private:
  // The route position in [begin, end] (wrapped) farthest from the room's walls and obstacles.
  double most_open_route_position(const World& world, const Room& room, double begin,
                                  double end) const {
    const std::vector<Rect2> obstacles = obstacles_near(world, room);
    double best_s = 0.5 * (begin + end), best = -1;
    for (double s = begin; s <= end; s += 0.05) {
      const double c = clearance(room, obstacles, path_.position(s));
      if (c > best) best = c, best_s = s;
    }
    return std::fmod(best_s, path_.length());
  }

  RoutePath path_;
  double amplitude_;
  std::vector<Interval> looks_;
  std::vector<double> stops_;  // route positions of the turns in place, ascending
};

// Frames per unit of tour parameter at each tabulated position: the inverse of a speed profile
// that keeps every frame within the step and yaw limits, stands still where a turn in place starts
// or ends, and changes speed by at most kMaxSpeedChange per frame (a bounded acceleration:
// continuous velocity, C1 positions). The classic two-pass construction: the pointwise speed
// limit, then forward and backward passes bounding d(v^2)/du by 2 a, around the closed tour.
std::vector<double> frames_per_metre(const TourPlan& plan, const TourParams& options,
                                     int& samples) {
  const double length = plan.length();
  samples = std::max(8, static_cast<int>(std::ceil(length / kSampleStep)));
  const double du = length / samples;
  const double max_step = kSafety * options.max_step;
  const double max_yaw = kSafety * options.max_yaw_step_deg * kDegree;
  std::vector<double> speed(samples);  // parameter units per frame
  double yaw_prev = plan.yaw(0), s_prev = plan.route_position(0);
  for (int i = 0; i < samples; ++i) {
    const double u = (i + 1) * du;
    const double yaw_next = plan.yaw(u), s_next = plan.route_position(u);
    const double yaw_rate = std::fabs(yaw_next - yaw_prev) / du;  // rad per unit
    const double step_rate = std::fabs(s_next - s_prev) / du;     // metres per unit
    double v = step_rate > 0 ? max_step / step_rate : max_step;
    if (yaw_rate > 0) v = std::min(v, max_yaw / yaw_rate);
    if (plan.starts_or_ends_turn(i * du, u)) v = 0.25 * kMaxSpeedChange;  // all but stopped
    speed[i] = v;
    yaw_prev = yaw_next;
    s_prev = s_next;
  }
  const double reach = 2.0 * kSafety * kMaxSpeedChange * du;  // the most v^2 may change per sample
  for (int pass = 0; pass < 2; ++pass) {                      // twice: the route is a loop
    for (int i = 1; i <= samples; ++i) {
      double& v = speed[i % samples];
      v = std::min(v, std::sqrt(speed[i - 1] * speed[i - 1] + reach));
    }
    for (int i = samples - 2; i >= -1; --i) {
      double& v = speed[(i + samples) % samples];
      v = std::min(v, std::sqrt(speed[i + 1] * speed[i + 1] + reach));
    }
  }
  std::vector<double> rate(samples);
  for (int i = 0; i < samples; ++i) rate[i] = 1.0 / speed[i];
  return rate;
}

}  // namespace

void TourParams::validate() const {
  require(camera_height > 0.1 && std::isfinite(camera_height),
          "TourParams: camera_height must be > 0.1 m");
  require(std::fabs(pitch_deg) < 80, "TourParams: pitch_deg must be within +-80 degrees");
  require(look_around_deg >= 0 && look_around_deg <= 90,
          "TourParams: look_around_deg must be in [0, 90]");
  require(max_step > 0 && max_yaw_step_deg > 0, "TourParams: per-frame limits must be positive");
  require(frame_rate > 0 && std::isfinite(frame_rate), "TourParams: frame_rate must be positive");
}

Eigen::Isometry3d camera_pose(const Eigen::Vector3d& position, double yaw, double pitch_down,
                              double roll) {
  const Eigen::Vector3d forward(std::cos(yaw) * std::cos(pitch_down),
                                std::sin(yaw) * std::cos(pitch_down), -std::sin(pitch_down));
  const Eigen::Vector3d right(std::sin(yaw), -std::cos(yaw), 0.0);
  const Eigen::Vector3d down = forward.cross(right);
  Eigen::Matrix3d rotation;
  rotation << right, down, forward;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = rotation * Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  pose.translation() = position;
  return pose;
}

// Frames the tour needs at the per-frame limits.
double frames_at_limits(const TourPlan& plan, const TourParams& options) {
  int samples = 0;
  const std::vector<double> rate = frames_per_metre(plan, options, samples);
  double total = 0;
  for (double r : rate) total += r * plan.length() / samples;
  return total;
}

int tour_frames_needed(const World& world, const TourParams& options) {
  options.validate();
  return static_cast<int>(
             std::ceil(frames_at_limits(TourPlan(world, 0.0, options.survey), options))) +
         1;
}

Trajectory robot_tour(const World& world, int frame_count, const TourParams& options) {
  require(frame_count >= 2,
          "robot_tour: needs at least 2 frames, got " + std::to_string(frame_count));
  options.validate();
  // The largest look-around that keeps the limits at this frame count (bisection; the frames
  // needed grow with it).
  const double budget = frame_count - 1;
  auto fits = [&](double look) {
    return frames_at_limits(TourPlan(world, look, options.survey), options) <= budget;
  };
  double look = options.look_around_deg;
  if (!fits(look)) {
    double lo = 0, hi = look;
    if (fits(0.0)) {
      for (int i = 0; i < 12; ++i) {
        const double mid = 0.5 * (lo + hi);
        (fits(mid) ? lo : hi) = mid;
      }
    }
    look = lo;
  }
  const TourPlan plan(world, look, options.survey);
  int samples = 0;
  const std::vector<double> rate = frames_per_metre(plan, options, samples);
  const double length = plan.length();
  const double du = length / samples;
  std::vector<double> cumulative(samples + 1, 0.0);  // frames spent up to sample i
  for (int i = 0; i < samples; ++i) cumulative[i + 1] = cumulative[i] + rate[i] * du;

  Trajectory trajectory;
  trajectory.reserve(static_cast<std::size_t>(frame_count));
  const double pitch = options.pitch_deg * kDegree;
  for (int k = 0; k < frame_count; ++k) {
    // Frames are spread evenly over the total: each gets the same share of "frame budget".
    const double target = cumulative.back() * k / (frame_count - 1);
    const auto it = std::upper_bound(cumulative.begin(), cumulative.end(), target);
    const int i = std::clamp(static_cast<int>(it - cumulative.begin()) - 1, 0, samples - 1);
    const double fraction = (target - cumulative[i]) / (cumulative[i + 1] - cumulative[i]);
    const double u = k == frame_count - 1 ? length : (i + std::clamp(fraction, 0.0, 1.0)) * du;
    const Eigen::Vector2d p = plan.path().position(plan.route_position(u));
    StampedPose pose;
    pose.timestamp = options.start_time + k / options.frame_rate;
    pose.pose = camera_pose({p.x(), p.y(), options.camera_height}, plan.yaw(u), pitch);
    trajectory.push_back(pose);
  }
  return trajectory;
}

std::pair<Eigen::Vector2d, double> most_open_point(const World& world, Label room_id) {
  const Room& room = world.room(room_id);
  const std::vector<Rect2> obstacles = obstacles_near(world, room);
  constexpr double kStep = 0.05;
  const Eigen::Vector2i cells = (room.rect.size() / kStep).array().floor().cast<int>();
  Eigen::Vector2d best = room.rect.center();
  double best_clearance = -1;
  for (int j = 0; j < cells.y(); ++j) {
    for (int i = 0; i < cells.x(); ++i) {
      const Eigen::Vector2d p = room.rect.min + kStep * Eigen::Vector2d(i + 0.5, j + 0.5);
      const double c = clearance(room, obstacles, p);
      if (c > best_clearance + 1e-12) {
        best_clearance = c;
        best = p;
      }
    }
  }
  return {best, best_clearance};
}

Trajectory handheld(const World& world, Label room, int frame_count, std::uint64_t seed,
                    const HandheldParams& options) {
  require(frame_count >= 1, "handheld: needs at least 1 frame");
  require(options.frame_rate > 0, "handheld: frame_rate must be positive");
  const auto [center, clearance] = most_open_point(world, room);
  Rng rng(hash_key(seed, room, 0x68616e64ULL));
  const double radius = std::clamp(clearance - 0.6, 0.05, 0.5);
  // A few sinusoids with random phases and slightly random frequencies [Hz]: smooth, bounded.
  struct Wave {
    double amplitude, frequency, phase;
    double at(double t) const {
      return amplitude * std::sin(2 * std::numbers::pi * frequency * t + phase);
    }
  };
  auto wave = [&](double amplitude, double frequency) {
    return Wave{amplitude, frequency * rng.uniform(0.8, 1.2), rng.uniform(0, 2 * std::numbers::pi)};
  };
  const Wave x1 = wave(0.6 * radius, 0.07), x2 = wave(0.4 * radius, 0.23);
  const Wave y1 = wave(0.6 * radius, 0.05), y2 = wave(0.4 * radius, 0.19);
  const Wave z1 = wave(0.06, 0.3), z2 = wave(0.015, 1.1);
  const Wave yaw_sweep = wave(1.2, 0.04);
  const double yaw_drift = (rng.bernoulli(0.5) ? 1.0 : -1.0) * 0.25;  // rad/s
  const double yaw0 = rng.uniform(-std::numbers::pi, std::numbers::pi);
  const Wave pitch1 = wave(4 * kDegree, 0.15), pitch2 = wave(1 * kDegree, 0.8);
  const Wave roll1 = wave(3 * kDegree, 0.12), roll2 = wave(1 * kDegree, 0.9);

  Trajectory trajectory;
  for (int k = 0; k < frame_count; ++k) {
    const double t = k / options.frame_rate;
    const Eigen::Vector3d position(center.x() + x1.at(t) + x2.at(t),
                                   center.y() + y1.at(t) + y2.at(t),
                                   options.height + z1.at(t) + z2.at(t));
    const double yaw = yaw0 + yaw_sweep.at(t) + yaw_drift * t;
    const double pitch = 12 * kDegree + pitch1.at(t) + pitch2.at(t);
    const double roll = roll1.at(t) + roll2.at(t);
    trajectory.push_back({options.start_time + t, camera_pose(position, yaw, pitch, roll)});
  }
  return trajectory;
}

}  // namespace kartograf::synth
