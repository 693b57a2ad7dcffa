#pragma once
// The motion prior file's clock as a run measured it (eval::estimate_clock_offset against the
// camera's own steps), in words for the summaries and the map's report.
#include <string>

#include "kartograf/eval/clock_offset.hpp"

namespace kartograf::io {

struct PriorClock {
  double given_s = 0;  // --prior-time-offset: the offset the run read the file at
  eval::ClockOffsetEstimate measured;
};

// The measured offset is the given one within three standard errors (or 5 ms).
bool prior_clock_agrees(const PriorClock& clock);

// "agrees with the offset in use (...)", "its turning matches best read at +S ...: try
// --prior-time-offset S", or why it was not measured.
std::string prior_clock_text(const PriorClock& clock);

}  // namespace kartograf::io
