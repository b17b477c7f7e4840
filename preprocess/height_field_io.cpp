#include "preprocess/height_field_io.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <vector>

#include "runtime/regular_file.h"

#include <unistd.h>

namespace lod {
namespace detail {

inline constexpr double kMaxElevation = 1e9;  // beyond: no data (e.g. an undeclared -3.4e38)

struct Samples {
  std::vector<double> x, y;
  std::vector<float> z;
  std::vector<size_t> line;  // 1-based, for messages
};

struct Axis {
  double origin = 0, step = 0;
  size_t count = 0;
};

std::string at_line(const std::string& name, size_t line) {
  return name + ": line " + std::to_string(line) + ": ";
}

const char* skip_blanks(const char* p, const char* end) {
  while (p < end && (*p == ' ' || *p == '\t' || *p == '\r' || *p == ',')) ++p;
  return p;
}

Status parse_line(std::string_view l, size_t n, const std::string& name, Samples& s) {
  double v[3];
  const char* p = l.data();
  const char* end = l.data() + l.size();
  for (double& x : v) {
    p = skip_blanks(p, end);
    const auto r = std::from_chars(p, end, x);
    if (r.ec != std::errc()) return Status::error(at_line(name, n) + "expected three numbers 'x y z'");
    p = r.ptr;
  }
  if (skip_blanks(p, end) != end) return Status::error(at_line(name, n) + "more than three values");
  for (double x : v)
    if (!std::isfinite(x)) return Status::error(at_line(name, n) + "value is not finite");
  if (std::abs(v[2]) > kMaxElevation)
    return Status::error(at_line(name, n) + "elevation " + std::to_string(v[2]) + " beyond +-1e9");
  s.x.push_back(v[0]), s.y.push_back(v[1]), s.z.push_back(float(v[2])), s.line.push_back(n);
  return Status::success();
}

Status parse_samples(std::string_view text, const std::string& name, Samples& s) {
  size_t n = 0;
  while (!text.empty()) {
    const size_t eol = std::min(text.find('\n'), text.size());
    const std::string_view l = text.substr(0, eol);
    text.remove_prefix(std::min(eol + 1, text.size()));
    ++n;
    const char* first = skip_blanks(l.data(), l.data() + l.size());
    if (first == l.data() + l.size() || *first == '#') continue;
    if (Status st = parse_line(l, n, name, s); !st) return st;
  }
  if (s.z.empty()) return Status::error(name + ": no samples (expected lines 'x y z')");
  return Status::success();
}

// Even spacing of the distinct values: the smallest gap between distinct sorted values is the
// step; the count follows from the range, so a stray value makes a huge (refused) grid, and a
// value between steps is refused when placed.
Status detect_axis(std::vector<double> v, const char* what, const std::string& name, Axis& a) {
  std::sort(v.begin(), v.end());
  const double range = v.back() - v.front();
  const double tiny = 1e-12 * std::max({std::abs(v.front()), std::abs(v.back()), 1.0});
  std::vector<double> gaps;
  for (size_t i = 1; i < v.size(); ++i)
    if (v[i] - v[i - 1] > tiny) gaps.push_back(v[i] - v[i - 1]);
  if (gaps.empty())
    return Status::error(name + ": all samples share one " + what + " value (need a 2-D grid)");
  a.origin = v.front();
  a.step = *std::min_element(gaps.begin(), gaps.end());
  const double count = std::round(range / a.step) + 1;
  a.count = count < 1e18 ? size_t(count) : size_t(-1);
  return Status::success();
}

size_t grid_index(double v, const Axis& a, bool* on_grid) {
  const double i = std::round((v - a.origin) / a.step);
  *on_grid = std::abs(v - (a.origin + i * a.step)) <= 0.01 * a.step;
  return size_t(i);
}

// Every sample to its cell: off-step values and repeated cells are refused; returns the
// per-cell index of the sample, so missing cells show up too.
Status place_samples(const Samples& s, const Axis& ax, const Axis& ay, const std::string& name,
                     std::vector<float>& heights) {
  std::vector<uint8_t> seen(ax.count * ay.count, 0);
  heights.assign(seen.size(), 0.f);
  for (size_t k = 0; k < s.z.size(); ++k) {
    bool okx, oky;
    const size_t i = grid_index(s.x[k], ax, &okx), j = grid_index(s.y[k], ay, &oky);
    if (!okx || !oky)
      return Status::error(at_line(name, s.line[k]) + "not a regular grid: the sample is off the " +
                           (okx ? "y" : "x") + " step of the others");
    const size_t cell = j * ax.count + i;
    if (seen[cell])
      return Status::error(at_line(name, s.line[k]) + "grid point (" + std::to_string(i) + ", " +
                           std::to_string(j) + ") given twice");
    seen[cell] = 1;
    heights[cell] = s.z[k];
  }
  return Status::success();
}

constexpr double kEarthRadius = 6371008.8;  // metres, mean
constexpr double kDegree = 3.14159265358979323846 / 180.0;

void set_cell_sizes(HeightField& f, const Axis& ax, const Axis& ay, GridCoordinates c) {
  if (c == GridCoordinates::metres) {
    f.cell_size_x = float(ax.step), f.cell_size_y = float(ay.step);
    return;
  }
  // x is longitude, y latitude (swapped on reading for degrees_lat_lon).
  const double lat_mid = ay.origin + 0.5 * ay.step * double(ay.count - 1);
  geographic_cell_sizes(ax.step, ay.step, lat_mid, f.cell_size_x, f.cell_size_y);
}

std::string gib(uint64_t bytes) {
  char b[32];
  std::snprintf(b, sizeof b, "%.2f GiB", double(bytes) / double(uint64_t(1) << 30));
  return b;
}

}  // namespace detail

void geographic_cell_sizes(double step_lon, double step_lat, double lat_mid, float& cell_x, float& cell_y) {
  cell_x = float(std::abs(step_lon) * detail::kDegree * detail::kEarthRadius * std::cos(lat_mid * detail::kDegree));
  cell_y = float(std::abs(step_lat) * detail::kDegree * detail::kEarthRadius);
}

uint64_t available_memory_bytes() {
  std::ifstream in("/proc/meminfo");
  std::string key;
  uint64_t kib = 0;
  std::string unit;
  while (in >> key >> kib >> unit)
    if (key == "MemAvailable:") return kib * 1024;
  const long pages = sysconf(_SC_AVPHYS_PAGES), page = sysconf(_SC_PAGESIZE);
  return pages > 0 && page > 0 ? uint64_t(pages) * uint64_t(page) : UINT64_MAX;
}

Status check_height_field_size(const std::string& name, uint64_t width, uint64_t height,
                               const HeightFieldOptions& o, uint64_t bytes_per_sample) {
  const std::string dims = std::to_string(width) + " x " + std::to_string(height);
  if (width < 2 || height < 2) return Status::error(name + ": a " + dims + " grid is too small (need 2 x 2 samples)");
  const double samples = double(width) * double(height);
  if (samples > double(o.max_samples))
    return Status::error(name + ": declares a grid of " + dims + ", more than the limit of " +
                         std::to_string(o.max_samples) + " samples");
  const double need = samples * double(bytes_per_sample);
  const uint64_t have = available_memory_bytes();
  if (need > double(have))
    return Status::error(name + ": a grid of " + dims + " needs " + detail::gib(uint64_t(need)) + ", only " +
                         detail::gib(have) + " of memory is available");
  return Status::success();
}

Status fill_no_data_samples(HeightField& f, double no_data, const std::string& name, size_t* filled) {
  std::vector<uint8_t> missing(f.sample_count());
  size_t holes = 0;
  const bool flag = !std::isnan(no_data);
  for (size_t i = 0; i < missing.size(); ++i)
    holes += missing[i] = !(std::abs(f.heights[i]) <= detail::kMaxElevation) || (flag && f.heights[i] == float(no_data));
  if (filled) *filled = holes;
  if (holes == 0) return Status::success();
  if (fill_missing_heights(f, missing) == 0) return Status::error(name + ": every sample is no-data");
  return Status::success();
}

Status parse_height_field_text(std::string_view text, const std::string& name, HeightField& out,
                               const HeightFieldTextOptions& o) {
  detail::Samples s;
  if (Status st = detail::parse_samples(text, name, s); !st) return st;
  if (o.coordinates == GridCoordinates::degrees_lat_lon) s.x.swap(s.y);
  if (o.coordinates != GridCoordinates::metres)
    for (size_t k = 0; k < s.y.size(); ++k)
      if (std::abs(s.y[k]) > 90.0)
        return Status::error(detail::at_line(name, s.line[k]) +
                             "latitude outside [-90, 90] degrees (check the column order)");
  detail::Axis ax, ay;
  if (Status st = detail::detect_axis(s.x, "x", name, ax); !st) return st;
  if (Status st = detail::detect_axis(s.y, "y", name, ay); !st) return st;
  const double cells = double(ax.count) * double(ay.count);
  if (cells > double(o.max_samples))
    return Status::error(name + ": the samples span a grid of " + std::to_string(ax.count) + " x " +
                         std::to_string(ay.count) + ", more than the limit of " +
                         std::to_string(o.max_samples) + " samples");
  if (Status st = check_height_field_size(name, ax.count, ay.count, o, sizeof(float) + 2); !st) return st;
  if (size_t(cells) != s.z.size())
    return Status::error(name + ": not a regular grid: " + std::to_string(s.z.size()) +
                         " samples for a grid of " + std::to_string(ax.count) + " x " +
                         std::to_string(ay.count) + " (missing or extra points)");
  HeightField f;
  f.width = uint32_t(ax.count), f.height = uint32_t(ay.count);
  f.vertical_scale = o.vertical_scale;
  if (Status st = detail::place_samples(s, ax, ay, name, f.heights); !st) return st;
  detail::set_cell_sizes(f, ax, ay, o.coordinates);
  if (!std::isnan(o.no_data_value))
    if (Status st = fill_no_data_samples(f, o.no_data_value, name); !st) return st;
  out = std::move(f);
  return Status::success();
}

Status read_height_field_text(const std::filesystem::path& path, HeightField& out,
                              const HeightFieldTextOptions& options) {
  const std::string name = path.string();
  if (path.extension() == ".gz")
    return Status::error(name +
                         ": gzip'd text is not read; decompress it first (gzip -dc, or "
                         "scripts/fetch-topography.sh, which writes topography.txt)");
  // A regular file only; text, by its first bytes, before it is read whole.
  RegularFile f;
  if (Status s = open_regular_file(path, kInputFileLimit, f); !s) return s;
  if (Status s = check_text_head(f, "height field"); !s) return s;
  std::vector<uint8_t> bytes;
  if (Status s = f.read_all(bytes); !s) return s;
  return parse_height_field_text(std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()), name, out,
                                 options);
}

}  // namespace lod
