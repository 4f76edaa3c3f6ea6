#pragma once
// Line charts as SVG, so that the examples draw their figures (crack length
// against time, force against displacement, ...) without a plotting program:
// browsers and image viewers open them, and they need no dependency.
//
//   io::PlotPanel panel{"Centre deflection", "t [ms]", "w [mm]"};
//   panel.series.push_back({"SPH shell", times_ms, deflections_mm});
//   io::write_svg_plot("deflection.svg", {panel});
//
// Several panels go side by side in one file. Non-finite y values break a line
// (a quantity that is undefined for a while, e.g. a crack speed before the
// crack moves).

#include <sphshell/core/error.hpp>
#include <sphshell/io/output_file.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

namespace sphshell::io {

enum class PlotStyle { line, dashed, points };

struct PlotSeries {
  std::string label;
  std::vector<double> x;
  std::vector<double> y;
  PlotStyle style = PlotStyle::line;
};

struct PlotPanel {
  std::string title;
  std::string x_label;
  std::string y_label;
  std::vector<PlotSeries> series;
};

// Pixel geometry of one panel; the plot area is the rectangle inside the margins.
struct PlotLayout {
  double panel_width = 560.0;
  double panel_height = 400.0;
  double margin_left = 78.0;
  double margin_right = 20.0;
  double margin_top = 36.0;
  double margin_bottom = 56.0;
  double plot_width() const { return panel_width - margin_left - margin_right; }
  double plot_height() const { return panel_height - margin_top - margin_bottom; }
};

// Axis range widened to whole multiples of a 1, 2, 2.5 or 5 × 10^k step, with
// about `target_intervals` intervals.
struct AxisTicks {
  double lower;
  double upper;
  double step;
};

inline AxisTicks nice_ticks(double minimum, double maximum, int target_intervals = 6) {
  if (!std::isfinite(minimum) || !std::isfinite(maximum) || minimum > maximum)
    throw Error("sphshell: plot axis range [" + detail::round_trip_decimal(minimum) + ", " +
                detail::round_trip_decimal(maximum) + "] is not a finite interval");
  if (target_intervals < 1)
    throw Error("sphshell: plot target_intervals = " + std::to_string(target_intervals) + " must be ≥ 1");
  if (maximum == minimum) {
    const double half_width =
        std::max(0.1 * std::abs(minimum), minimum == 0.0 ? 1.0 : std::numeric_limits<double>::min() * 1e10);
    minimum -= half_width;
    maximum += half_width;
  }
  // Halves first, so that a range spanning most of the doubles does not overflow.
  const double raw_step = (0.5 * maximum - 0.5 * minimum) / (0.5 * target_intervals);
  const double magnitude = std::pow(10.0, std::floor(std::log10(raw_step)));
  const double residual = raw_step / magnitude;
  double step = 10.0 * magnitude;
  for (const double candidate : {1.0, 2.0, 2.5, 5.0})
    if (residual <= candidate * (1.0 + 1e-9)) {
      step = candidate * magnitude;
      break;
    }
  // The small tolerance keeps a bound that is a multiple of the step (up to
  // rounding) from gaining a whole extra interval.
  double lower = std::floor(minimum / step + 1e-9) * step;
  double upper = std::ceil(maximum / step - 1e-9) * step;
  // Rounding out can pass the largest double; the data bound then serves.
  if (!std::isfinite(lower)) lower = minimum;
  if (!std::isfinite(upper)) upper = maximum;
  return {lower, upper, step};
}

namespace detail {

inline std::string tick_label(double value, double step) {
  if (std::abs(value) < 1e-9 * step) value = 0.0;
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.6g", value);
  return buffer;
}

inline std::string pixel(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.2f", value);
  return buffer;
}

inline const char* series_colour(std::size_t index) {
  static const char* const palette[] = {"#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b"};
  return palette[index % (sizeof(palette) / sizeof(palette[0]))];
}

inline void check_series(const PlotPanel& panel, const PlotSeries& series) {
  if (series.x.size() != series.y.size())
    throw Error("sphshell: plot series '" + series.label + "' in panel '" + panel.title + "' has " +
                std::to_string(series.x.size()) + " x values but " + std::to_string(series.y.size()) +
                " y values");
  for (const double x : series.x)
    if (!std::isfinite(x))
      throw Error("sphshell: plot series '" + series.label + "' in panel '" + panel.title +
                  "' has a non-finite x value (" + round_trip_decimal(x) + ")");
}

// Range of the finite points of a panel; a panel without any gets [0, 1].
inline void data_range(const PlotPanel& panel, double& x_min, double& x_max, double& y_min, double& y_max) {
  x_min = y_min = std::numeric_limits<double>::infinity();
  x_max = y_max = -std::numeric_limits<double>::infinity();
  for (const PlotSeries& series : panel.series)
    for (std::size_t k = 0; k < series.x.size(); ++k) {
      if (!std::isfinite(series.y[k])) continue;
      x_min = std::min(x_min, series.x[k]);
      x_max = std::max(x_max, series.x[k]);
      y_min = std::min(y_min, series.y[k]);
      y_max = std::max(y_max, series.y[k]);
    }
  if (x_min > x_max) x_min = 0.0, x_max = 1.0;
  if (y_min > y_max) y_min = 0.0, y_max = 1.0;
}

inline void write_panel(std::ostream& out, const PlotPanel& panel, const PlotLayout& layout, double offset_x) {
  double x_min, x_max, y_min, y_max;
  data_range(panel, x_min, x_max, y_min, y_max);
  const AxisTicks x_axis = nice_ticks(x_min, x_max);
  // Headroom above the data for the legend box, so that no point is hidden
  // behind it: the box is 18 px per series plus 14 px tall.
  // Differences of halves throughout: a range over most of the doubles must
  // not overflow.
  if (!panel.series.empty() && y_max > y_min) {
    const double legend_fraction = (18.0 * double(panel.series.size()) + 14.0) / layout.plot_height();
    if (legend_fraction < 0.5) {
      const double raised = y_max + 2.0 * (0.5 * y_max - 0.5 * y_min) * legend_fraction / (1.0 - legend_fraction);
      y_max = std::isfinite(raised) ? raised : std::numeric_limits<double>::max();
    }
  }
  const AxisTicks y_axis = nice_ticks(y_min, y_max);
  const double left = offset_x + layout.margin_left, top = layout.margin_top;
  const double width = layout.plot_width(), height = layout.plot_height();
  auto fraction = [](double value, const AxisTicks& axis) {
    return (0.5 * value - 0.5 * axis.lower) / (0.5 * axis.upper - 0.5 * axis.lower);
  };
  auto to_x = [&](double x) { return left + fraction(x, x_axis) * width; };
  auto to_y = [&](double y) { return top + (1.0 - fraction(y, y_axis)) * height; };
  // Ticks inside the axis range (its bounds are whole steps unless rounding
  // them out would have overflowed).
  auto tick_count = [](const AxisTicks& axis) {
    return int(std::floor((0.5 * axis.upper - 0.5 * axis.lower) / (0.5 * axis.step) + 1e-9));
  };
  // lower + k·step, in halves (scaling by 2 is exact).
  auto tick_value = [](const AxisTicks& axis, int k) { return 2.0 * (0.5 * axis.lower + k * (0.5 * axis.step)); };

  out << "<text x=\"" << pixel(left + width / 2) << "\" y=\"22\" text-anchor=\"middle\" font-size=\"15\">"
      << xml_escape(panel.title) << "</text>\n";
  const int x_intervals = tick_count(x_axis);
  for (int k = 0; k <= x_intervals; ++k) {
    const double value = tick_value(x_axis, k), px = to_x(value);
    out << "<line x1=\"" << pixel(px) << "\" y1=\"" << pixel(top) << "\" x2=\"" << pixel(px) << "\" y2=\""
        << pixel(top + height) << "\" stroke=\"#dddddd\"/>\n"
        << "<text x=\"" << pixel(px) << "\" y=\"" << pixel(top + height + 18)
        << "\" text-anchor=\"middle\" font-size=\"12\">" << tick_label(value, x_axis.step) << "</text>\n";
  }
  const int y_intervals = tick_count(y_axis);
  for (int k = 0; k <= y_intervals; ++k) {
    const double value = tick_value(y_axis, k), py = to_y(value);
    out << "<line x1=\"" << pixel(left) << "\" y1=\"" << pixel(py) << "\" x2=\"" << pixel(left + width)
        << "\" y2=\"" << pixel(py) << "\" stroke=\"#dddddd\"/>\n"
        << "<text x=\"" << pixel(left - 6) << "\" y=\"" << pixel(py + 4)
        << "\" text-anchor=\"end\" font-size=\"12\">" << tick_label(value, y_axis.step) << "</text>\n";
  }
  out << "<rect x=\"" << pixel(left) << "\" y=\"" << pixel(top) << "\" width=\"" << pixel(width)
      << "\" height=\"" << pixel(height) << "\" fill=\"none\" stroke=\"black\"/>\n"
      << "<text x=\"" << pixel(left + width / 2) << "\" y=\"" << pixel(top + height + 42)
      << "\" text-anchor=\"middle\" font-size=\"13\">" << xml_escape(panel.x_label) << "</text>\n"
      << "<text transform=\"translate(" << pixel(offset_x + 18) << "," << pixel(top + height / 2)
      << ") rotate(-90)\" text-anchor=\"middle\" font-size=\"13\">" << xml_escape(panel.y_label)
      << "</text>\n";

  // No clip path is needed (the axes enclose every point), and some SVG
  // renderers (ImageMagick's) draw nothing inside one.
  for (std::size_t s = 0; s < panel.series.size(); ++s) {
    const PlotSeries& series = panel.series[s];
    const char* colour = series_colour(s);
    if (series.style == PlotStyle::points) {
      for (std::size_t k = 0; k < series.x.size(); ++k)
        if (std::isfinite(series.y[k]))
          out << "<circle cx=\"" << pixel(to_x(series.x[k])) << "\" cy=\"" << pixel(to_y(series.y[k]))
              << "\" r=\"3.5\" fill=\"none\" stroke=\"" << colour << "\"/>\n";
      continue;
    }
    const std::string dash = series.style == PlotStyle::dashed ? " stroke-dasharray=\"6,4\"" : "";
    std::string points;
    auto flush_line = [&]() {
      if (!points.empty())
        out << "<polyline points=\"" << points << "\" fill=\"none\" stroke=\"" << colour
            << "\" stroke-width=\"1.6\"" << dash << "/>\n";
      points.clear();
    };
    for (std::size_t k = 0; k < series.x.size(); ++k) {
      if (!std::isfinite(series.y[k])) {
        flush_line();
        continue;
      }
      if (!points.empty()) points += ' ';
      points += pixel(to_x(series.x[k])) + "," + pixel(to_y(series.y[k]));
    }
    flush_line();
  }

  // Legend in the top right corner, on a translucent box sized from the label
  // lengths (about 7 px per character at this font size).
  std::size_t longest_label = 0;
  for (const PlotSeries& series : panel.series) longest_label = std::max(longest_label, series.label.size());
  const double key_width = 42.0 + 7.0 * double(longest_label);
  if (!panel.series.empty())
    out << "<rect x=\"" << pixel(left + width - key_width - 6) << "\" y=\"" << pixel(top + 4) << "\" width=\""
        << pixel(key_width) << "\" height=\"" << pixel(18.0 * double(panel.series.size()) + 6)
        << "\" fill=\"white\" fill-opacity=\"0.85\" stroke=\"#bbbbbb\"/>\n";
  for (std::size_t s = 0; s < panel.series.size(); ++s) {
    const double row_y = top + 20 + 18 * double(s), key_x = left + width - key_width;
    const char* colour = series_colour(s);
    if (panel.series[s].style == PlotStyle::points)
      out << "<circle cx=\"" << pixel(key_x + 12) << "\" cy=\"" << pixel(row_y - 4) << "\" r=\"3.5\" fill=\"none\" stroke=\""
          << colour << "\"/>\n";
    else
      out << "<line x1=\"" << pixel(key_x) << "\" y1=\"" << pixel(row_y - 4) << "\" x2=\"" << pixel(key_x + 24)
          << "\" y2=\"" << pixel(row_y - 4) << "\" stroke=\"" << colour << "\" stroke-width=\"1.6\""
          << (panel.series[s].style == PlotStyle::dashed ? " stroke-dasharray=\"6,4\"" : "") << "/>\n";
    out << "<text x=\"" << pixel(key_x + 30) << "\" y=\"" << pixel(row_y) << "\" font-size=\"12\">"
        << xml_escape(panel.series[s].label) << "</text>\n";
  }
}

}  // namespace detail

inline void write_svg_plot(const std::string& path, const std::vector<PlotPanel>& panels,
                           const PlotLayout& layout = {}) {
  if (panels.empty()) throw Error("sphshell: SVG plot '" + path + "' needs at least one panel");
  sphshell::detail::require_positive("PlotLayout::panel_width", layout.panel_width);
  sphshell::detail::require_positive("PlotLayout::panel_height", layout.panel_height);
  sphshell::detail::require_nonnegative("PlotLayout::margin_left", layout.margin_left);
  sphshell::detail::require_nonnegative("PlotLayout::margin_right", layout.margin_right);
  sphshell::detail::require_nonnegative("PlotLayout::margin_top", layout.margin_top);
  sphshell::detail::require_nonnegative("PlotLayout::margin_bottom", layout.margin_bottom);
  if (layout.plot_width() <= 0.0 || layout.plot_height() <= 0.0)
    throw Error("sphshell: SVG plot '" + path + "': the margins leave no plot area (" +
                detail::round_trip_decimal(layout.plot_width()) + " × " +
                detail::round_trip_decimal(layout.plot_height()) + " px)");
  for (const PlotPanel& panel : panels)
    for (const PlotSeries& series : panel.series) detail::check_series(panel, series);
  std::ostringstream body;
  for (std::size_t p = 0; p < panels.size(); ++p)
    detail::write_panel(body, panels[p], layout, layout.panel_width * double(p));
  detail::ReplacingOutputFile file(path);
  const double total_width = layout.panel_width * double(panels.size());
  file.stream() << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
                << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << detail::pixel(total_width)
                << "\" height=\"" << detail::pixel(layout.panel_height) << "\" viewBox=\"0 0 "
                << detail::pixel(total_width) << " " << detail::pixel(layout.panel_height)
                << "\" font-family=\"sans-serif\">\n"
                << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n"
                << body.str() << "</svg>\n";
  file.commit();
}

}  // namespace sphshell::io
