// The scene's [[terrain]] made drawable: its height field read, resampled onto ROAM's grid and
// placed in the world.
#pragma once
#include <memory>

#include "jobs/scene.h"
#include "jobs/scene_config.h"
#include "runtime/status.h"
#include "runtime/terrain_lod.h"

namespace lod {

// Reads config.file (preprocess/height_field_read.h: text, PNG or any GDAL raster), applies cell_size and vertical_scale,
// resamples bilinearly onto a (2^n + 1)-square grid (samples, or the smallest holding the
// field, at most 4097), builds the bintree and moves it to its placement. `pixel_error` is
// the tau used when the block gives none. Errors name the file.
Status load_terrain_model(const TerrainConfig& config, float pixel_error, TerrainModel& out);

// The scene's terrain, or null when it has none.
Status load_scene_terrain(const SceneConfig& config, std::shared_ptr<const TerrainModel>& out);

// Height of the terrain's true surface (bilinear between grid samples, world units) at world
// (x, z); points beyond the grid take its nearest edge.
float terrain_height_at(const TerrainModel& terrain, float x, float z);

// [[instances]] on_terrain: each object of such a block is lifted by the ground height under
// it (its y from the box becomes a height above the ground) and its world sphere recomputed.
// Objects sit on the bilinear surface, which ROAM's coarser triangles approximate within their
// pixel error. `scene` must be make_scene(config, ...); returns the objects moved.
size_t place_on_terrain(Scene& scene, const SceneConfig& config, const TerrainModel& terrain);

}  // namespace lod
