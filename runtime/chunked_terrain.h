// Chunked LOD (T. Ulrich, "Rendering Massive Terrains using Chunked Level of Detail Control",
// SIGGRAPH 2002 course notes): a quadtree of fixed-size patches over the same grid ROAM uses,
// the baseline the ROAM benchmark compares with.
//
// Every node is a (patch + 1)-square regular patch sampling the grid at its node's step (the
// root the whole grid at the coarsest step, each level halving the step over a quarter of the
// area), triangulated on a fixed diagonal, with a skirt hanging down each of its four edges to
// hide cracks between neighbours at different levels (Ulrich's choice: no stitching, so chunks
// stay static GPU buffers). Its error is the largest vertical distance between the patch and
// the full-resolution samples it covers, nested (a parent's is at least its children's), so the
// selection is monotone. Per frame, nodes whose bounding box is outside the frustum are skipped
// and a node is drawn when error * focal / distance to its box <= tau (or it is a leaf); the
// same projected-error rule ROAM applies per diamond, so both can be compared at one tau.
#pragma once
#include <cstdint>
#include <glm/glm.hpp>
#include <vector>

#include "runtime/roam.h"
#include "runtime/view.h"

namespace lod {

struct ChunkedTerrain {
  uint32_t patch = 32;  // cells per chunk side
  uint32_t size = 0;    // grid samples per side
  struct Node {
    uint32_t x0 = 0, y0 = 0, step = 1;  // first sample and sample step of the patch
    float error = 0;                    // nested, world units
    glm::vec3 lo{0}, hi{0};             // bounding box of the full-resolution samples covered
    int32_t first_child = -1;           // four consecutive children; -1 = leaf (step 1)
  };
  std::vector<Node> nodes;  // nodes[0] = root
};

// Triangles one chunk draws: its patch (2 per cell) and its four skirts (2 per edge cell).
inline uint32_t chunk_triangles(uint32_t patch) { return 2 * patch * patch + 8 * patch; }

// True when (size - 1) / patch is a power of two (>= 1) and patch divides size - 1.
bool chunked_size_valid(uint32_t size, uint32_t patch);
// Precondition: chunked_size_valid(terrain.size, patch). Heights are terrain.positions' y.
ChunkedTerrain build_chunked_terrain(const RoamTerrain& terrain, uint32_t patch);

struct ChunkedSelection {
  uint32_t chunks = 0;
  uint64_t triangles = 0;       // chunks * chunk_triangles(patch), skirts included
  uint64_t skirt_triangles = 0;
};

// The chunks drawn for `view` at `pixel_error` (tau), appended to `out` after clearing it.
ChunkedSelection select_chunks(std::vector<uint32_t>& out, const ChunkedTerrain& chunked, const View& view,
                               float pixel_error);

}  // namespace lod
