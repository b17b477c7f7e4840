// Geomorphing: linear blends of positions over time (R3's v(t) = (1 - t) v_i + t v_f).
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
  m.start.assign(t.node_count(), -std::numeric_limits<double>::infinity());
  m.duration = duration;
}

void vertex_morph_position(const VertexMorph& m, uint32_t v, double now, float out[3]) {
  const float t = morph_factor(now, m.start[v], m.duration);
  for (int k = 0; k < 3; ++k) out[k] = blend(m.from[3 * size_t(v) + k], m.to[3 * size_t(v) + k], t);
}

void vertex_morph_apply(VertexMorph& m, const VertexTree& t, std::span<const FrontEvent> events, double now) {
  auto retarget = [&](uint32_t v, const float* from, const float* to) {
    for (int k = 0; k < 3; ++k) m.from[3 * size_t(v) + k] = from[k], m.to[3 * size_t(v) + k] = to[k];
    m.start[v] = now;
  };
  for (const FrontEvent& e : events) {
    const uint32_t i = e.node - t.leaf_count;
    const uint32_t c[2] = {t.children[2 * i], t.children[2 * i + 1]};
    const float* own = &t.positions[3 * size_t(e.node)];
    float here[3];
    switch (e.kind) {
      case FrontEventKind::split:
        // Both children appear where the parent is shown and move out to their own positions.
        vertex_morph_position(m, e.node, now, here);
        for (uint32_t ch : c) retarget(ch, here, &t.positions[3 * size_t(ch)]);
        break;
      case FrontEventKind::collapse_begin:
        for (uint32_t ch : c) {
          vertex_morph_position(m, ch, now, here);
          retarget(ch, here, own);
        }
        break;
      case FrontEventKind::collapse_cancel:
        for (uint32_t ch : c) {
          vertex_morph_position(m, ch, now, here);
          retarget(ch, here, &t.positions[3 * size_t(ch)]);
        }
        break;
      case FrontEventKind::collapse:
        // The children have arrived (deferred) or jump (no delay); the parent is settled.
        retarget(e.node, own, own);
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

void level_morph_targets(std::span<uint32_t> target, std::span<const float> fine_positions,
                         std::span<const uint32_t> fine_source, std::span<const float> coarse_positions,
                         std::span<const uint32_t> coarse_source) {
  const size_t nf = fine_positions.size() / 3, nc = coarse_positions.size() / 3;
  assert(target.size() == nf && fine_source.size() == nf && coarse_source.size() == nc);
  if (nc == 0) return;
  // Sources that survive keep their own coarse vertex (sorted pairs, binary search).
  std::vector<std::pair<uint32_t, uint32_t>> by_source(nc);
  for (size_t c = 0; c < nc; ++c) by_source[c] = {coarse_source[c], static_cast<uint32_t>(c)};
  std::sort(by_source.begin(), by_source.end());
  // Merged-away vertices take the nearest coarse vertex: a uniform grid of about one coarse
  // vertex per cell, searched in growing shells (a bake-time cost, never per frame).
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
    const auto it = std::lower_bound(by_source.begin(), by_source.end(), std::make_pair(fine_source[v], 0u));
    if (it != by_source.end() && it->first == fine_source[v]) {
      target[v] = it->second;
      continue;
    }
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

}  // namespace

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
  level_morph_targets(target, fine_positions, fine_source, coarse_positions, coarse_source);
  const size_t nf = fine_positions.size() / 3, nc = coarse_positions.size() / 3;
  if (nc == 0 || nf == 0) return level_morph_misses(target, fine_indices, coarse_indices);
  // Which fine vertices may move: those whose source did not survive.
  std::vector<uint32_t> kept(coarse_source.begin(), coarse_source.end());
  std::sort(kept.begin(), kept.end());
  std::vector<uint8_t> free(nf);
  for (size_t v = 0; v < nf; ++v) free[v] = !std::binary_search(kept.begin(), kept.end(), fine_source[v]);
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
  // Misses among v's triangles if v went to c (the other corners where they are now).
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
  std::vector<uint32_t> candidates;
  // Local search, one vertex at a time in index order (deterministic); each round can only
  // keep or lower a vertex's own misses, and a few rounds settle real chains.
  for (int round = 0; round < 16; ++round) {
    bool changed = false;
    for (size_t v = 0; v < nf; ++v) {
      if (!free[v] || first[v] == first[v + 1]) continue;
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
      if (best_misses == 0) continue;
      for (uint32_t c : candidates) {
        const uint32_t m = misses_if(v, c);
        const float d2 = dist2(v, c);
        if (m < best_misses || (m == best_misses && d2 < best_d2)) best = c, best_misses = m, best_d2 = d2;
      }
      if (best != target[v]) target[v] = best, changed = true;
    }
    if (!changed) break;
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
