// Inline SVG charts: axes with round ticks, polylines, stacked histograms.
#include "report_svg.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <sstream>

#include "web_text.hpp"

namespace c3po::svg {
namespace {

struct Frame {   // plot area inside the SVG, in pixels
  double left = 58, right = 0, top = 28, bottom = 0;
};

std::string Fixed(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f", value);
  return text;
}

class Axes {
 public:
  Axes(const LineChart& chart, const Frame& frame) : c_(chart), f_(frame) {}
  double X(double x) const {
    const double span = c_.x_max - c_.x_min;
    return f_.left + (span > 0 ? (x - c_.x_min) / span : 0.5) * (f_.right - f_.left);
  }
  double Y(double y) const {
    double low = c_.y_min, high = c_.y_max;
    if (c_.log_y) {
      y = std::log10(std::max(y, low));
      low = std::log10(low);
      high = std::log10(high);
    }
    const double span = high - low;
    const double fraction = span > 0 ? (y - low) / span : 0.5;
    return f_.bottom - std::clamp(fraction, 0.0, 1.0) * (f_.bottom - f_.top);
  }

 private:
  const LineChart& c_;
  Frame f_;
};

std::vector<double> LogTicks(double low, double high) {
  std::vector<double> ticks;
  for (double p = std::floor(std::log10(low)); p <= std::ceil(std::log10(high)); p += 1.0) {
    const double value = std::pow(10.0, p);
    if (value >= low * (1 - 1e-9) && value <= high * (1 + 1e-9)) ticks.push_back(value);
  }
  if (ticks.size() < 2) ticks = {low, high};
  return ticks;
}

void DrawAxes(const LineChart& chart, const Frame& f, const Axes& axes, std::ostringstream& out) {
  out << "<rect x=\"" << f.left << "\" y=\"" << f.top << "\" width=\"" << f.right - f.left
      << "\" height=\"" << f.bottom - f.top << "\" fill=\"#fff\" stroke=\"#999\"/>\n";
  for (double x : NiceTicks(chart.x_min, chart.x_max, 6)) {
    out << "<line x1=\"" << Fixed(axes.X(x)) << "\" x2=\"" << Fixed(axes.X(x)) << "\" y1=\"" << f.top
        << "\" y2=\"" << f.bottom << "\" stroke=\"#eee\"/>"
        << "<text x=\"" << Fixed(axes.X(x)) << "\" y=\"" << f.bottom + 14
        << "\" text-anchor=\"middle\">" << ShortNumber(x) << "</text>\n";
  }
  const std::vector<double> y_ticks =
      chart.log_y ? LogTicks(chart.y_min, chart.y_max) : NiceTicks(chart.y_min, chart.y_max, 5);
  for (double y : y_ticks) {
    out << "<line x1=\"" << f.left << "\" x2=\"" << f.right << "\" y1=\"" << Fixed(axes.Y(y))
        << "\" y2=\"" << Fixed(axes.Y(y)) << "\" stroke=\"#eee\"/>"
        << "<text x=\"" << f.left - 4 << "\" y=\"" << Fixed(axes.Y(y) + 4)
        << "\" text-anchor=\"end\">" << ShortNumber(y) << "</text>\n";
  }
  out << "<text x=\"" << (f.left + f.right) / 2 << "\" y=\"" << f.bottom + 30
      << "\" text-anchor=\"middle\">" << web::HtmlEscape(chart.x_label) << "</text>\n";
  out << "<text x=\"12\" y=\"" << (f.top + f.bottom) / 2 << "\" text-anchor=\"middle\" transform=\"rotate(-90 12 "
      << (f.top + f.bottom) / 2 << ")\">" << web::HtmlEscape(chart.y_label) << "</text>\n";
  out << "<text x=\"" << f.left << "\" y=\"16\" font-weight=\"600\">" << web::HtmlEscape(chart.title) << "</text>\n";
}

void DrawMarkers(const std::vector<Marker>& markers, double x_min, double x_max, const Frame& f,
                 const std::function<double(double)>& to_x, std::ostringstream& out) {
  for (const auto& m : markers) {
    if (!(m.x >= x_min && m.x <= x_max)) continue;
    const std::string x = Fixed(to_x(m.x));
    out << "<line x1=\"" << x << "\" x2=\"" << x << "\" y1=\"" << f.top << "\" y2=\"" << f.bottom
        << "\" stroke=\"#c00\" stroke-dasharray=\"4 3\"/>"
        << "<text x=\"" << x << "\" y=\"" << f.top - 3 << "\" text-anchor=\"middle\" fill=\"#c00\">"
        << web::HtmlEscape(m.label) << "</text>\n";
  }
}

void DrawSeries(const LineChart& chart, const Axes& axes, std::ostringstream& out) {
  for (const auto& s : chart.series) {
    std::ostringstream points;
    for (const auto& [x, y] : s.points) {
      if (!std::isfinite(x) || !std::isfinite(y)) continue;
      const double cx = std::clamp(x, chart.x_min, chart.x_max);
      points << Fixed(axes.X(cx)) << "," << Fixed(axes.Y(y)) << " ";
      if (s.markers) {
        out << "<circle cx=\"" << Fixed(axes.X(cx)) << "\" cy=\"" << Fixed(axes.Y(y))
            << "\" r=\"2.5\" fill=\"" << s.colour << "\"/>";
      }
    }
    out << "<polyline fill=\"none\" stroke=\"" << s.colour << "\" stroke-width=\"1.8\""
        << (s.dashed ? " stroke-dasharray=\"6 3\"" : "") << " points=\"" << points.str() << "\">"
        << "<title>" << web::HtmlEscape(s.name) << "</title></polyline>\n";
  }
}

void DrawLegend(const LineChart& chart, const Frame& f, std::ostringstream& out) {
  double y = f.top + 12;
  for (const auto& s : chart.series) {
    out << "<line x1=\"" << f.right + 10 << "\" x2=\"" << f.right + 30 << "\" y1=\"" << y - 4 << "\" y2=\""
        << y - 4 << "\" stroke=\"" << s.colour << "\" stroke-width=\"2\""
        << (s.dashed ? " stroke-dasharray=\"6 3\"" : "") << "/>"
        << "<text x=\"" << f.right + 34 << "\" y=\"" << y << "\">" << web::HtmlEscape(s.name) << "</text>\n";
    y += 16;
  }
}

}  // namespace

std::vector<double> NiceTicks(double low, double high, int count) {
  if (!(high > low) || !std::isfinite(low) || !std::isfinite(high) || count < 1) return {low};
  const double raw = (high - low) / count;
  const double magnitude = std::pow(10.0, std::floor(std::log10(raw)));
  double step = magnitude;
  for (double factor : {1.0, 2.0, 2.5, 5.0, 10.0}) {
    step = factor * magnitude;
    if (step >= raw) break;
  }
  std::vector<double> ticks;
  for (double t = std::ceil(low / step - 1e-9) * step; t <= high + step * 1e-9; t += step) {
    ticks.push_back(std::abs(t) < step * 1e-9 ? 0.0 : t);
  }
  return ticks;
}

std::string ShortNumber(double value) {
  if (!std::isfinite(value)) return std::isnan(value) ? "-" : "inf";
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", value);
  return text;
}

std::string Render(const LineChart& chart) {
  const bool legend = !chart.series.empty();
  Frame f;
  f.right = chart.width - (legend ? 210 : 16);
  f.bottom = chart.height - 40;
  const Axes axes(chart, f);
  std::ostringstream out;
  out << "<svg class=\"chart\" width=\"" << chart.width << "\" height=\""
      << chart.height << "\" viewBox=\"0 0 " << chart.width << " " << chart.height
      << "\" font-size=\"11\" font-family=\"sans-serif\">\n";
  DrawAxes(chart, f, axes, out);
  DrawMarkers(chart.markers, chart.x_min, chart.x_max, f, [&](double x) { return axes.X(x); }, out);
  DrawSeries(chart, axes, out);
  if (legend) DrawLegend(chart, f, out);
  out << "</svg>\n";
  return out.str();
}

std::string Render(const Histogram& h) {
  const int bins = std::max(1, h.bins);
  std::vector<int> first(bins + 1, 0), second(bins + 1, 0);
  auto bin_of = [&](double v) {
    if (!(v < h.x_max)) return bins;   // overflow, +inf and NaN
    return std::clamp(static_cast<int>(std::floor(v / h.x_max * bins)), 0, bins - 1);
  };
  for (double v : h.first) ++first[bin_of(v)];
  for (double v : h.second) ++second[bin_of(v)];
  int tallest = 1;
  for (int b = 0; b <= bins; ++b) tallest = std::max(tallest, first[b] + second[b]);

  Frame f;
  f.left = 34;
  f.right = h.width - 10;
  f.bottom = h.height - 36;
  const double slot = (f.right - f.left) / (bins + 1.5);   // overflow bin after a gap
  auto bar_x = [&](int b) { return f.left + slot * (b + (b == bins ? 0.5 : 0.0)); };
  auto height_of = [&](int count) { return (f.bottom - f.top) * count / tallest; };
  std::ostringstream out;
  out << "<svg class=\"chart histogram\" width=\"" << h.width
      << "\" height=\"" << h.height << "\" viewBox=\"0 0 " << h.width << " " << h.height
      << "\" font-size=\"10\" font-family=\"sans-serif\">\n";
  out << "<text x=\"" << f.left << "\" y=\"14\" font-weight=\"600\">" << web::HtmlEscape(h.title) << "</text>\n";
  out << "<line x1=\"" << f.left << "\" x2=\"" << f.right << "\" y1=\"" << f.bottom << "\" y2=\"" << f.bottom
      << "\" stroke=\"#999\"/>\n";
  for (int b = 0; b <= bins; ++b) {
    const double h1 = height_of(first[b]), h2 = height_of(second[b]);
    const std::string range = b == bins ? ">= " + ShortNumber(h.x_max)
                                        : ShortNumber(h.x_max * b / bins) + " - " + ShortNumber(h.x_max * (b + 1) / bins);
    if (first[b] > 0) {
      out << "<rect x=\"" << Fixed(bar_x(b)) << "\" y=\"" << Fixed(f.bottom - h1) << "\" width=\""
          << Fixed(slot * 0.9) << "\" height=\"" << Fixed(h1) << "\" fill=\"" << h.first_colour << "\"><title>"
          << web::HtmlEscape(h.first_name) << " " << range << ": " << first[b] << "</title></rect>";
    }
    if (second[b] > 0) {
      out << "<rect x=\"" << Fixed(bar_x(b)) << "\" y=\"" << Fixed(f.bottom - h1 - h2) << "\" width=\""
          << Fixed(slot * 0.9) << "\" height=\"" << Fixed(h2) << "\" fill=\"" << h.second_colour << "\"><title>"
          << web::HtmlEscape(h.second_name) << " " << range << ": " << second[b] << "</title></rect>";
    }
  }
  out << "\n<text x=\"" << f.left - 3 << "\" y=\"" << f.top + 8 << "\" text-anchor=\"end\">" << tallest
      << "</text><text x=\"" << f.left - 3 << "\" y=\"" << f.bottom << "\" text-anchor=\"end\">0</text>\n";
  out << "<text x=\"" << f.left << "\" y=\"" << f.bottom + 12 << "\">0</text>"
      << "<text x=\"" << f.right << "\" y=\"" << f.bottom + 12 << "\" text-anchor=\"end\">&gt;=" << ShortNumber(h.x_max)
      << "</text>\n";
  out << "<text x=\"" << (f.left + f.right) / 2 << "\" y=\"" << f.bottom + 26 << "\" text-anchor=\"middle\">"
      << web::HtmlEscape(h.x_label) << "</text>\n";
  DrawMarkers(h.markers, 0.0, h.x_max, f, [&](double x) { return f.left + slot * bins * x / h.x_max; }, out);
  out << "</svg>\n";
  return out.str();
}

}  // namespace c3po::svg
