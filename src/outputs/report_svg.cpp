#include "outputs/report_svg.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "outputs/html_text.hpp"

namespace kartograf::io::detail {

namespace {

struct Range {
  double low = std::numeric_limits<double>::infinity();
  double high = -std::numeric_limits<double>::infinity();
  void add(double v) {
    low = std::min(low, v);
    high = std::max(high, v);
  }
  bool empty() const { return !(low <= high); }
};

// Data to pixels inside the plot area.
struct Frame {
  double left, top, width, height;
  Range x, y;
  double px(double v) const { return left + (v - x.low) / (x.high - x.low) * width; }
  double py(double v) const { return top + height - (v - y.low) / (y.high - y.low) * height; }
};

// A range widened to whole tick steps, never of zero width.
Range padded(Range r, double step) {
  r.low = std::floor(r.low / step + 1e-9) * step;
  r.high = std::ceil(r.high / step - 1e-9) * step;
  if (r.high <= r.low) r.high = r.low + step;
  return r;
}

std::string tick_text(double v, double step) {
  const int decimals = std::clamp(static_cast<int>(std::ceil(-std::log10(step) - 1e-9)), 0, 6);
  const std::string format = "%." + std::to_string(decimals) + "f";
  return format_number(std::abs(v) < step * 1e-6 ? 0.0 : v, format.c_str());
}

void grid_and_ticks(std::ostringstream& svg, const Frame& f, double x_step, double y_step) {
  svg << "<g class=\"grid\">";
  for (double v = f.x.low; v <= f.x.high + x_step * 1e-6; v += x_step)
    svg << "<line x1=\"" << f.px(v) << "\" y1=\"" << f.top << "\" x2=\"" << f.px(v) << "\" y2=\""
        << f.top + f.height << "\"/><text class=\"tick\" x=\"" << f.px(v) << "\" y=\""
        << f.top + f.height + 14 << "\" text-anchor=\"middle\">" << tick_text(v, x_step)
        << "</text>";
  for (double v = f.y.low; v <= f.y.high + y_step * 1e-6; v += y_step)
    svg << "<line x1=\"" << f.left << "\" y1=\"" << f.py(v) << "\" x2=\"" << f.left + f.width
        << "\" y2=\"" << f.py(v) << "\"/><text class=\"tick\" x=\"" << f.left - 6 << "\" y=\""
        << f.py(v) + 4 << "\" text-anchor=\"end\">" << tick_text(v, y_step) << "</text>";
  svg << "</g>\n";
}

void axis_labels(std::ostringstream& svg, const Frame& f, const PlotAxes& axes) {
  svg << "<text class=\"label\" x=\"" << f.left + f.width / 2 << "\" y=\"" << f.top + f.height + 32
      << "\" text-anchor=\"middle\">" << html_escape(axes.x_label) << "</text>"
      << "<text class=\"label\" transform=\"translate(14," << f.top + f.height / 2
      << ") rotate(-90)\" text-anchor=\"middle\">" << html_escape(axes.y_label) << "</text>\n";
}

void polyline(std::ostringstream& svg, const Frame& f, const PlotSeries& s) {
  svg << "<polyline fill=\"none\" stroke-width=\"1.6\" stroke=\"" << html_escape(s.colour)
      << "\" points=\"";
  for (const auto& [x, y] : s.points) svg << f.px(x) << ',' << f.py(y) << ' ';
  svg << "\"><title>" << html_escape(s.name) << "</title></polyline>\n";
}

void legend(std::ostringstream& svg, const Frame& f, const std::vector<PlotSeries>& series) {
  double y = f.top + 6;
  for (const PlotSeries& s : series) {
    const double x = f.left + f.width - 170;
    svg << "<line x1=\"" << x << "\" y1=\"" << y << "\" x2=\"" << x + 22 << "\" y2=\"" << y
        << "\" stroke-width=\"2.5\" stroke=\"" << html_escape(s.colour) << "\"/><text x=\""
        << x + 28 << "\" y=\"" << y + 4 << "\">" << html_escape(s.name) << "</text>\n";
    y += 16;
  }
}

}  // namespace

double nice_step(double range, int ticks) {
  if (!(range > 0) || ticks < 1) return 1;
  const double raw = range / ticks;
  const double power = std::pow(10.0, std::floor(std::log10(raw)));
  for (const double m : {1.0, 2.0, 5.0})
    if (raw <= m * power * 1.000001) return m * power;
  return 10 * power;
}

std::string svg_line_plot(const std::vector<PlotSeries>& series, const PlotAxes& axes) {
  Frame f{58, 10, axes.width - 58.0 - 14, axes.height - 10.0 - 42, {}, {}};
  for (const PlotSeries& s : series) {
    for (const auto& [x, y] : s.points) {
      f.x.add(x);
      f.y.add(y);
    }
  }
  if (f.x.empty()) return "<p>Nothing to plot.</p>\n";
  if (axes.y_from_zero) f.y.add(0);
  if (axes.y_reference) f.y.add(axes.y_reference->first);
  const double x_step = nice_step(f.x.high - f.x.low, 8), y_step = nice_step(f.y.high - f.y.low, 5);
  f.x = padded(f.x, x_step);
  f.y = padded(f.y, y_step);
  std::ostringstream svg;
  svg << "<svg class=\"plot\" viewBox=\"0 0 " << axes.width << ' ' << axes.height
      << "\" role=\"img\" aria-label=\"" << html_escape(axes.y_label) << " over "
      << html_escape(axes.x_label) << "\">\n";
  grid_and_ticks(svg, f, x_step, y_step);
  axis_labels(svg, f, axes);
  if (axes.y_reference) {
    const double y = f.py(axes.y_reference->first);
    svg << "<line class=\"reference\" x1=\"" << f.left << "\" y1=\"" << y << "\" x2=\""
        << f.left + f.width << "\" y2=\"" << y << "\"/><text class=\"reference-label\" x=\""
        << f.left + f.width - 4 << "\" y=\"" << y - 5 << "\" text-anchor=\"end\">"
        << html_escape(axes.y_reference->second) << "</text>\n";
  }
  for (const PlotSeries& s : series) polyline(svg, f, s);
  if (series.size() > 1) legend(svg, f, series);
  svg << "</svg>\n";
  return svg.str();
}

std::string svg_bar_chart(const std::vector<Bar>& bars, int width) {
  constexpr double kRow = 24, kLabel = 120, kText = 150;
  double longest = 0;
  for (const Bar& b : bars) longest = std::max(longest, b.value);
  const double height = kRow * static_cast<double>(bars.size()) + 4;
  const double span = width - kLabel - kText;
  std::ostringstream svg;
  svg << "<svg class=\"bars\" viewBox=\"0 0 " << width << ' ' << height << "\" role=\"img\">\n";
  double y = 2;
  for (const Bar& b : bars) {
    const double length = longest > 0 ? std::max(1.0, b.value / longest * span) : 1.0;
    svg << "<text x=\"" << kLabel - 8 << "\" y=\"" << y + 16 << "\" text-anchor=\"end\">"
        << html_escape(b.label) << "</text><rect x=\"" << kLabel << "\" y=\"" << y + 3
        << "\" width=\"" << length << "\" height=\"" << kRow - 6 << "\" rx=\"2\"/><text x=\""
        << kLabel + length + 6 << "\" y=\"" << y + 16 << "\">" << html_escape(b.text)
        << "</text>\n";
    y += kRow;
  }
  svg << "</svg>\n";
  return svg.str();
}

}  // namespace kartograf::io::detail
