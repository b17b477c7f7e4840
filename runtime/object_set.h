// Objects as structs of arrays, indexed by object id, so each stage streams over memory.
#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

#include "lodkit/types.hpp"

namespace lod {

// Placement of every instance: fixed for a run (a simulator may rewrite it between frames).
struct ObjectSet {
  std::vector<uint32_t> model;              // index into ModelTable / chains
  std::vector<float> x, y, z;               // world position (model origin)
  std::vector<float> scale;                 // uniform
  std::vector<float> yaw;                   // radians about +y
  std::vector<float> cx, cy, cz, radius;    // world bounding sphere of level 0

  size_t size() const { return model.size(); }
  void resize(size_t n);
};

// Everything a frame computes per object. Stages write only their own columns.
struct ObjectState {
  std::vector<uint8_t> visible;        // visibility
  std::vector<float> distance;         // importance: eye to sphere centre
  std::vector<float> area;             // importance: projected area in pixels
  std::vector<float> weight;           // importance: d / S, so f = weight * SLC
  std::vector<uint8_t> level;          // selection: chain level index (0 = full)
  std::vector<uint8_t> prev_level;     // last frame's published level
  std::vector<uint8_t> was_visible;    // last frame's visibility

  void resize(size_t n);
};

// Object i's placement as a Transform (its yaw as a quaternion about +y).
Transform transform_of(const ObjectSet& objects, size_t i);

}  // namespace lod
