#pragma once
// Inline SVG charts of the evaluation report (no scripts, no external files).
#include <string>
#include <utility>
#include <vector>

namespace c3po::svg {

struct Series {
  std::string name;
  std::string colour;                            // CSS colour
  std::vector<std::pair<double, double>> points; // (x, y), drawn in order
  bool dashed = false;
  bool markers = false;                          // a dot at every point
};

struct Marker {       // a vertical reference line
  double x = 0.0;
  std::string label;
};

struct LineChart {
  std::string title;
  std::string x_label;
  std::string y_label;
  double x_min = 0.0, x_max = 1.0;
  double y_min = 0.0, y_max = 1.0;
  bool log_y = false;                            // y_min must then be > 0
  std::vector<Marker> markers;
  std::vector<Series> series;
  int width = 640;
  int height = 320;
};
std::string Render(const LineChart& chart);

// Stacked histogram of two groups over equal bins on [0, x_max) plus one
// overflow bin ">= x_max" (which also holds +inf).
struct Histogram {
  std::string title;
  std::string x_label;
  double x_max = 1.0;
  int bins = 20;
  std::vector<Marker> markers;
  std::vector<double> first;                     // e.g. certified samples
  std::vector<double> second;                    // e.g. rejected samples
  std::string first_name, second_name;
  std::string first_colour = "#2e8b57", second_colour = "#b0b0b0";
  int width = 320;
  int height = 190;
};
std::string Render(const Histogram& histogram);

// Round tick positions covering [low, high] (about `count` of them).
std::vector<double> NiceTicks(double low, double high, int count);
std::string ShortNumber(double value);          // "0.012", "1.5e-05"

}  // namespace c3po::svg
