// Derived columns: an ObjectStore's world spheres and controls brought up to date where its
// objects changed (ObjectStore::dirty), so the cost follows the changes, not the scene size.
#pragma once
#include <cstddef>
#include <span>

#include "runtime/level_caps.h"
#include "runtime/lod_chain.h"
#include "runtime/object_store.h"

namespace lod {

// Objects [begin, end) only, so chunks may run at once; returns how many were refreshed.
size_t refresh_derived_columns(ObjectStore& store, size_t begin, size_t end, const LevelCaps& caps,
                               std::span<const Sphere> model_spheres);

}  // namespace lod
