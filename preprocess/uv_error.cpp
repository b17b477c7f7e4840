// Texture-coordinate error by closest-point queries (Embree 3 rtcPointQuery): sample_level
// (vertices + area-weighted points with their interpolated uvs) -> closest_distance (query
// sphere shrinking to the nearest triangle) -> nearest_uv (every triangle within that distance
// plus the tie tolerance: the uv at its closest point, the smallest texel distance kept).
// Closest point with barycentric weights after Ericson, "Real-Time Collision Detection", 5.1.5.
#include "preprocess/uv_error.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

namespace lod {
namespace {

struct V3 {
  double x, y, z;
};
V3 operator-(V3 a, V3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
double dot(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
V3 load3(const float* p) { return {p[0], p[1], p[2]}; }

// Weights (wa, wb, wc) of the point of triangle abc closest to p.
void closest_weights(V3 p, V3 a, V3 b, V3 c, double w[3]) {
  const V3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  auto set = [&](double x, double y, double z) { w[0] = x, w[1] = y, w[2] = z; };
  if (d1 <= 0 && d2 <= 0) return set(1, 0, 0);
  const V3 bp = p - b;
  const double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return set(0, 1, 0);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    const double t = d1 / (d1 - d3);
    return set(1 - t, t, 0);
  }
  const V3 cp = p - c;
  const double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return set(0, 0, 1);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    const double t = d2 / (d2 - d6);
    return set(1 - t, 0, t);
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    const double t = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return set(0, 1 - t, t);
  }
  const double denom = va + vb + vc;
  if (!(denom > 0)) {  // degenerate: its nearest corner
    const double da = dot(p - a, p - a), db = dot(p - b, p - b), dc = dot(p - c, p - c);
    return da <= db && da <= dc ? set(1, 0, 0) : db <= dc ? set(0, 1, 0) : set(0, 0, 1);
  }
  const double v = vb / denom, ww = vc / denom;
  set(1 - v - ww, v, ww);
}

struct Sample {
  V3 p;
  double u, v;
};

struct Query {
  const std::vector<float>* positions;
  const std::vector<float>* uvs;
  const std::vector<uint32_t>* indices;
  Sample s;
  double best_sq;       // closest_distance: shrinks
  double within_sq;     // nearest_uv: triangles this close count
  double best_texels;   // nearest_uv: smallest uv distance so far
  double width, height;
  double closest_texels;  // closest_distance: the uv distance on the closest triangle found
};

// Texel distance between the sample's uv and triangle t's uv at weights w.
double uv_texels(const Query& q, const uint32_t* t, const double w[3]) {
  const float* uv = q.uvs->data();
  double u = 0, v = 0;
  for (int k = 0; k < 3; ++k) u += w[k] * uv[2 * t[k]], v += w[k] * uv[2 * t[k] + 1];
  const double du = (u - q.s.u) * q.width, dv = (v - q.s.v) * q.height;
  return std::sqrt(du * du + dv * dv);
}

void triangle_point(const Query& q, unsigned prim, double w[3], double& dist_sq, const uint32_t*& t) {
  t = q.indices->data() + 3 * size_t(prim);
  const float* pos = q.positions->data();
  const V3 a = load3(pos + 3 * t[0]), b = load3(pos + 3 * t[1]), c = load3(pos + 3 * t[2]);
  closest_weights(q.s.p, a, b, c, w);
  const V3 x{w[0] * a.x + w[1] * b.x + w[2] * c.x, w[0] * a.y + w[1] * b.y + w[2] * c.y,
             w[0] * a.z + w[1] * b.z + w[2] * c.z};
  dist_sq = dot(q.s.p - x, q.s.p - x);
}

bool shrink_callback(RTCPointQueryFunctionArguments* args) {
  auto* q = static_cast<Query*>(args->userPtr);
  double w[3], d2;
  const uint32_t* t;
  triangle_point(*q, args->primID, w, d2, t);
  if (d2 >= q->best_sq) return false;
  q->best_sq = d2;
  q->closest_texels = uv_texels(*q, t, w);
  args->query->radius = float(std::sqrt(d2));
  return true;
}

bool uv_callback(RTCPointQueryFunctionArguments* args) {
  auto* q = static_cast<Query*>(args->userPtr);
  double w[3], d2;
  const uint32_t* t;
  triangle_point(*q, args->primID, w, d2, t);
  if (d2 > q->within_sq) return false;
  q->best_texels = std::min(q->best_texels, uv_texels(*q, t, w));
  // A corner at the closest point carries its own uv (at a pole, or in a degenerate triangle
  // whose corners coincide, the weights pick one corner of several).
  const float* pos = q->positions->data();
  for (int k = 0; k < 3; ++k) {
    const V3 c = load3(pos + 3 * t[k]);
    if (dot(q->s.p - c, q->s.p - c) > q->within_sq) continue;
    const double corner[3] = {k == 0 ? 1.0 : 0.0, k == 1 ? 1.0 : 0.0, k == 2 ? 1.0 : 0.0};
    q->best_texels = std::min(q->best_texels, uv_texels(*q, t, corner));
  }
  return false;
}

Status check_view(const UvMeshView& m, const std::string& what) {
  if (m.index_count == 0 || m.index_count % 3 != 0)
    return Status::error(what + ": no triangles (" + std::to_string(m.index_count) + " indices)");
  if (!m.positions || !m.uvs) return Status::error(what + ": has no texture coordinates to compare");
  for (size_t i = 0; i < m.index_count; ++i)
    if (m.indices[i] >= m.vertex_count)
      return Status::error(what + ": triangle " + std::to_string(i / 3) + " references vertex " +
                           std::to_string(m.indices[i]) + " of " + std::to_string(m.vertex_count));
  for (size_t i = 0; i < 3 * m.vertex_count; ++i)
    if (!std::isfinite(m.positions[i])) return Status::error(what + ": vertex " + std::to_string(i / 3) + " is not finite");
  for (size_t i = 0; i < 2 * m.vertex_count; ++i)
    if (!std::isfinite(m.uvs[i])) return Status::error(what + ": uv " + std::to_string(i / 2) + " is not finite");
  return Status::success();
}

// Every used vertex, then `count` area-weighted points (seeded, so reproducible).
std::vector<Sample> sample_level(const UvMeshView& m, size_t count, uint64_t seed) {
  std::vector<Sample> out;
  std::vector<uint8_t> used(m.vertex_count, 0);
  for (size_t i = 0; i < m.index_count; ++i) used[m.indices[i]] = 1;
  for (size_t v = 0; v < m.vertex_count; ++v)
    if (used[v]) out.push_back({load3(m.positions + 3 * v), m.uvs[2 * v], m.uvs[2 * v + 1]});
  const size_t nt = m.index_count / 3;
  std::vector<double> cumulative(nt);
  double total = 0;
  for (size_t t = 0; t < nt; ++t) {
    const V3 a = load3(m.positions + 3 * m.indices[3 * t]), b = load3(m.positions + 3 * m.indices[3 * t + 1]),
             c = load3(m.positions + 3 * m.indices[3 * t + 2]);
    const V3 e0 = b - a, e1 = c - a;
    const V3 n{e0.y * e1.z - e0.z * e1.y, e0.z * e1.x - e0.x * e1.z, e0.x * e1.y - e0.y * e1.x};
    total += 0.5 * std::sqrt(dot(n, n));
    cumulative[t] = total;
  }
  if (!(total > 0)) return out;
  std::mt19937_64 rng(seed);
  auto uniform = [&rng] { return double(rng() >> 11) * 0x1.0p-53; };
  for (size_t i = 0; i < count; ++i) {
    const double pick = uniform() * total;
    const size_t t = std::min<size_t>(nt - 1, size_t(std::upper_bound(cumulative.begin(), cumulative.end(), pick) -
                                                     cumulative.begin()));
    const double r1 = std::sqrt(uniform()), r2 = uniform();
    const double w[3] = {1 - r1, r1 * (1 - r2), r1 * r2};
    Sample s{{0, 0, 0}, 0, 0};
    for (int k = 0; k < 3; ++k) {
      const uint32_t v = m.indices[3 * t + size_t(k)];
      s.p.x += w[k] * m.positions[3 * v], s.p.y += w[k] * m.positions[3 * v + 1], s.p.z += w[k] * m.positions[3 * v + 2];
      s.u += w[k] * m.uvs[2 * v], s.v += w[k] * m.uvs[2 * v + 1];
    }
    out.push_back(s);
  }
  return out;
}

}  // namespace

struct UvErrorMeter::Impl {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  std::vector<float> positions, uvs;
  std::vector<uint32_t> indices;
  UvErrorSettings settings;
  double tie = 0;  // absolute tie tolerance
  std::string what;

  void release_scene() {
    if (scene) rtcReleaseScene(scene);
    scene = nullptr;
  }
  ~Impl() {
    release_scene();
    if (device) rtcReleaseDevice(device);
  }
};

UvErrorMeter::UvErrorMeter() : impl_(std::make_unique<Impl>()) {}
UvErrorMeter::~UvErrorMeter() = default;

Status UvErrorMeter::set_reference(const UvMeshView& original, const UvErrorSettings& settings, const std::string& what) {
  Impl& m = *impl_;
  m.release_scene();
  if (Status s = check_view(original, what); !s) return s;
  if (!(settings.texture_width > 0) || !(settings.texture_height > 0))
    return Status::error(what + ": texture size must be positive");
  m.settings = settings;
  m.what = what;
  m.positions.assign(original.positions, original.positions + 3 * original.vertex_count);
  m.uvs.assign(original.uvs, original.uvs + 2 * original.vertex_count);
  m.indices.assign(original.indices, original.indices + original.index_count);
  double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
  for (size_t v = 0; v < original.vertex_count; ++v)
    for (int c = 0; c < 3; ++c)
      lo[c] = std::min(lo[c], double(m.positions[3 * v + size_t(c)])), hi[c] = std::max(hi[c], double(m.positions[3 * v + size_t(c)]));
  m.tie = settings.tie_tolerance * std::sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                                             (hi[2] - lo[2]) * (hi[2] - lo[2]));
  if (!m.device) m.device = rtcNewDevice(nullptr);
  if (!m.device) return Status::error(what + ": Embree device could not be created");
  RTCGeometry geom = rtcNewGeometry(m.device, RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                         3 * sizeof(float), original.vertex_count));
  auto* ib = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                            3 * sizeof(uint32_t), original.index_count / 3));
  if (!vb || !ib) {
    rtcReleaseGeometry(geom);
    return Status::error(what + ": Embree could not allocate its buffers");
  }
  std::memcpy(vb, m.positions.data(), m.positions.size() * sizeof(float));
  std::memcpy(ib, m.indices.data(), m.indices.size() * sizeof(uint32_t));
  rtcCommitGeometry(geom);
  m.scene = rtcNewScene(m.device);
  rtcSetSceneFlags(m.scene, RTC_SCENE_FLAG_ROBUST);
  rtcAttachGeometry(m.scene, geom);
  rtcReleaseGeometry(geom);
  rtcCommitScene(m.scene);
  if (rtcGetDeviceError(m.device) != RTC_ERROR_NONE) return Status::error(what + ": Embree failed to build its BVH");
  return Status::success();
}

Status UvErrorMeter::measure(const UvMeshView& level, UvError& out) const {
  const Impl& m = *impl_;
  if (!m.scene) return Status::error("uv error: no reference surface set");
  if (Status s = check_view(level, m.what + " level"); !s) return s;
  const std::vector<Sample> samples = sample_level(level, m.settings.surface_samples, m.settings.seed);
  RTCPointQueryContext context;
  rtcInitPointQueryContext(&context);
  constexpr double kInf = std::numeric_limits<double>::infinity();
  double sum = 0, sum_sq = 0, worst = 0;
  for (const Sample& s : samples) {
    Query q{&m.positions, &m.uvs, &m.indices, s, kInf, 0, kInf, m.settings.texture_width, m.settings.texture_height, 0};
    RTCPointQuery pq;
    pq.x = float(s.p.x), pq.y = float(s.p.y), pq.z = float(s.p.z), pq.time = 0;
    pq.radius = std::numeric_limits<float>::infinity();
    rtcPointQuery(m.scene, &pq, &context, shrink_callback, &q);
    const double within = std::sqrt(q.best_sq) * (1 + 1e-6) + m.tie;
    q.within_sq = within * within;
    pq.radius = float(within * (1 + 1e-6));
    rtcPointQuery(m.scene, &pq, &context, uv_callback, &q);
    // The closest triangle is always within the second query; rounding aside, its uv stands.
    const double e = std::min(q.best_texels, q.closest_texels);
    sum += e, sum_sq += e * e, worst = std::max(worst, e);
  }
  const double n = double(std::max<size_t>(samples.size(), 1));
  out.samples = samples.size();
  out.mean = sum / n;
  out.rms = std::sqrt(sum_sq / n);
  out.max = worst;
  return Status::success();
}

}  // namespace lod
