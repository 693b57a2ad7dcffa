#include "kartograf/outputs/prior_clock.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace kartograf::io {

namespace {

std::string signed_seconds(double s) {
  char text[32];
  std::snprintf(text, sizeof(text), "%+.3f s", s);
  return text;
}

}  // namespace

bool prior_clock_agrees(const PriorClock& clock) {
  const eval::ClockOffsetEstimate& e = clock.measured;
  return e.observable && std::fabs(e.offset_s - clock.given_s) <= std::max(3 * e.sigma_s, 0.005);
}

std::string prior_clock_text(const PriorClock& clock) {
  const eval::ClockOffsetEstimate& e = clock.measured;
  if (e.steps == 0) {
    return "not measured (the file's poses do not span the frames' times +- 500 ms)";
  }
  if (!e.observable) {
    return "not measurable from this run (" + std::to_string(e.steps) +
           " steps compared; the camera must turn, and not at one rate)";
  }
  char line[320];
  if (prior_clock_agrees(clock)) {
    std::snprintf(line, sizeof(line),
                  "agrees with the offset in use (%s; best match %s +- %.1f ms, turning off by "
                  "%.2f deg a step)",
                  signed_seconds(clock.given_s).c_str(), signed_seconds(e.offset_s).c_str(),
                  1000 * e.sigma_s, e.rms_deg);
  } else {
    std::snprintf(line, sizeof(line),
                  "its turning matches best read at %s (+- %.1f ms) from the frames' timestamps, "
                  "not %s as in use (turning off by %.2f deg a step there, %.2f in use): try "
                  "--prior-time-offset %.3f",
                  signed_seconds(e.offset_s).c_str(), 1000 * e.sigma_s,
                  signed_seconds(clock.given_s).c_str(), e.rms_deg, e.given_rms_deg, e.offset_s);
  }
  return line;
}

}  // namespace kartograf::io
