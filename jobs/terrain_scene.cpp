// [[terrain]] -> TerrainModel: read, resample, build the bintree, place.
#include "jobs/terrain_scene.h"

#include <algorithm>

#include "preprocess/height_field_read.h"
#include "runtime/height_field.h"
#include "runtime/world_bounds.h"

namespace lod {
namespace {

inline constexpr uint32_t kMaxGridSamples = 4097;  // per side: 2^12 + 1

// The smallest 2^n + 1 holding the field along both sides, at most kMaxGridSamples.
uint32_t grid_samples_for(const HeightField& f) {
  const uint32_t side = std::max(f.width, f.height);
  uint32_t n = 3;
  while (n < side && n < kMaxGridSamples) n = 2 * (n - 1) + 1;
  return n;
}

// Where the grid's sample (0, 0) goes: `position` itself, or so that the grid's centre is there.
glm::vec3 grid_origin(const TerrainConfig& c, const HeightField& f) {
  glm::vec3 at(c.position[0], c.position[1], c.position[2]);
  if (c.centered) {
    at.x -= 0.5f * f.cell_size_x * float(f.width - 1);
    at.z -= 0.5f * f.cell_size_y * float(f.height - 1);
  }
  return at;
}

}  // namespace

Status load_terrain_model(const TerrainConfig& config, float pixel_error, TerrainModel& out) {
  HeightFieldOptions options;
  options.coordinates = config.coordinates;
  options.vertical_scale = config.vertical_scale;
  options.no_data_value = config.no_data;
  options.gdal_drivers = config.gdal_drivers;
  HeightField field;
  if (auto st = read_height_field(config.file, field, options); !st) return st;
  if (config.cell_size[0] > 0) field.cell_size_x = config.cell_size[0];
  if (config.cell_size[1] > 0) field.cell_size_y = config.cell_size[1];
  const uint32_t samples = config.samples ? config.samples : grid_samples_for(field);
  if (field.width != samples || field.height != samples) field = resample_square(field, samples);
  TerrainModel m;
  m.roam = build_roam_terrain(field);
  const glm::vec3 origin = grid_origin(config, field);
  for (glm::vec3& p : m.roam.positions) p += origin;
  m.target = config.target;
  m.max_ms = config.max_ms;
  m.pixel_error = config.pixel_error > 0 ? config.pixel_error : pixel_error;
  m.max_triangles = config.max_triangles;
  m.initial_share = config.initial_share;
  m.min_share = config.min_share;
  m.max_share = config.max_share;
  out = std::move(m);
  return Status::success();
}

Status load_scene_terrain(const SceneConfig& config, std::shared_ptr<const TerrainModel>& out) {
  out.reset();
  if (!config.terrain) return Status::success();
  auto m = std::make_shared<TerrainModel>();
  if (auto st = load_terrain_model(*config.terrain, config.pixel_error, *m); !st) return st;
  out = std::move(m);
  return Status::success();
}

float terrain_height_at(const TerrainModel& terrain, float x, float z) {
  const RoamTerrain& t = terrain.roam;
  const glm::vec3 origin = t.positions.front();
  const float cx = t.positions[1].x - origin.x, cz = t.positions[t.size].z - origin.z;
  const float max = float(t.size - 1);
  const float gx = std::clamp((x - origin.x) / cx, 0.f, max), gz = std::clamp((z - origin.z) / cz, 0.f, max);
  const uint32_t x0 = std::min(uint32_t(gx), t.size - 2), z0 = std::min(uint32_t(gz), t.size - 2);
  const float fx = gx - float(x0), fz = gz - float(z0);
  auto h = [&](uint32_t i, uint32_t j) { return t.positions[size_t(j) * t.size + i].y; };
  const float a = h(x0, z0) + fx * (h(x0 + 1, z0) - h(x0, z0));
  const float b = h(x0, z0 + 1) + fx * (h(x0 + 1, z0 + 1) - h(x0, z0 + 1));
  return a + fz * (b - a);
}

size_t place_on_terrain(Scene& scene, const SceneConfig& config, const TerrainModel& terrain) {
  ObjectSet& o = scene.objects;
  size_t first = 0, moved = 0;
  for (const InstanceConfig& inst : config.instances) {
    if (inst.on_terrain)
      for (size_t i = first; i < first + inst.count && i < o.size(); ++i) {
        o.y[i] += terrain_height_at(terrain, o.x[i], o.z[i]);
        const Sphere w = world_sphere(transform_of(o, i), chain_sphere(scene.chains[o.model[i]]));
        o.cx[i] = w.center[0], o.cy[i] = w.center[1], o.cz[i] = w.center[2], o.radius[i] = w.radius;
        ++moved;
      }
    first += inst.count;
  }
  return moved;
}

}  // namespace lod
