// ObjectStore: the live objects of a service as dense structs of arrays, plus the columns that
// carry an object's state from one frame to the next. Outside code names an object by handle
// (slot + generation); a frame streams over the dense index. Erasing moves the last object
// into the hole with every column, so an object's level, blend and visibility history follow
// it through other objects' creation and destruction.
#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

#include "lodkit/types.hpp"

namespace lod {

inline constexpr uint32_t kNoIndex = 0xffffffffu;

inline uint32_t handle_slot(ObjectHandle h) { return static_cast<uint32_t>(h); }
inline uint32_t handle_generation(ObjectHandle h) { return static_cast<uint32_t>(h >> 32); }
inline ObjectHandle make_handle(uint32_t slot, uint32_t generation) {
  return uint64_t{generation} << 32 | slot;
}

struct ObjectStore {
  // Dense: index = the object's place in this frame's object order.
  std::vector<ObjectHandle> handle;
  std::vector<uint32_t> model;
  std::vector<Transform> transform;    // exactly as the caller set it
  std::vector<ObjectOptions> options;  // exactly as the caller set it
  // Derived from transform, options and model (world_bounds.h, object_controls.h), kept until
  // they change: recomputed only where `dirty` is set (inserted, moved, options changed, or
  // every object after the models changed), so a static object costs nothing per frame.
  std::vector<float> cx, cy, cz, radius;  // world bounding sphere
  std::vector<uint32_t> row;              // selection row (LevelCaps)
  std::vector<uint8_t> min_level;
  std::vector<float> error_scale;
  std::vector<float> inv_priority;
  std::vector<uint8_t> never_cull;
  std::vector<uint8_t> dirty;
  bool any_dirty = false;
  // Written by frames, read by the next one.
  std::vector<uint8_t> prev_level;     // last published level
  std::vector<uint8_t> was_visible;    // visible last frame
  std::vector<uint8_t> morph_from;     // level a blend runs from
  std::vector<double> morph_start;     // when the blend started (service clock, seconds)
  // Handle slot -> dense index (kNoIndex when the slot holds no live object).
  std::vector<uint32_t> index_of_slot;

  size_t size() const { return handle.size(); }
  // Dense index of a live object, or kNoIndex for a stale or unknown handle.
  uint32_t find(ObjectHandle h) const;
  // Appends an object with fresh temporal state (not visible last frame, settled).
  uint32_t insert(ObjectHandle h, uint32_t model, const Transform& t, const ObjectOptions& o);
  // Removes the object at `index`; the last object takes its place.
  void erase(uint32_t index);
  void clear();
  void reset_temporal_state();  // as if no frame had run
  void mark_dirty(uint32_t index) {
    dirty[index] = 1;
    any_dirty = true;
  }
  void mark_all_dirty();
};

}  // namespace lod
