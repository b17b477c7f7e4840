// LOD chain by OpenMesh's Decimater: ModQuadric (Garland & Heckbert, "Surface
// Simplification Using Quadric Error Metrics", 1997) as the priority, ModNormalFlipping as a
// binary veto. One decimater run makes the whole chain: decimate to each level's target in
// turn and copy the live triangles out after each step.
//
// Passes: build a TriMesh (re-adding faces OpenMesh refuses as non-manifold on copies of
// their vertices, so no input face is lost) -> initialise the decimater -> for each ratio:
// decimate_to_faces, snapshot into a compact level.
#include "preprocess/decimater_chain.h"

#include "preprocess/openmesh_log_capture.h"

#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#include <OpenMesh/Tools/Decimater/DecimaterT.hh>
#include <OpenMesh/Tools/Decimater/ModNormalFlippingT.hh>
#include <OpenMesh/Tools/Decimater/ModQuadricT.hh>
#include <OpenMesh/Tools/Decimater/Observer.hh>

#include <chrono>
#include <cmath>
#include <sstream>

namespace lod {

namespace detail {
std::mutex& openmesh_global_mutex() {
  static std::mutex m;
  return m;
}
}  // namespace detail

namespace {

using TriMesh = OpenMesh::TriMesh_ArrayKernelT<>;
using VertexHandle = TriMesh::VertexHandle;

// Copies of a face's vertices are shared between refused faces in "layers", so stacked
// duplicate sheets stay connected among themselves; past the last layer a face gets private
// copies, which OpenMesh always accepts (an isolated triangle).
constexpr int kCopyLayers = 3;
// ModNormalFlipping: a collapse may not turn a face normal by more than this.
constexpr float kMaxNormalDeviationDeg = 60.0f;
constexpr size_t kProgressEveryCollapses = 2000;

class ProgressObserver final : public OpenMesh::Decimater::Observer {
 public:
  ProgressObserver(const ChainProgress& progress, size_t expected_collapses)
      : Observer(kProgressEveryCollapses), progress_(progress), expected_(std::max<size_t>(1, expected_collapses)) {}
  void start_level(size_t collapses_before) { before_ = collapses_before; }
  void notify(size_t step) override {
    if (progress_) progress_(std::min(0.99f, float(double(before_ + step) / double(expected_))));
  }

 private:
  const ChainProgress& progress_;
  size_t expected_;
  size_t before_ = 0;
};

// Builds the TriMesh; returns faces refused by OpenMesh and copies made.
void build_trimesh(const MeshData& mesh, TriMesh& m, DecimaterChainStats& stats) {
  const size_t nv = mesh.vertex_count();
  m.reserve(nv, 3 * nv, mesh.triangle_count());
  std::vector<VertexHandle> vh(nv);
  for (size_t v = 0; v < nv; ++v)
    vh[v] = m.add_vertex(TriMesh::Point(mesh.positions[3 * v], mesh.positions[3 * v + 1], mesh.positions[3 * v + 2]));
  auto point = [&](uint32_t v) {
    return TriMesh::Point(mesh.positions[3 * v], mesh.positions[3 * v + 1], mesh.positions[3 * v + 2]);
  };

  // add_face complains on omerr() for every refused face; that is expected here, so keep
  // it off the terminal (the count goes into the stats instead). A capture, not
  // omerr().disable(), which would also drop other threads' OpenMesh messages.
  std::lock_guard<std::mutex> lock(detail::openmesh_global_mutex());
  const detail::OpenMeshLogCapture refused_face_chatter;

  std::vector<uint32_t> pending;
  for (size_t t = 0; t < mesh.triangle_count(); ++t) {
    const uint32_t* f = &mesh.indices[3 * t];
    if (!m.add_face(vh[f[0]], vh[f[1]], vh[f[2]]).is_valid()) pending.push_back(uint32_t(t));
  }
  stats.refused_faces = pending.size();

  for (int layer = 0; layer < kCopyLayers && !pending.empty(); ++layer) {
    std::vector<VertexHandle> copy(nv);  // invalid handles until made
    std::vector<uint32_t> still;
    for (uint32_t t : pending) {
      VertexHandle c[3];
      for (int k = 0; k < 3; ++k) {
        const uint32_t v = mesh.indices[3 * t + k];
        if (!copy[v].is_valid()) {
          copy[v] = m.add_vertex(point(v));
          ++stats.copied_vertices;
        }
        c[k] = copy[v];
      }
      if (!m.add_face(c[0], c[1], c[2]).is_valid()) still.push_back(t);
    }
    pending.swap(still);
  }
  for (uint32_t t : pending) {
    VertexHandle c[3];
    for (int k = 0; k < 3; ++k) c[k] = m.add_vertex(point(mesh.indices[3 * t + k]));
    stats.copied_vertices += 3;
    m.add_face(c[0], c[1], c[2]);
  }
}

// Copies the live triangles of `m` into a compact level (vertices in order of first use).
void snapshot(const TriMesh& m, std::vector<uint32_t>& local, ChainLevel& level) {
  local.assign(m.n_vertices(), UINT32_MAX);
  level.positions.clear();
  level.indices.clear();
  for (TriMesh::FaceHandle f : m.faces()) {
    if (m.status(f).deleted()) continue;
    for (VertexHandle v : m.fv_range(f)) {
      uint32_t& l = local[size_t(v.idx())];
      if (l == UINT32_MAX) {
        l = uint32_t(level.positions.size() / 3);
        const TriMesh::Point& p = m.point(v);
        level.positions.insert(level.positions.end(), {p[0], p[1], p[2]});
      }
      level.indices.push_back(l);
    }
  }
  level.normals.resize(level.positions.size());
  compute_vertex_normals(level.positions.data(), level.vertex_count(), level.indices.data(), level.indices.size(),
                         level.normals.data());
}

}  // namespace

void compute_vertex_normals(const float* positions, size_t vertex_count, const uint32_t* indices,
                            size_t index_count, float* normals_out) {
  std::vector<double> acc(3 * vertex_count, 0.0);
  for (size_t t = 0; t + 2 < index_count; t += 3) {
    const float* a = positions + 3 * indices[t];
    const float* b = positions + 3 * indices[t + 1];
    const float* c = positions + 3 * indices[t + 2];
    const double e0[3] = {double(b[0]) - a[0], double(b[1]) - a[1], double(b[2]) - a[2]};
    const double e1[3] = {double(c[0]) - a[0], double(c[1]) - a[1], double(c[2]) - a[2]};
    // Unnormalised cross product = normal scaled by twice the area: area weighting for free.
    const double n[3] = {e0[1] * e1[2] - e0[2] * e1[1], e0[2] * e1[0] - e0[0] * e1[2], e0[0] * e1[1] - e0[1] * e1[0]};
    for (size_t k = 0; k < 3; ++k)
      for (int d = 0; d < 3; ++d) acc[3 * indices[t + k] + d] += n[d];
  }
  for (size_t v = 0; v < vertex_count; ++v) {
    const double* n = &acc[3 * v];
    const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    for (int d = 0; d < 3; ++d) normals_out[3 * v + d] = len > 0 ? float(n[d] / len) : 0.0f;
  }
}

Status bake_decimater_chain(const MeshData& mesh, std::span<const float> ratios, std::vector<ChainLevel>& levels,
                            DecimaterChainStats* stats_out, const ChainProgress& progress) {
  const std::string what = mesh.source.empty() ? std::string("mesh") : mesh.source;
  if (mesh.triangle_count() == 0) return Status::error(what + ": no triangles to simplify");
  if (ratios.empty()) return Status::error(what + ": no LOD ratios given");
  for (size_t i = 0; i < ratios.size(); ++i) {
    if (!(ratios[i] > 0.0f && ratios[i] <= 1.0f) || (i > 0 && !(ratios[i] < ratios[i - 1])))
      return Status::error(what + ": LOD ratio " + std::to_string(i) + " (" + std::to_string(ratios[i]) +
                           ") must be in (0, 1] and below the previous one");
  }
  for (uint32_t v : mesh.indices)
    if (v >= mesh.vertex_count()) return Status::error(what + ": index out of range");

  DecimaterChainStats stats;
  TriMesh m;
  m.request_vertex_status();
  m.request_edge_status();
  m.request_face_status();
  m.request_face_normals();
  build_trimesh(mesh, m, stats);
  m.update_face_normals();

  using Decimater = OpenMesh::Decimater::DecimaterT<TriMesh>;
  Decimater decimater(m);
  OpenMesh::Decimater::ModQuadricT<TriMesh>::Handle quadric;
  OpenMesh::Decimater::ModNormalFlippingT<TriMesh>::Handle flipping;
  decimater.add(quadric);
  decimater.add(flipping);
  decimater.module(quadric).unset_max_err();
  decimater.module(flipping).set_max_normal_deviation(kMaxNormalDeviationDeg);
  if (!decimater.initialize()) return Status::error(what + ": OpenMesh's decimater failed to initialise");

  const size_t input_triangles = mesh.triangle_count();
  auto target_of = [&](float ratio) {
    return std::max<size_t>(1, size_t(std::llround(double(ratio) * double(input_triangles))));
  };
  const size_t last_target = target_of(ratios.back());
  ProgressObserver observer(progress, (input_triangles - std::min(input_triangles, last_target)) / 2);
  decimater.set_observer(&observer);

  std::vector<ChainLevel> out(ratios.size());
  std::vector<uint32_t> local;
  size_t live = input_triangles;  // faces not yet deleted; m.n_faces() still counts deleted ones
  for (size_t i = 0; i < ratios.size(); ++i) {
    ChainLevel& level = out[i];
    level.target_triangles = target_of(ratios[i]);
    if (level.target_triangles < live) {
      observer.start_level(stats.collapses);
      // decimate_to_faces counts from m.n_faces(), which includes deleted faces.
      const size_t deleted = m.n_faces() - live;
      const auto t0 = std::chrono::steady_clock::now();
      stats.collapses += decimater.decimate_to_faces(0, level.target_triangles + deleted);
      stats.decimate_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    }
    snapshot(m, local, level);
    live = level.triangle_count();
    if (live > level.target_triangles) {
      std::ostringstream note;
      note << "level " << i << " stopped at " << live << " triangles, above its target of "
           << level.target_triangles << " (no legal collapse left)";
      stats.notes.push_back(note.str());
    }
    if (progress)
      progress(i + 1 == ratios.size() ? 1.0f
                                      : std::min(0.99f, float(double(stats.collapses) /
                                                              double(std::max<size_t>(1, (input_triangles - last_target) / 2)))));
  }
  decimater.set_observer(nullptr);
  levels = std::move(out);
  if (stats_out) *stats_out = std::move(stats);
  return Status::success();
}

}  // namespace lod
