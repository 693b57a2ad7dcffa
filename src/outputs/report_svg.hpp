#pragma once
// Plots as inline SVG for the map report: no script, they print and scale with the page.
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace kartograf::io::detail {

struct PlotSeries {
  std::string name;
  std::string colour;                             // CSS colour
  std::vector<std::pair<double, double>> points;  // (x, y) in order
};

struct PlotAxes {
  std::string x_label, y_label;
  int width = 760, height = 260;  // the SVG's size in CSS pixels (it scales to the page)
  bool y_from_zero = true;
  std::optional<std::pair<double, std::string>> y_reference;  // a dashed line and its label
};

// A line plot with a grid, ticks, axis labels and (for more than one series) a legend.
std::string svg_line_plot(const std::vector<PlotSeries>& series, const PlotAxes& axes);

struct Bar {
  std::string label;
  double value = 0;
  std::string text;  // written after the bar, e.g. "3.2 s (41 %)"
};

// Horizontal bars, one row each, longest = the widest bar.
std::string svg_bar_chart(const std::vector<Bar>& bars, int width = 760);

// A step of 1, 2 or 5 x 10^k that cuts `range` into about `ticks` parts.
double nice_step(double range, int ticks);

}  // namespace kartograf::io::detail
