// A small SVG line plot: enough for per-frame figures, no plotting dependency.
#pragma once
#include <string>
#include <vector>

namespace lod::cli {

struct PlotSeries {
  std::string name;
  std::string color;            // any SVG colour
  std::vector<double> values;   // one per x step, or one per entry of x
  bool dashed = false;
  std::vector<double> x;        // empty: value i is at x = i; else the x of every value, ascending
};

struct PlotOptions {
  std::string title;
  std::string x_label = "frame";
  std::string y_label;
  bool log_y = false;
  int width = 960, height = 420;
};

std::string svg_line_plot(const std::vector<PlotSeries>& series, const PlotOptions& options);

}  // namespace lod::cli
