#include "cli/svg_plot.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <sstream>

namespace lod::cli {
namespace {

std::string format_tick(double v) {
  char buf[32];
  const double a = std::fabs(v);
  if (a >= 1e9) std::snprintf(buf, sizeof buf, "%.3gG", v / 1e9);
  else if (a >= 1e6) std::snprintf(buf, sizeof buf, "%.3gM", v / 1e6);
  else if (a >= 1e3) std::snprintf(buf, sizeof buf, "%.3gk", v / 1e3);
  else std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

std::string escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '<') out += "&lt;";
    else if (c == '>') out += "&gt;";
    else if (c == '&') out += "&amp;";
    else out += c;
  }
  return out;
}

}  // namespace

std::string svg_line_plot(const std::vector<PlotSeries>& series, const PlotOptions& opt) {
  const double left = 80, right = 180, top = 40, bottom = 50;
  const double pw = opt.width - left - right, ph = opt.height - top - bottom;
  // The x range: 0 to the last x of any series (a series without x has x = 0, 1, 2, ...).
  double x_hi = 0;
  auto x_of = [](const PlotSeries& s, size_t i) { return s.x.empty() ? double(i) : s.x[i]; };
  double lo = INFINITY, hi = -INFINITY;
  for (const auto& s : series) {
    if (!s.values.empty()) x_hi = std::max(x_hi, x_of(s, s.values.size() - 1));
    for (double v : s.values) {
      if (!std::isfinite(v) || (opt.log_y && v <= 0)) continue;
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
  }
  if (!(lo <= hi)) lo = opt.log_y ? 1 : 0, hi = opt.log_y ? 10 : 1;  // nothing to draw (no frames): an empty frame
  if (opt.log_y) {
    lo = std::pow(10.0, std::floor(std::log10(lo)));
    hi = std::pow(10.0, std::ceil(std::log10(hi)));
    if (hi <= lo) hi = lo * 10;
  } else {
    lo = std::min(lo, 0.0);
    if (hi <= lo) hi = lo + 1;
    hi *= 1.05;
  }
  auto ymap = [&](double v) {
    const double t = opt.log_y ? (std::log10(std::max(v, lo)) - std::log10(lo)) / (std::log10(hi) - std::log10(lo))
                               : (v - lo) / (hi - lo);
    return top + ph * (1 - t);
  };
  auto xmap = [&](double x) { return left + (x_hi > 0 ? pw * x / x_hi : 0); };

  std::ostringstream o;
  o << "<svg xmlns='http://www.w3.org/2000/svg' width='" << opt.width << "' height='" << opt.height
    << "' font-family='sans-serif' font-size='12'>\n";
  o << "<rect width='100%' height='100%' fill='white'/>\n";
  o << "<text x='" << left << "' y='24' font-size='15' font-weight='bold'>" << escape(opt.title) << "</text>\n";
  o << "<rect x='" << left << "' y='" << top << "' width='" << pw << "' height='" << ph
    << "' fill='none' stroke='#888'/>\n";
  // Y grid and ticks.
  std::vector<double> ticks;
  if (opt.log_y) {
    for (double t = lo; t <= hi * 1.0001; t *= 10) ticks.push_back(t);
  } else {
    for (int i = 0; i <= 5; ++i) ticks.push_back(lo + (hi - lo) * i / 5);
  }
  for (double t : ticks) {
    const double y = ymap(t);
    o << "<line x1='" << left << "' x2='" << left + pw << "' y1='" << y << "' y2='" << y
      << "' stroke='#ddd'/><text x='" << left - 6 << "' y='" << y + 4 << "' text-anchor='end'>" << format_tick(t)
      << "</text>\n";
  }
  for (int i = 0; i <= 6 && x_hi > 0; ++i) {
    const uint64_t at = uint64_t(x_hi) * uint64_t(i) / 6;
    o << "<text x='" << xmap(double(at)) << "' y='" << top + ph + 18 << "' text-anchor='middle'>" << at << "</text>\n";
  }
  o << "<text x='" << left + pw / 2 << "' y='" << opt.height - 10 << "' text-anchor='middle'>" << escape(opt.x_label)
    << "</text>\n";
  o << "<text transform='translate(18," << top + ph / 2 << ") rotate(-90)' text-anchor='middle'>"
    << escape(opt.y_label) << "</text>\n";
  for (size_t k = 0; k < series.size(); ++k) {
    const auto& s = series[k];
    o << "<polyline fill='none' stroke='" << s.color << "' stroke-width='1.6'"
      << (s.dashed ? " stroke-dasharray='6,4'" : "") << " points='";
    for (size_t i = 0; i < s.values.size(); ++i) {
      if (!std::isfinite(s.values[i])) continue;
      o << xmap(x_of(s, i)) << "," << ymap(s.values[i]) << " ";
    }
    o << "'/>\n";
    const double ly = top + 14 + 20.0 * double(k);
    o << "<line x1='" << left + pw + 12 << "' x2='" << left + pw + 36 << "' y1='" << ly - 4 << "' y2='" << ly - 4
      << "' stroke='" << s.color << "' stroke-width='2'" << (s.dashed ? " stroke-dasharray='6,4'" : "")
      << "/><text x='" << left + pw + 42 << "' y='" << ly << "'>" << escape(s.name) << "</text>\n";
  }
  o << "</svg>\n";
  return o.str();
}

}  // namespace lod::cli
