// Geomorphing: linear blends of positions over time (v(t) = (1 - t) v_i + t v_f).
#include "runtime/geomorph.h"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <limits>

namespace lod {

namespace {

// Exact at both ends: t = 0 gives a, t = 1 gives b (a + t (b - a) would not, in floats).
inline float blend(float a, float b, float t) { return (1 - t) * a + t * b; }

}  // namespace

void geomorph_lerp(std::span<float> out, std::span<const float> from, std::span<const float> to, float t) {
  assert(from.size() == out.size() && to.size() == out.size());
  t = std::clamp(t, 0.f, 1.f);
  for (size_t i = 0; i < out.size(); ++i) out[i] = blend(from[i], to[i], t);
}

float morph_factor(double now, double start, float duration) {
  if (duration <= 0) return 1;
  return static_cast<float>(std::clamp((now - start) / duration, 0.0, 1.0));
}

void vertex_morph_init(VertexMorph& m, const VertexTree& t, float duration) {
  m.from = t.positions;
  m.to = t.positions;
  m.from_uv = t.uvs;
  m.to_uv = t.uvs;
  auto init = [](MorphColumn& c, const std::vector<float>& values, uint32_t width) {
    const size_t nodes = values.size() / width;
    c.width = values.empty() ? 0 : width;
    c.ends.resize(2 * values.size());
    for (size_t v = 0; v < nodes; ++v) {
      std::copy_n(&values[width * v], width, &c.ends[2 * width * v]);
      std::copy_n(&values[width * v], width, &c.ends[2 * width * v + width]);
    }
  };
  init(m.uv1, t.uvs1, 2);
  init(m.color, t.colors, 4);
  init(m.normal, t.normals, 3);
  m.start.assign(t.node_count(), -std::numeric_limits<double>::infinity());
  m.duration = duration;
}

void vertex_morph_position(const VertexMorph& m, uint32_t v, double now, float out[3]) {
  const float t = morph_factor(now, m.start[v], m.duration);
  for (int k = 0; k < 3; ++k) out[k] = blend(m.from[3 * size_t(v) + k], m.to[3 * size_t(v) + k], t);
}

namespace {

// Displayed uv of one node at `now` (the tree has uvs).
void vertex_morph_uv(const VertexMorph& m, uint32_t v, double now, float out[2]) {
  const float t = morph_factor(now, m.start[v], m.duration);
  for (int k = 0; k < 2; ++k) out[k] = blend(m.from_uv[2 * size_t(v) + k], m.to_uv[2 * size_t(v) + k], t);
}

// Displayed value of one node's column at `now`.
void vertex_morph_value(const MorphColumn& c, uint32_t v, float t, float* out) {
  const size_t w = c.width;
  const float* e = &c.ends[2 * w * v];
  for (size_t k = 0; k < w; ++k) out[k] = blend(e[k], e[w + k], t);
}

}  // namespace

void vertex_morph_apply(VertexMorph& m, const VertexTree& t, std::span<const FrontEvent> events, double now) {
  const bool uvs = !m.to_uv.empty();
  // Node v moves from what `shown` (a node) displays now to `target`'s own position and uv.
  MorphColumn* const extra[3] = {&m.uv1, &m.color, &m.normal};
  const std::vector<float>* const extra_tree[3] = {&t.uvs1, &t.colors, &t.normals};
  const bool extras = !m.uv1.empty() || !m.color.empty() || !m.normal.empty();
  auto retarget = [&](uint32_t v, uint32_t shown, uint32_t target) {
    float here[3], here_uv[2];
    vertex_morph_position(m, shown, now, here);
    if (uvs) vertex_morph_uv(m, shown, now, here_uv);
    // Read before anything is written: `shown` may be v itself.
    for (int c = 0; extras && c < 3; ++c) {
      MorphColumn& col = *extra[c];
      if (col.empty()) continue;
      float value[4];
      vertex_morph_value(col, shown, morph_factor(now, m.start[shown], m.duration), value);
      const size_t w = col.width;
      float* e = &col.ends[2 * w * v];
      for (size_t k = 0; k < w; ++k) e[k] = value[k], e[w + k] = (*extra_tree[c])[w * target + k];
    }
    for (int k = 0; k < 3; ++k) m.from[3 * size_t(v) + k] = here[k], m.to[3 * size_t(v) + k] = t.positions[3 * size_t(target) + k];
    if (uvs)
      for (int k = 0; k < 2; ++k) m.from_uv[2 * size_t(v) + k] = here_uv[k], m.to_uv[2 * size_t(v) + k] = t.uvs[2 * size_t(target) + k];
    m.start[v] = now;
  };
  for (const FrontEvent& e : events) {
    const uint32_t i = e.node - t.leaf_count;
    const uint32_t c[2] = {t.children[2 * i], t.children[2 * i + 1]};
    switch (e.kind) {
      case FrontEventKind::split:
        // Both children appear where the parent is shown and move out to their own positions.
        for (uint32_t ch : c) retarget(ch, e.node, ch);
        break;
      case FrontEventKind::collapse_begin:
        for (uint32_t ch : c) retarget(ch, ch, e.node);
        break;
      case FrontEventKind::collapse_cancel:
        for (uint32_t ch : c) retarget(ch, ch, ch);
        break;
      case FrontEventKind::collapse:
        // The children have arrived (deferred) or jump (no delay); the parent is settled.
        for (int k = 0; k < 3; ++k) m.from[3 * size_t(e.node) + k] = m.to[3 * size_t(e.node) + k] = t.positions[3 * size_t(e.node) + k];
        if (uvs)
          for (int k = 0; k < 2; ++k) m.from_uv[2 * size_t(e.node) + k] = m.to_uv[2 * size_t(e.node) + k] = t.uvs[2 * size_t(e.node) + k];
        for (int x = 0; extras && x < 3; ++x) {
          MorphColumn& col = *extra[x];
          const size_t w = col.width;
          float* ends = col.ends.data() + 2 * w * e.node;
          for (size_t k = 0; k < w; ++k) ends[k] = ends[w + k] = (*extra_tree[x])[w * e.node + k];
        }
        m.start[e.node] = -std::numeric_limits<double>::infinity();
        break;
    }
  }
}

size_t vertex_morph_positions(std::span<float> out, const VertexMorph& m, std::span<const uint32_t> nodes,
                              double now) {
  size_t moving = 0;
  for (uint32_t v : nodes) {
    assert(3 * size_t(v) + 2 < out.size());
    const float t = morph_factor(now, m.start[v], m.duration);
    moving += t < 1;
    for (int k = 0; k < 3; ++k)
      out[3 * size_t(v) + k] = blend(m.from[3 * size_t(v) + k], m.to[3 * size_t(v) + k], t);
  }
  return moving;
}

void vertex_morph_column(std::span<float> out, const VertexMorph& m, const MorphColumn& c,
                         std::span<const uint32_t> nodes, double now) {
  assert(!c.empty());
  for (uint32_t v : nodes) {
    assert(c.width * size_t(v) + c.width <= out.size());
    vertex_morph_value(c, v, morph_factor(now, m.start[v], m.duration), &out[c.width * size_t(v)]);
  }
}

void vertex_morph_compact(std::span<const MorphOutput> outputs, const VertexMorph& m,
                          std::span<const uint32_t> nodes, double now) {
#ifndef NDEBUG
  for (const MorphOutput& o : outputs) assert(!o.column->empty() && o.out.size() >= o.column->width * nodes.size());
#endif
  // Nodes are scattered over the tree's arrays: ask for a later node's lines ahead (the loop is
  // bound by those misses, not by its arithmetic).
  constexpr size_t kAhead = 16;
  for (size_t k = 0; k < nodes.size(); ++k) {
    if (k + kAhead < nodes.size()) {
      const uint32_t w = nodes[k + kAhead];
      __builtin_prefetch(&m.start[w]);
      for (const MorphOutput& o : outputs)
        __builtin_prefetch(&o.column->ends[2 * size_t(o.column->width) * w]);
    }
    const uint32_t v = nodes[k];
    const float t = morph_factor(now, m.start[v], m.duration);
    for (const MorphOutput& o : outputs) vertex_morph_value(*o.column, v, t, &o.out[o.column->width * k]);
  }
}

void vertex_morph_uvs(std::span<float> out, const VertexMorph& m, std::span<const uint32_t> nodes, double now) {
  assert(!m.to_uv.empty());
  for (uint32_t v : nodes) {
    assert(2 * size_t(v) + 1 < out.size());
    vertex_morph_uv(m, v, now, &out[2 * size_t(v)]);
  }
}

void level_morph_attributes(std::span<float> out, std::span<const float> fine, std::span<const float> coarse,
                            std::span<const uint32_t> target, size_t components, float t) {
  assert(out.size() == fine.size() && fine.size() == components * target.size());
  t = std::clamp(t, 0.f, 1.f);
  for (size_t v = 0; v < target.size(); ++v)
    for (size_t k = 0; k < components; ++k)
      out[components * v + k] = blend(fine[components * v + k], coarse[components * size_t(target[v]) + k], t);
}

namespace {

using Tri = std::array<uint32_t, 3>;

Tri sorted_tri(uint32_t a, uint32_t b, uint32_t c) {
  Tri t{a, b, c};
  std::sort(t.begin(), t.end());
  return t;
}

// The coarse triangles as sorted vertex sets, sorted, for binary search.
std::vector<Tri> triangle_sets(std::span<const uint32_t> indices) {
  std::vector<Tri> tris(indices.size() / 3);
  for (size_t f = 0; f < tris.size(); ++f) tris[f] = sorted_tri(indices[3 * f], indices[3 * f + 1], indices[3 * f + 2]);
  std::sort(tris.begin(), tris.end());
  return tris;
}

// A fine triangle whose corners go to a, b, c: fine if they coincide, else a coarse triangle.
bool lands(const std::vector<Tri>& coarse, uint32_t a, uint32_t b, uint32_t c) {
  if (a == b || b == c || a == c) return true;
  return std::binary_search(coarse.begin(), coarse.end(), sorted_tri(a, b, c));
}

constexpr uint32_t kUnset = UINT32_MAX;

// Coarse vertex index per fine vertex whose source survives, kUnset elsewhere.
void surviving_targets(std::span<uint32_t> target, std::span<const uint32_t> fine_source,
                       std::span<const uint32_t> coarse_source) {
  std::vector<std::pair<uint32_t, uint32_t>> by_source(coarse_source.size());
  for (size_t c = 0; c < coarse_source.size(); ++c) by_source[c] = {coarse_source[c], static_cast<uint32_t>(c)};
  std::sort(by_source.begin(), by_source.end());
  for (size_t v = 0; v < target.size(); ++v) {
    const auto it = std::lower_bound(by_source.begin(), by_source.end(), std::make_pair(fine_source[v], 0u));
    target[v] = it != by_source.end() && it->first == fine_source[v] ? it->second : kUnset;
  }
}

// Every target still kUnset becomes the coarse vertex nearest to its fine vertex: a uniform
// grid of about one coarse vertex per cell, searched in growing shells (bake time, not per frame).
void nearest_targets(std::span<uint32_t> target, std::span<const float> fine_positions,
                     std::span<const float> coarse_positions) {
  const size_t nf = target.size(), nc = coarse_positions.size() / 3;
  if (nc == 0 || std::find(target.begin(), target.end(), kUnset) == target.end()) return;
  float lo[3], hi[3];
  for (int k = 0; k < 3; ++k) lo[k] = hi[k] = coarse_positions[k];
  for (size_t c = 0; c < nc; ++c)
    for (int k = 0; k < 3; ++k)
      lo[k] = std::min(lo[k], coarse_positions[3 * c + k]),
      hi[k] = std::max(hi[k], coarse_positions[3 * c + k]);
  const int res = std::clamp(static_cast<int>(std::cbrt(double(nc))), 1, 256);
  float cell = 0;
  for (int k = 0; k < 3; ++k) cell = std::max(cell, (hi[k] - lo[k]) / res);
  if (!(cell > 0)) cell = 1;
  auto cell_of = [&](const float* p, int k) {
    return std::clamp(static_cast<int>((p[k] - lo[k]) / cell), 0, res - 1);
  };
  const size_t cells = size_t(res) * res * res;
  std::vector<uint32_t> start(cells + 1, 0), items(nc);
  auto index = [&](int x, int y, int z) { return (size_t(z) * res + y) * res + x; };
  for (size_t c = 0; c < nc; ++c) {
    const float* p = &coarse_positions[3 * c];
    ++start[index(cell_of(p, 0), cell_of(p, 1), cell_of(p, 2)) + 1];
  }
  for (size_t i = 0; i < cells; ++i) start[i + 1] += start[i];
  std::vector<uint32_t> fill(start.begin(), start.end() - 1);
  for (size_t c = 0; c < nc; ++c) {
    const float* p = &coarse_positions[3 * c];
    items[fill[index(cell_of(p, 0), cell_of(p, 1), cell_of(p, 2))]++] = static_cast<uint32_t>(c);
  }
  for (size_t v = 0; v < nf; ++v) {
    if (target[v] != kUnset) continue;
    const float* p = &fine_positions[3 * v];
    const int cx = cell_of(p, 0), cy = cell_of(p, 1), cz = cell_of(p, 2);
    float best = std::numeric_limits<float>::infinity();
    uint32_t best_c = 0;
    // Shell r holds every cell at Chebyshev distance r; once a hit is closer than the inner
    // edge of the next shell, nothing farther can beat it.
    for (int r = 0; r < res; ++r) {
      for (int z = std::max(cz - r, 0); z <= std::min(cz + r, res - 1); ++z)
        for (int y = std::max(cy - r, 0); y <= std::min(cy + r, res - 1); ++y)
          for (int x = std::max(cx - r, 0); x <= std::min(cx + r, res - 1); ++x) {
            if (std::max({std::abs(x - cx), std::abs(y - cy), std::abs(z - cz)}) != r) continue;
            const size_t i = index(x, y, z);
            for (uint32_t k = start[i]; k < start[i + 1]; ++k) {
              const uint32_t c = items[k];
              float d2 = 0;
              for (int a = 0; a < 3; ++a) {
                const float d = p[a] - coarse_positions[3 * size_t(c) + a];
                d2 += d * d;
              }
              if (d2 < best || (d2 == best && c < best_c)) best = d2, best_c = c;
            }
          }
      if (best <= (r * cell) * (r * cell)) break;
    }
    target[v] = best_c;
  }
}

}  // namespace

void level_morph_targets(std::span<uint32_t> target, std::span<const float> fine_positions,
                         std::span<const uint32_t> fine_source, std::span<const float> coarse_positions,
                         std::span<const uint32_t> coarse_source) {
  const size_t nf = fine_positions.size() / 3, nc = coarse_positions.size() / 3;
  assert(target.size() == nf && fine_source.size() == nf && coarse_source.size() == nc);
  (void)nf;
  if (nc == 0) return;
  surviving_targets(target, fine_source, coarse_source);
  nearest_targets(target, fine_positions, coarse_positions);
}

size_t level_morph_misses(std::span<const uint32_t> target, std::span<const uint32_t> fine_indices,
                          std::span<const uint32_t> coarse_indices) {
  const std::vector<Tri> coarse = triangle_sets(coarse_indices);
  size_t misses = 0;
  for (size_t f = 0; f + 2 < fine_indices.size(); f += 3)
    misses += !lands(coarse, target[fine_indices[f]], target[fine_indices[f + 1]], target[fine_indices[f + 2]]);
  return misses;
}

size_t level_morph_targets_by_collapse(std::span<uint32_t> target, std::span<const float> fine_positions,
                                       std::span<const uint32_t> fine_indices,
                                       std::span<const uint32_t> fine_source,
                                       std::span<const float> coarse_positions,
                                       std::span<const uint32_t> coarse_indices,
                                       std::span<const uint32_t> coarse_source) {
  const size_t nf = fine_positions.size() / 3, nc = coarse_positions.size() / 3;
  assert(target.size() == nf && fine_source.size() == nf && coarse_source.size() == nc);
  if (nc == 0 || nf == 0) return level_morph_misses(target, fine_indices, coarse_indices);
  surviving_targets(target, fine_source, coarse_source);
  // Which fine vertices may move: those whose source did not survive.
  std::vector<uint8_t> free(nf);
  for (size_t v = 0; v < nf; ++v) free[v] = target[v] == kUnset;
  // Fine vertex -> incident triangles (CSR).
  const size_t nt = fine_indices.size() / 3;
  std::vector<uint32_t> first(nf + 1, 0), faces(3 * nt);
  for (size_t i = 0; i < 3 * nt; ++i) ++first[fine_indices[i] + 1];
  for (size_t v = 0; v < nf; ++v) first[v + 1] += first[v];
  {
    std::vector<uint32_t> fill(first.begin(), first.end() - 1);
    for (size_t i = 0; i < 3 * nt; ++i) faces[fill[fine_indices[i]]++] = static_cast<uint32_t>(i / 3);
  }
  const std::vector<Tri> coarse = triangle_sets(coarse_indices);
  auto dist2 = [&](size_t v, uint32_t c) {
    float d2 = 0;
    for (int k = 0; k < 3; ++k) {
      const float d = fine_positions[3 * v + k] - coarse_positions[3 * size_t(c) + k];
      d2 += d * d;
    }
    return d2;
  };
  // Misses among v's triangles if v went to c.
  auto misses_if = [&](size_t v, uint32_t c) {
    uint32_t n = 0;
    for (uint32_t i = first[v]; i < first[v + 1]; ++i) {
      const uint32_t* f = &fine_indices[3 * size_t(faces[i])];
      uint32_t t[3];
      for (int k = 0; k < 3; ++k) t[k] = f[k] == v ? c : target[f[k]];
      n += !lands(coarse, t[0], t[1], t[2]);
    }
    return n;
  };
  // Best of v's own and its neighbours' targets (fewest misses, then nearest).
  std::vector<uint32_t> candidates;
  auto choose = [&](size_t v) {
    candidates.clear();
    for (uint32_t i = first[v]; i < first[v + 1]; ++i)
      for (int k = 0; k < 3; ++k) {
        const uint32_t u = fine_indices[3 * size_t(faces[i]) + k];
        if (u != v) candidates.push_back(target[u]);
      }
    std::sort(candidates.begin(), candidates.end());
    candidates.erase(std::unique(candidates.begin(), candidates.end()), candidates.end());
    uint32_t best = target[v], best_misses = misses_if(v, best);
    float best_d2 = dist2(v, best);
    if (best_misses == 0) return best;
    for (uint32_t c : candidates) {
      const uint32_t m = misses_if(v, c);
      const float d2 = dist2(v, c);
      if (m < best_misses || (m == best_misses && d2 < best_d2)) best = c, best_misses = m, best_d2 = d2;
    }
    return best;
  };
  // Start from the nearest coarse vertex (right for most merged vertices), then repair: a
  // vertex with a triangle that lands nowhere takes the best of its neighbours' targets, and
  // when it changes, its free neighbours are looked at again. Each change lowers that vertex's
  // misses (or keeps them and gets nearer); the work is bounded, and index order keeps it
  // deterministic.
  nearest_targets(target, fine_positions, coarse_positions);
  std::vector<uint32_t> work, next;
  std::vector<uint8_t> queued(nf, 0);
  auto repair = [&] {
    for (int round = 0; round < 16 && !work.empty(); ++round) {
      next.clear();
      for (uint32_t v : work) queued[v] = 0;
      for (uint32_t v : work) {
        const uint32_t best = choose(v);
        if (best == target[v]) continue;
        target[v] = best;
        for (uint32_t i = first[v]; i < first[v + 1]; ++i)
          for (int k = 0; k < 3; ++k) {
            const uint32_t u = fine_indices[3 * size_t(faces[i]) + k];
            if (free[u] && !queued[u]) queued[u] = 1, next.push_back(u);
          }
      }
      std::sort(next.begin(), next.end());
      work.swap(next);
    }
    for (uint32_t v : work) queued[v] = 0;
    work.clear();
  };
  for (size_t v = 0; v < nf; ++v)
    if (free[v] && misses_if(v, target[v]) > 0) work.push_back(static_cast<uint32_t>(v)), queued[v] = 1;
  repair();
  // What one vertex at a time cannot fix, two free corners of a missing triangle moving
  // together often can (a chain of collapses through both): try every pair of their own and
  // neighbours' targets, keep a pair that lowers the misses around both, then repair again.
  std::vector<uint32_t> ca, cb;
  auto candidates_of = [&](uint32_t v, std::vector<uint32_t>& out) {
    out.assign(1, target[v]);
    for (uint32_t i = first[v]; i < first[v + 1]; ++i)
      for (int k = 0; k < 3; ++k) out.push_back(target[fine_indices[3 * size_t(faces[i]) + k]]);
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
  };
  auto misses_around = [&](uint32_t a, uint32_t b) { return misses_if(a, target[a]) + misses_if(b, target[b]); };
  for (int pass = 0; pass < 4; ++pass) {
    bool improved = false;
    for (size_t f = 0; f + 2 < fine_indices.size(); f += 3) {
      const uint32_t* t = &fine_indices[f];
      if (lands(coarse, target[t[0]], target[t[1]], target[t[2]])) continue;
      for (int e = 0; e < 3; ++e) {
        const uint32_t a = t[e], b = t[(e + 1) % 3];
        if (!free[a] || !free[b]) continue;
        candidates_of(a, ca);
        candidates_of(b, cb);
        const uint32_t keep_a = target[a], keep_b = target[b];
        uint32_t best = misses_around(a, b), best_a = keep_a, best_b = keep_b;
        for (uint32_t x : ca)
          for (uint32_t y : cb) {
            target[a] = x, target[b] = y;
            if (const uint32_t m = misses_around(a, b); m < best) best = m, best_a = x, best_b = y;
          }
        target[a] = best_a, target[b] = best_b;
        if (best_a != keep_a || best_b != keep_b) {
          improved = true;
          for (uint32_t v : {a, b})
            for (uint32_t i = first[v]; i < first[v + 1]; ++i)
              for (int k = 0; k < 3; ++k) {
                const uint32_t u = fine_indices[3 * size_t(faces[i]) + k];
                if (free[u] && u != a && u != b && !queued[u]) queued[u] = 1, work.push_back(u);
              }
          break;
        }
      }
    }
    std::sort(work.begin(), work.end());
    repair();
    if (!improved) break;
  }
  return level_morph_misses(target, fine_indices, coarse_indices);
}

void level_morph_positions(std::span<float> out, std::span<const float> fine_positions,
                           std::span<const float> coarse_positions, std::span<const uint32_t> target,
                           float t) {
  assert(out.size() == fine_positions.size() && target.size() * 3 == fine_positions.size());
  t = std::clamp(t, 0.f, 1.f);
  for (size_t v = 0; v < target.size(); ++v)
    for (int k = 0; k < 3; ++k)
      out[3 * v + k] = blend(fine_positions[3 * v + k], coarse_positions[3 * size_t(target[v]) + k], t);
}

size_t advance_level_morph(std::span<float> morph, std::span<const uint8_t> level,
                           std::span<const uint8_t> prev_level, float dt, float duration) {
  assert(level.size() == morph.size() && prev_level.size() == morph.size());
  const float step = duration > 0 ? dt / duration : 1.f;
  size_t moving = 0;
  for (size_t i = 0; i < morph.size(); ++i) {
    const float m = level[i] != prev_level[i] ? 0.f : morph[i];
    morph[i] = std::min(1.f, m + (level[i] != prev_level[i] ? 0.f : step));
    moving += morph[i] < 1;
  }
  return moving;
}

}  // namespace lod
