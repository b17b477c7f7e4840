// Symmetric Hausdorff approximation by closest-point queries (Embree 3 rtcPointQuery with a
// point-triangle distance callback; closest point on a triangle after Ericson, "Real-Time
// Collision Detection", 5.1.5). Samples: every vertex plus area-weighted random points
// (uniform on each triangle by the square-root parametrisation), seeded, so a measurement
// is reproducible.
#include "preprocess/surface_error.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

namespace lod {
namespace {

struct Vec3 {
  float x, y, z;
};
inline Vec3 operator-(Vec3 a, Vec3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline Vec3 operator+(Vec3 a, Vec3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline Vec3 operator*(Vec3 a, float s) { return {a.x * s, a.y * s, a.z * s}; }
inline float dot(Vec3 a, Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline Vec3 load(const float* p) { return {p[0], p[1], p[2]}; }

Vec3 closest_point_on_triangle(Vec3 p, Vec3 a, Vec3 b, Vec3 c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const float d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Vec3 bp = p - b;
  const float d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const float vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + ab * (d1 / (d1 - d3));
  const Vec3 cp = p - c;
  const float d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const float vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + ac * (d2 / (d2 - d6));
  const float va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  const float denom = va + vb + vc;
  if (!(denom > 0)) {  // degenerate triangle: nearest of its three edges' endpoints is close enough
    const Vec3 q[3] = {a, b, c};
    Vec3 best = a;
    float bd = std::numeric_limits<float>::max();
    for (const Vec3& v : q) {
      const Vec3 d = p - v;
      if (dot(d, d) < bd) bd = dot(d, d), best = v;
    }
    return best;
  }
  const float v = vb / denom, w = vc / denom;
  return a + ab * v + ac * w;
}

// A mesh copied into an Embree scene, plus the arrays the query callback reads.
struct QueryMesh {
  std::vector<float> positions;
  std::vector<uint32_t> indices;
  RTCScene scene = nullptr;
  float slack = 0;  // above float rounding of any distance computed to it (see closest_within)

  ~QueryMesh() { release(); }
  void release() {
    if (scene) rtcReleaseScene(scene);
    scene = nullptr;
  }
};

struct QueryState {
  const QueryMesh* mesh;
  Vec3 point;
  float best_sq;
};

bool closest_point_callback(RTCPointQueryFunctionArguments* args) {
  auto* st = static_cast<QueryState*>(args->userPtr);
  const uint32_t* t = &st->mesh->indices[3 * size_t(args->primID)];
  const float* pos = st->mesh->positions.data();
  const Vec3 q = closest_point_on_triangle(st->point, load(pos + 3 * t[0]), load(pos + 3 * t[1]), load(pos + 3 * t[2]));
  const Vec3 d = st->point - q;
  const float dsq = dot(d, d);
  if (dsq < st->best_sq) {
    st->best_sq = dsq;
    // Not to the distance itself: a triangle within rounding of the nearest is still visited,
    // so the minimum does not depend on the order the BVH visits them in (nor on which BVH).
    args->query->radius = std::sqrt(dsq) * (1 + 1e-5f) + st->mesh->slack;
    return true;  // the query sphere changed
  }
  return false;
}

// Above the rounding of a closest point computed among coordinates this large (a few ulps).
float rounding_slack(const float* positions, size_t floats) {
  float extent = 0;
  for (size_t i = 0; i < floats; ++i) extent = std::max(extent, std::fabs(positions[i]));
  return 1e-6f * extent;
}

std::string device_error_text(RTCDevice device) {
  switch (rtcGetDeviceError(device)) {
    case RTC_ERROR_NONE: return "no error";
    case RTC_ERROR_INVALID_ARGUMENT: return "invalid argument";
    case RTC_ERROR_INVALID_OPERATION: return "invalid operation";
    case RTC_ERROR_OUT_OF_MEMORY: return "out of memory";
    case RTC_ERROR_UNSUPPORTED_CPU: return "unsupported CPU";
    case RTC_ERROR_CANCELLED: return "cancelled";
    default: return "unknown error";
  }
}

Status commit_query_mesh(RTCDevice device, const std::string& what, BvhBuilder builder, QueryMesh& out);

// Triangle f of `whole` into a part, its vertices renumbered in the order the part meets them
// (remap: whole's vertex -> the part's, UINT32_MAX where not yet taken).
void take_triangle(const TriangleMeshView& whole, const uint32_t* f, std::vector<uint32_t>& remap, QueryMesh& part) {
  for (int k = 0; k < 3; ++k) {
    uint32_t& v = remap[f[k]];
    if (v == UINT32_MAX) {
      v = uint32_t(part.positions.size() / 3);
      part.positions.insert(part.positions.end(), whole.positions + 3 * size_t(f[k]), whole.positions + 3 * size_t(f[k]) + 3);
    }
    part.indices.push_back(v);
  }
}

Status build_query_mesh(RTCDevice device, const TriangleMeshView& view, const std::string& what, QueryMesh& out,
                        BvhBuilder builder = BvhBuilder::sah) {
  out.release();
  if (view.index_count % 3 != 0 || view.index_count == 0)
    return Status::error(what + ": no triangles to measure against");
  for (size_t i = 0; i < view.index_count; ++i)
    if (view.indices[i] >= view.vertex_count)
      return Status::error(what + ": triangle " + std::to_string(i / 3) + " references vertex " +
                           std::to_string(view.indices[i]) + " of " + std::to_string(view.vertex_count));
  out.positions.reserve(3 * view.vertex_count + 1);
  out.positions.assign(view.positions, view.positions + 3 * view.vertex_count);
  out.indices.assign(view.indices, view.indices + view.index_count);
  out.slack = rounding_slack(view.positions, 3 * view.vertex_count);
  return commit_query_mesh(device, what, builder, out);
}

// out's arrays into an Embree scene, shared rather than copied (out keeps them while the scene
// lives): a vertex buffer is read 16 bytes at a time, so one float of padding follows the last.
Status commit_query_mesh(RTCDevice device, const std::string& what, BvhBuilder builder, QueryMesh& out) {
  const size_t vertex_count = out.positions.size() / 3, index_count = out.indices.size();
  out.positions.resize(3 * vertex_count + 1, 0.0f);
  RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
  if (!geom) return Status::error(what + ": Embree could not create a geometry (" + device_error_text(device) + ")");
  rtcSetSharedGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, out.positions.data(), 0,
                             3 * sizeof(float), vertex_count);
  rtcSetSharedGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, out.indices.data(), 0,
                             3 * sizeof(uint32_t), index_count / 3);
  // Morton: Embree picks its Morton-code builder only for a low-quality geometry in a dynamic,
  // low-quality scene.
  const bool morton = builder == BvhBuilder::morton;
  if (morton) rtcSetGeometryBuildQuality(geom, RTC_BUILD_QUALITY_LOW);
  rtcCommitGeometry(geom);
  out.scene = rtcNewScene(device);
  // Compact: half the BVH's memory, and on a 14M-triangle original a quarter less build time
  // (memory-bound) at the same query speed (bench_mesh_input); the answers never depend on it.
  rtcSetSceneFlags(out.scene, RTCSceneFlags(RTC_SCENE_FLAG_ROBUST | RTC_SCENE_FLAG_COMPACT |
                                            (morton ? RTC_SCENE_FLAG_DYNAMIC : RTC_SCENE_FLAG_NONE)));
  if (morton) rtcSetSceneBuildQuality(out.scene, RTC_BUILD_QUALITY_LOW);
  rtcAttachGeometry(out.scene, geom);
  rtcReleaseGeometry(geom);
  rtcCommitScene(out.scene);
  if (rtcGetDeviceError(device) != RTC_ERROR_NONE)
    return Status::error(what + ": Embree failed to build its BVH (" + device_error_text(device) + ")");
  return Status::success();
}

// Every vertex some triangle uses (an unused one is not on the surface: at distance 0 it would
// only dilute the RMS), then `count` area-weighted surface points.
std::vector<float> sample_surface(const TriangleMeshView& view, size_t count, uint64_t seed) {
  std::vector<uint8_t> used(view.vertex_count, 0);
  for (size_t i = 0; i < view.index_count; ++i) used[view.indices[i]] = 1;
  std::vector<float> samples;
  samples.reserve(3 * view.vertex_count);
  for (size_t v = 0; v < view.vertex_count; ++v)
    if (used[v]) samples.insert(samples.end(), view.positions + 3 * v, view.positions + 3 * v + 3);
  const size_t nt = view.index_count / 3;
  std::vector<double> cumulative(nt);
  double total = 0;
  for (size_t t = 0; t < nt; ++t) {
    const Vec3 a = load(view.positions + 3 * view.indices[3 * t]);
    const Vec3 b = load(view.positions + 3 * view.indices[3 * t + 1]);
    const Vec3 c = load(view.positions + 3 * view.indices[3 * t + 2]);
    const Vec3 e0 = b - a, e1 = c - a;
    const double cx = double(e0.y) * e1.z - double(e0.z) * e1.y;
    const double cy = double(e0.z) * e1.x - double(e0.x) * e1.z;
    const double cz = double(e0.x) * e1.y - double(e0.y) * e1.x;
    total += 0.5 * std::sqrt(cx * cx + cy * cy + cz * cz);
    cumulative[t] = total;
  }
  if (!(total > 0)) return samples;
  std::mt19937_64 rng(seed);
  auto uniform = [&rng] { return double(rng() >> 11) * 0x1.0p-53; };  // same on every platform
  samples.reserve(samples.size() + 3 * count);
  // Sorted picks visit triangles in mesh order, so consecutive samples are near each other
  // (see the radius bound in query_distances).
  std::vector<double> picks(count);
  for (double& pick : picks) pick = uniform() * total;
  std::sort(picks.begin(), picks.end());
  for (size_t i = 0; i < count; ++i) {
    const double pick = picks[i];
    const size_t t = std::min<size_t>(nt - 1, size_t(std::upper_bound(cumulative.begin(), cumulative.end(), pick) -
                                                     cumulative.begin()));
    const double r1 = std::sqrt(uniform()), r2 = uniform();
    const float wa = float(1 - r1), wb = float(r1 * (1 - r2)), wc = float(r1 * r2);
    const Vec3 a = load(view.positions + 3 * view.indices[3 * t]);
    const Vec3 b = load(view.positions + 3 * view.indices[3 * t + 1]);
    const Vec3 c = load(view.positions + 3 * view.indices[3 * t + 2]);
    const Vec3 p = a * wa + b * wb + c * wc;
    samples.insert(samples.end(), {p.x, p.y, p.z});
  }
  return samples;
}

constexpr float kInf = std::numeric_limits<float>::infinity();

// The nearest distance from p to `mesh` among the triangles a query of `radius` visits (+inf
// when none). When the true nearest lies within the radius, that is the least distance computed
// to any triangle of the mesh, whatever its BVH: the sphere never shrinks below the nearest plus
// the rounding slack (closest_point_callback).
double closest_within(const QueryMesh& mesh, Vec3 p, float radius, RTCPointQueryContext& context) {
  QueryState st{&mesh, p, kInf};
  RTCPointQuery q;
  q.x = p.x;
  q.y = p.y;
  q.z = p.z;
  q.time = 0;
  q.radius = radius;
  rtcPointQuery(mesh.scene, &q, &context, closest_point_callback, &st);
  return st.best_sq == kInf ? double(kInf) : std::sqrt(double(st.best_sq));
}

// Triangle inequality: the surface is no farther than the previous sample's distance plus the
// step between the samples (or the caller's own bound, when tighter). Starting the query with
// that radius prunes most of the BVH; the margins cover float rounding.
float start_radius(Vec3 p, Vec3 prev, double prev_d, const float* known, size_t i, float slack) {
  const Vec3 step = p - prev;
  double bound = prev_d + std::sqrt(double(dot(step, step)));
  if (known) bound = std::min(bound, double(known[i]));
  return float(bound * 1.0001 + 1e-12) + slack;
}

// One sample's distance as every query on a whole surface makes it: within the start radius,
// then open when nothing was found there.
double sample_distance(const QueryMesh& mesh, Vec3 p, float radius, RTCPointQueryContext& context) {
  const double d = closest_within(mesh, p, radius, context);
  return d == double(kInf) ? closest_within(mesh, p, kInf, context) : d;
}

// Distances from every sample to `mesh`: updates max and the sum of squares.
void query_distances(const float* samples, size_t sample_floats, const float* known, const QueryMesh& mesh,
                     double& max_d, double& sum_sq, size_t& n) {
  RTCPointQueryContext context;
  rtcInitPointQueryContext(&context);
  Vec3 prev{0, 0, 0};
  double prev_d = kInf;
  for (size_t i = 0; i + 2 < sample_floats; i += 3) {
    const Vec3 p = load(&samples[i]);
    // known 0: a point of the surface itself, nothing to look up
    const double d = known && known[i / 3] == 0
                         ? 0.0
                         : sample_distance(mesh, p, start_radius(p, prev, prev_d, known, i / 3, mesh.slack), context);
    prev = p;
    prev_d = d;
    max_d = std::max(max_d, d);
    sum_sq += d * d;
    ++n;
  }
}

}  // namespace

struct SurfaceErrorMeter::Impl {
  RTCDevice device = nullptr;
  QueryMesh reference;
  std::vector<float> reference_samples;
  SurfaceErrorSettings settings;
  std::string what;
  bool ready = false;

  ~Impl() {
    reference.release();
    if (device) rtcReleaseDevice(device);
  }
};

SurfaceErrorMeter::SurfaceErrorMeter() : impl_(std::make_unique<Impl>()) {}
SurfaceErrorMeter::~SurfaceErrorMeter() = default;

Status SurfaceErrorMeter::set_reference(const TriangleMeshView& reference, const SurfaceErrorSettings& settings,
                                        const std::string& what) {
  Impl& m = *impl_;
  m.ready = false;
  m.settings = settings;
  m.what = what;
  if (!m.device) {
    m.device = rtcNewDevice(nullptr);
    if (!m.device) return Status::error(what + ": Embree device could not be created");
  }
  Status s = build_query_mesh(m.device, reference, what, m.reference);
  if (!s) return s;
  m.reference_samples = sample_surface(reference, settings.surface_samples, settings.seed);
  m.ready = true;
  return Status::success();
}

Status SurfaceErrorMeter::measure(const TriangleMeshView& mesh, SurfaceError& out) {
  Impl& m = *impl_;
  if (!m.ready) return Status::error("surface error: no reference set");
  QueryMesh other;
  Status s = build_query_mesh(m.device, mesh, m.what + " (level)", other);
  if (!s) return s;
  const std::vector<float> samples = sample_surface(mesh, m.settings.surface_samples, m.settings.seed + 1);
  double max_d = 0, sum_sq = 0;
  size_t n = 0;
  query_distances(samples.data(), samples.size(), nullptr, m.reference, max_d, sum_sq, n);
  query_distances(m.reference_samples.data(), m.reference_samples.size(), nullptr, other, max_d, sum_sq, n);
  if (rtcGetDeviceError(m.device) != RTC_ERROR_NONE)
    return Status::error(m.what + ": Embree point query failed (" + device_error_text(m.device) + ")");
  out.max = float(max_d);
  out.rms = n ? float(std::sqrt(sum_sq / double(n))) : 0.0f;
  out.samples = n;
  return Status::success();
}

uint32_t SurfaceGrid::cell(float x, int axis) const {
  const float t = (x - lo[axis]) * (float(n) / edge);  // monotonic in x, so is the cell
  if (!(t > 0)) return 0;                               // below, or NaN
  return t >= float(n) ? n - 1 : std::min(n - 1, uint32_t(t));
}

namespace {

// A box's cells: [lo, hi] per axis, inclusive.
struct CellRange {
  uint32_t lo[3], hi[3];
  size_t count() const { return size_t(hi[0] - lo[0] + 1) * (hi[1] - lo[1] + 1) * (hi[2] - lo[2] + 1); }
  template <class F>
  bool all(const SurfaceGrid& g, F&& f) const {  // f(cell index) true for every cell
    for (uint32_t z = lo[2]; z <= hi[2]; ++z)
      for (uint32_t y = lo[1]; y <= hi[1]; ++y)
        for (uint32_t x = lo[0]; x <= hi[0]; ++x)
          if (!f((size_t(z) * g.n + y) * g.n + x)) return false;
    return true;
  }
};

CellRange cells_of_box(const SurfaceGrid& g, const float* lo, const float* hi) {
  CellRange r;
  for (int k = 0; k < 3; ++k) r.lo[k] = g.cell(lo[k], k), r.hi[k] = g.cell(hi[k], k);
  return r;
}

// A triangle spanning more cells than this stays in every part (bounds the cost of huge ones).
constexpr size_t kPartSpanCells = 4096;
// Cells per axis a part's grid may have: a cell coordinate fits 16 bits (and the flags memory).
constexpr uint32_t kMaxGridCells = 65535;

// Per vertex, the index of its cell (x fastest), once per vertex instead of once per use: a
// triangle whose three agree lies in that cell. The cell is monotonic in the coordinate, so a
// triangle's box's cells are its vertices' least and greatest on each axis (cells_of_triangle).
std::vector<uint32_t> vertex_cells(const TriangleMeshView& mesh, const SurfaceGrid& g) {
  std::vector<uint32_t> cells(mesh.vertex_count);
  for (size_t v = 0; v < mesh.vertex_count; ++v) {
    const float* p = mesh.positions + 3 * v;
    cells[v] = (g.cell(p[2], 2) * g.n + g.cell(p[1], 1)) * g.n + g.cell(p[0], 0);
  }
  return cells;
}

CellRange cells_of_triangle(const TriangleMeshView& mesh, const SurfaceGrid& g, const uint32_t* f) {
  CellRange r;
  for (int k = 0; k < 3; ++k) {
    const uint32_t a = g.cell(mesh.positions[3 * size_t(f[0]) + k], k), b = g.cell(mesh.positions[3 * size_t(f[1]) + k], k),
                   c = g.cell(mesh.positions[3 * size_t(f[2]) + k], k);
    r.lo[k] = std::min({a, b, c}), r.hi[k] = std::max({a, b, c});
  }
  return r;
}

}  // namespace

struct SurfaceDistance::Impl {
  RTCDevice device = nullptr;
  BvhBuilder builder = BvhBuilder::morton;
  QueryMesh surface;
  std::string what;
  bool ready = false;
  bool part = false;
  size_t triangles = 0;
  SurfaceGrid grid;
  std::vector<uint8_t> complete;  // a part's: per cell, no triangle outside the part reaches in
  bool planned = false;           // a planned part: the cells of `box` are complete, no others
  CellRange box{};

  bool holds_cells(const CellRange& r) const {
    if (planned)
      return r.lo[0] >= box.lo[0] && r.lo[1] >= box.lo[1] && r.lo[2] >= box.lo[2] && r.hi[0] <= box.hi[0] &&
             r.hi[1] <= box.hi[1] && r.hi[2] <= box.hi[2];
    return r.all(grid, [&](size_t c) { return complete[c] != 0; });
  }
  // Whether every triangle of the whole surface within `radius` of p is in the part: each one
  // reaches into a cell the ball's box reaches into (cells are monotonic in the coordinate).
  bool holds_ball(Vec3 p, double radius) const {
    const float r = float(radius);
    const float lo[3] = {p.x - r, p.y - r, p.z - r}, hi[3] = {p.x + r, p.y + r, p.z + r};
    return holds_cells(cells_of_box(grid, lo, hi));
  }

  Status ensure_device() {  // `what` set already
    if (!device) device = rtcNewDevice(nullptr);
    return device ? Status::success() : Status::error(what + ": Embree device could not be created");
  }

  ~Impl() {
    surface.release();
    if (device) rtcReleaseDevice(device);
  }
};

SurfaceDistance::SurfaceDistance(BvhBuilder builder) : impl_(std::make_unique<Impl>()) { impl_->builder = builder; }
SurfaceDistance::~SurfaceDistance() = default;

Status SurfaceDistance::set_surface(const TriangleMeshView& surface, const std::string& what) {
  Impl& m = *impl_;
  m.ready = false;
  m.what = what;
  if (Status s = m.ensure_device(); !s) return s;
  if (Status s = build_query_mesh(m.device, surface, what, m.surface, m.builder); !s) return s;
  m.part = false;
  m.triangles = surface.index_count / 3;
  m.ready = true;
  return Status::success();
}

Status SurfaceDistance::set_surface_part(const TriangleMeshView& whole, const SurfaceGrid& grid,
                                         const std::vector<uint8_t>& wanted, const std::string& what) {
  Impl& m = *impl_;
  m.ready = false;
  m.what = what;
  m.surface.release();
  if (whole.index_count % 3 != 0 || grid.n == 0 || grid.n > kMaxGridCells || wanted.size() != grid.cells() ||
      grid.cells() > UINT32_MAX)
    return Status::error(what + ": a surface part needs whole triangles and one flag per grid cell (at most 2^32)");
  for (size_t i = 0; i < whole.index_count; ++i)
    if (whole.indices[i] >= whole.vertex_count)
      return Status::error(what + ": triangle " + std::to_string(i / 3) + " references vertex " +
                           std::to_string(whole.indices[i]) + " of " + std::to_string(whole.vertex_count));
  if (Status s = m.ensure_device(); !s) return s;
  // A triangle is kept when its box reaches into a wanted cell; otherwise every cell its box
  // reaches into is incomplete.
  m.grid = grid;
  m.planned = false;
  m.complete.assign(grid.cells(), 1);
  const std::vector<uint32_t> cells = vertex_cells(whole, grid);
  std::vector<uint32_t> remap(whole.vertex_count, UINT32_MAX);
  QueryMesh& part = m.surface;
  part.positions.clear();
  part.indices.clear();
  // Address space only: the pages a smaller part never touches are never committed.
  part.positions.reserve(3 * whole.vertex_count + 1);
  part.indices.reserve(whole.index_count);
  for (size_t t = 0; t < whole.index_count / 3; ++t) {
    const uint32_t* f = whole.indices + 3 * t;
    const uint32_t cell = cells[f[0]];
    if (cell == cells[f[1]] && cell == cells[f[2]]) {  // most triangles: one cell, one flag
      if (!wanted[cell]) {
        m.complete[cell] = 0;
        continue;
      }
    } else if (const CellRange range = cells_of_triangle(whole, grid, f);
               range.count() <= kPartSpanCells && range.all(grid, [&](size_t c) { return wanted[c] == 0; })) {
      range.all(grid, [&](size_t c) { return m.complete[c] = 0, true; });
      continue;
    }
    take_triangle(whole, f, remap, part);
  }
  // The whole surface's slack, so that start radii and sphere updates are the whole's.
  part.slack = rounding_slack(whole.positions, 3 * whole.vertex_count);
  m.part = true;
  m.triangles = part.indices.size() / 3;
  if (m.triangles > 0)
    if (Status s = commit_query_mesh(m.device, what, m.builder, part); !s) return s;
  m.ready = true;
  return Status::success();
}

size_t SurfaceDistance::triangles() const { return impl_->triangles; }
bool SurfaceDistance::ready() const { return impl_->ready; }

bool SurfaceDistance::holds(const float* p) const {
  const Impl& m = *impl_;
  if (!m.part) return m.ready;
  const float q[3] = {p[0], p[1], p[2]};
  return m.holds_cells(cells_of_box(m.grid, q, q));
}

namespace {
SurfaceError distance_summary(double max_d, double sum_sq, size_t n) {
  SurfaceError e;
  e.max = float(max_d);
  e.rms = n ? float(std::sqrt(sum_sq / double(n))) : 0.0f;
  e.samples = n;
  return e;
}
}  // namespace

namespace {

bool meet(const CellRange& a, const CellRange& b) {
  for (int k = 0; k < 3; ++k)
    if (a.hi[k] < b.lo[k] || b.hi[k] < a.lo[k]) return false;
  return true;
}

// Boxes by blocks of cells (about 32 per axis), so that a triangle is tested against the few
// boxes near it rather than every one: per block, the boxes meeting it (offsets, ids).
struct BoxBlocks {
  uint32_t size = 1, per_axis = 1;
  std::vector<uint32_t> offsets, ids;

  BoxBlocks(const SurfaceGrid& g, const std::vector<CellRange>& boxes)
      : size((g.n + 31) / 32), per_axis((g.n + size - 1) / size) {
    const size_t blocks = size_t(per_axis) * per_axis * per_axis;
    offsets.assign(blocks + 1, 0);
    for_blocks(boxes, [&](size_t b, uint32_t) { ++offsets[b + 1]; });
    for (size_t b = 0; b < blocks; ++b) offsets[b + 1] += offsets[b];
    ids.resize(offsets[blocks]);
    std::vector<uint32_t> at(offsets.begin(), offsets.end() - 1);
    for_blocks(boxes, [&](size_t b, uint32_t i) { ids[at[b]++] = i; });
  }
  CellRange blocks_of(const CellRange& r) const {
    CellRange b;
    for (int k = 0; k < 3; ++k) b.lo[k] = r.lo[k] / size, b.hi[k] = r.hi[k] / size;
    return b;
  }
  template <class F>
  void for_blocks(const std::vector<CellRange>& boxes, F&& f) const {
    const SurfaceGrid blocks = block_grid();
    for (uint32_t i = 0; i < boxes.size(); ++i) blocks_of(boxes[i]).all(blocks, [&](size_t b) { return f(b, i), true; });
  }
  SurfaceGrid block_grid() const {
    SurfaceGrid g;
    g.n = per_axis;
    return g;
  }
};

}  // namespace

Status plan_surface_parts(const TriangleMeshView& whole, const SurfaceGrid& grid, std::vector<SurfaceBox> boxes,
                          SurfacePartPlan& out, const std::string& what) {
  if (whole.index_count % 3 != 0 || grid.n == 0 || grid.n > kMaxGridCells || boxes.size() > UINT32_MAX)
    return Status::error(what + ": surface parts need whole triangles and a grid of at most " +
                         std::to_string(kMaxGridCells) + " cells per axis");
  for (size_t i = 0; i < whole.index_count; ++i)
    if (whole.indices[i] >= whole.vertex_count)
      return Status::error(what + ": triangle " + std::to_string(i / 3) + " references vertex " +
                           std::to_string(whole.indices[i]) + " of " + std::to_string(whole.vertex_count));
  std::vector<CellRange> ranges;
  for (const SurfaceBox& b : boxes) ranges.push_back(cells_of_box(grid, b.lo, b.hi));
  const BoxBlocks blocks(grid, ranges);
  const SurfaceGrid block_grid = blocks.block_grid();
  std::vector<std::vector<uint32_t>> lists(boxes.size());
  for (uint32_t t = 0; t < whole.index_count / 3; ++t) {
    const CellRange r = cells_of_triangle(whole, grid, whole.indices + 3 * size_t(t));
    blocks.blocks_of(r).all(block_grid, [&](size_t b) {
      for (uint32_t k = blocks.offsets[b]; k < blocks.offsets[b + 1]; ++k) {
        std::vector<uint32_t>& list = lists[blocks.ids[k]];
        if (meet(r, ranges[blocks.ids[k]]) && (list.empty() || list.back() != t)) list.push_back(t);
      }
      return true;
    });
  }
  out.grid = grid;
  out.slack = rounding_slack(whole.positions, 3 * whole.vertex_count);
  out.vertex_count = whole.vertex_count;
  out.triangle_count = whole.index_count / 3;
  out.boxes = std::move(boxes);
  out.triangles = std::move(lists);
  return Status::success();
}

Status SurfaceDistance::set_surface_planned(const TriangleMeshView& whole, const SurfacePartPlan& plan, size_t box,
                                            std::vector<uint32_t>& remap, const std::string& what) {
  Impl& m = *impl_;
  m.ready = false;
  m.what = what;
  m.surface.release();
  if (box >= plan.boxes.size() || plan.vertex_count != whole.vertex_count || plan.triangle_count != whole.index_count / 3)
    return Status::error(what + ": no such part in a plan made over this surface");
  if (remap.empty()) remap.assign(whole.vertex_count, UINT32_MAX);
  if (remap.size() != whole.vertex_count) return Status::error(what + ": vertex scratch of another surface");
  if (Status s = m.ensure_device(); !s) return s;
  QueryMesh& part = m.surface;
  part.positions.clear();
  part.indices.clear();
  const std::vector<uint32_t>& list = plan.triangles[box];
  for (uint32_t t : list)
    if (t >= plan.triangle_count) return Status::error(what + ": the plan lists a triangle the surface lacks");
  part.indices.reserve(3 * list.size());
  for (uint32_t t : list) take_triangle(whole, whole.indices + 3 * size_t(t), remap, part);  // checked when planned
  for (uint32_t t : list)
    for (int k = 0; k < 3; ++k) remap[whole.indices[3 * size_t(t) + k]] = UINT32_MAX;
  part.slack = plan.slack;
  m.grid = plan.grid;
  m.part = m.planned = true;
  m.box = cells_of_box(plan.grid, plan.boxes[box].lo, plan.boxes[box].hi);
  m.complete.clear();
  m.triangles = list.size();
  if (m.triangles > 0)
    if (Status s = commit_query_mesh(m.device, what, m.builder, part); !s) return s;
  m.ready = true;
  return Status::success();
}

Status SurfaceDistance::from_points(const float* points, size_t count, const float* known, SurfaceError& out) const {
  const Impl& m = *impl_;
  if (!m.ready) return Status::error("surface distance: no surface set");
  double max_d = 0, sum_sq = 0;
  size_t n = 0;
  query_distances(points, 3 * count, known, m.surface, max_d, sum_sq, n);
  out = distance_summary(max_d, sum_sq, n);
  return Status::success();
}

Status SurfaceDistance::from_points_to(const TriangleMeshView& mesh, const float* points, size_t count,
                                       const float* known, SurfaceError& out) const {
  const Impl& m = *impl_;
  if (!m.ready) return Status::error("surface distance: no surface set");
  QueryMesh other;
  if (Status s = build_query_mesh(m.device, mesh, m.what + " (layer)", other); !s) return s;
  double max_d = 0, sum_sq = 0;
  size_t n = 0;
  query_distances(points, 3 * count, known, other, max_d, sum_sq, n);
  out = distance_summary(max_d, sum_sq, n);
  return Status::success();
}

Status SurfaceDistance::from_points_part(const float* points, size_t count, const float* known,
                                         const std::function<const SurfaceDistance*()>& whole, SurfaceError& out,
                                         std::vector<uint8_t>* answered) const {
  const Impl& m = *impl_;
  if (!m.ready) return Status::error("surface distance: no surface set");
  if (answered) answered->assign(count, m.part ? 0 : 1);
  if (!m.part) return from_points(points, count, known, out);
  RTCPointQueryContext context;
  rtcInitPointQueryContext(&context);
  const float slack = m.surface.slack;
  Vec3 prev{0, 0, 0};
  double prev_d = kInf, max_d = 0, sum_sq = 0;
  size_t n = 0;
  for (size_t i = 0; i < count; ++i) {
    const Vec3 p = load(points + 3 * i);
    double d = 0;
    if (!(known && known[i] == 0)) {
      const float radius = start_radius(p, prev, prev_d, known, i, slack);
      d = m.triangles ? closest_within(m.surface, p, radius, context) : double(kInf);
      // Found within the start radius, rounding included (so the whole's query visits its
      // nearest too), and every triangle as near as it held here: the whole's answer.
      const bool mine = d + 0.5 * slack <= double(radius) && m.holds_ball(p, d * (1 + 1e-4) + 4.0 * slack);
      if (!mine) {
        const SurfaceDistance* w = whole ? whole() : nullptr;
        if (whole && !w) return Status::error(m.what + ": the whole surface could not be built");
        if (!w) continue;  // unanswered: the caller asks elsewhere
        d = sample_distance(w->impl_->surface, p, radius, context);
      }
    }
    if (answered) (*answered)[i] = 1;
    prev = p;
    prev_d = d;
    max_d = std::max(max_d, d);
    sum_sq += d * d;
    ++n;
  }
  out = distance_summary(max_d, sum_sq, n);
  return Status::success();
}

Status measure_surface_error(const TriangleMeshView& a, const TriangleMeshView& b,
                             const SurfaceErrorSettings& settings, SurfaceError& out) {
  SurfaceErrorMeter meter;
  Status s = meter.set_reference(a, settings, "surface error reference");
  if (!s) return s;
  return meter.measure(b, out);
}

}  // namespace lod
