// A discrete LOD chain from one run of OpenMesh's Decimater (quadric error metric,
// Garland & Heckbert 1997, with normal-flip prevention). Flat arrays in, flat arrays out;
// no OpenMesh type appears here.
#pragma once
#include <cstddef>
#include <cstdint>
#include <functional>
#include <mutex>
#include <span>
#include <string>
#include <vector>

#include "preprocess/mesh.h"
#include "runtime/status.h"

namespace lod {

// One level: its own compact vertex array (only vertices its triangles use).
struct ChainLevel {
  std::vector<float> positions;   // xyz per vertex
  std::vector<float> normals;     // xyz per vertex, area-weighted, unit length
  std::vector<uint32_t> indices;  // level-local, 3 per triangle
  std::vector<float> uvs;         // uv per vertex, or empty (the input had none, or they were dropped)
  std::vector<float> uvs1;        // second uv set per vertex, or empty (likewise)
  std::vector<float> colors;      // linear RGBA per vertex, or empty (likewise)
  size_t target_triangles = 0;    // what the ratio asked for
  size_t triangle_count() const { return indices.size() / 3; }
  size_t vertex_count() const { return positions.size() / 3; }
};

struct DecimaterChainStats {
  size_t refused_faces = 0;   // faces OpenMesh refused as non-manifold, re-added on copied vertices
  size_t copied_vertices = 0; // vertex copies made for them
  size_t collapses = 0;       // edge collapses over the whole chain
  double decimate_seconds = 0;
  std::vector<std::string> notes;  // e.g. a level that stopped above its target
};

// progress(fraction in [0,1]) after every level and periodically during collapses.
using ChainProgress = std::function<void(float)>;

// `ratios`: fractions of the input's triangles, 1.0 first, decreasing. Level i aims at
// round(ratio_i * triangles); a level that cannot get there keeps what it reached (the
// decimater stops when no legal collapse is left) and gets a note. Every input face is kept
// in level 0, including non-manifold ones. Fails only on empty input or bad ratios.
Status bake_decimater_chain(const MeshData& mesh, std::span<const float> ratios, std::vector<ChainLevel>& levels,
                            DecimaterChainStats* stats, const ChainProgress& progress);

// Area-weighted vertex normals of a triangle list (unit length; zero for isolated vertices).
void compute_vertex_normals(const float* positions, size_t vertex_count, const uint32_t* indices,
                            size_t index_count, float* normals_out);

namespace detail {
// OpenMesh's omerr()/omlog() and its reader singletons are process-wide; every piece of
// preprocess/ that touches them (loading, building a TriMesh) holds this lock.
std::mutex& openmesh_global_mutex();
}  // namespace detail

}  // namespace lod
