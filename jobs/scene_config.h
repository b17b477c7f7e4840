// SceneConfig: everything a configs/*.toml file says, parsed and checked.
#pragma once
#include "runtime/regular_file.h"
#include <cstdint>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "preprocess/height_field_io.h"
#include "preprocess/lod_bake.h"
#include "runtime/camera_path.h"
#include "runtime/motion_path.h"
#include "runtime/roam.h"
#include "runtime/slc_selection.h"
#include "runtime/status.h"

namespace lod {

struct ModelConfig {
  std::string name;
  std::filesystem::path file;   // resolved: config folder first, then the data directory
  BakeSettings bake;
  bool view_dependent = false;  // view_dependent = true: a vertex hierarchy, refined per frame
  // vd_parts = N: the hierarchy is cut into N spatial parts (seams kept at full detail) whose
  // fronts update on separate threads; 1 = one front per object.
  uint32_t vd_parts = 1;
  // hlod = true: baked to a .hlod (Zhou and Tian's octree of layered nodes) and drawn through its tree,
  // streamed under [stream]; its [[instances]] block places exactly one object.
  bool hlod = false;
  uint32_t min_verts = 1000;    // min_verts: the HLOD build's leaf size (Zhou and Tian, Table I)
};

// [stream]: the HLOD node pager (jobs/stream_pager.h).
struct StreamConfig {
  uint32_t budget_mb = 256;     // budget_mb: resident node payloads, MiB
  uint32_t loader_threads = 2;  // loader_threads
};

// [scene_hlod]: merged proxies over the static instances (preprocess/scene_hlod_build.h).
struct SceneHlodConfig {
  bool enabled = false;         // enabled
  uint32_t min_objects = 2;     // min_objects: a cell with fewer is not split (Zhou and Tian: 2)
  float reduction = 0.5f;       // reduction: a proxy keeps this fraction of its inputs' triangles
};

struct InstanceConfig {
  uint32_t model = 0;          // index into SceneConfig::models
  uint32_t count = 0;
  bool grid = false;           // placement = "grid" (else seeded random)
  float box_min[3] = {-500, 0, -500};
  float box_max[3] = {500, 0, 500};
  float scale_min = 1, scale_max = 1;
  uint64_t seed = 1;            // absent: 1 for block 0, a mix of the block index for later ones
  MotionSpec motion;           // motion = "wander" / "orbit" with a speed: moved every frame
  bool on_terrain = false;     // on_terrain = true: y = the [[terrain]]'s height at (x, z) + the box's y (static blocks)
};

// [[terrain]] (at most one): a height field drawn by ROAM within the same budget.
struct TerrainConfig {
  std::filesystem::path file;  // file: "x y z" text, PNG or a GDAL raster (preprocess/height_field_read.h), found like meshes
  GridCoordinates coordinates = GridCoordinates::metres;  // coordinates = "metres" | "lon_lat" | "lat_lon" (text; rasters carry theirs)
  float cell_size[2] = {0, 0};  // cell_size = m or [mx, my]: metres between samples; 0 = from the file
  float vertical_scale = 1;     // vertical_scale: world height = elevation * this
  double no_data = std::numeric_limits<double>::quiet_NaN();  // no_data: elevation meaning "none"
  bool centered = true;         // placement = "center" (position = the grid's centre) | "corner"
  float position[3] = {0, 0, 0};  // position = [x, y, z]: where that point goes (y adds to heights)
  uint32_t samples = 0;         // samples: ROAM grid side 2^n + 1 (<= 4097); 0 = smallest holding the field
  float pixel_error = 0;        // pixel_error: ROAM's tau; 0 = [lod] pixel_error
  RoamTarget target = RoamTarget::pixel_error;  // target = "pixel_error" | "triangles" (= its share) | "time"
  float max_ms = 0;             // max_ms: ROAM's time limit per frame, any target (needed by "time"); 0 = none
  uint32_t max_triangles = 1u << 18;  // max_triangles: cap in any mode (the share of levels budgets)
  float initial_share = 0.5f, min_share = 0.05f, max_share = 0.9f;  // share = [min, initial, max] of M
  std::vector<std::string> gdal_drivers;  // gdal_drivers = ["GTiff", ...]: GDAL drivers allowed to open file; [] = all
};

struct SceneConfig {
  std::filesystem::path file;        // the config itself
  uint32_t frames = 600;
  uint32_t threads = 0;              // 0 = all cores
  double rate_hz = 60;
  SelectionParams selection;
  float pixel_error = 1.0f;          // [lod] pixel_error: screen-space threshold of initial levels
  float hysteresis = 0.25f;          // [lod] hysteresis
  float max_distance = 0;            // [lod] max_distance: objects farther are not drawn; 0 = no limit
  bool occlusion = false;            // [visibility] occlusion
  bool occlusion_embree = false;     // [visibility] occlusion_method = "embree" (default "raster")
  uint32_t occluders = 48;           // [visibility] occluders
  CameraPath camera;
  StreamConfig stream;
  SceneHlodConfig scene_hlod;
  std::vector<ModelConfig> models;
  std::vector<InstanceConfig> instances;
  std::optional<TerrainConfig> terrain;
  // [cache] dir: where baked models are cached (relative: to the config's folder); empty =
  // the default folder (cache_dir_for, jobs/cache_folder.h).
  std::filesystem::path cache_dir;
};

// Refuses unknown paths, wrong types, absurd values (negative counts, zero size windows,
// budgets of 0, thread counts over 1024, unknown model names) naming the file and key.
// `data_dir` is where mesh files are looked for after the config's own folder.
// `objects_optional`: a config without [[model]] or [[instances]] is fine (a service that a
// program fills itself); `lod run` and the viewer need both.
Status load_scene_config(const std::filesystem::path& file, const std::filesystem::path& data_dir,
                         SceneConfig& out, bool objects_optional = false);

// The same over a config's text; `file` names it in messages and is where relative mesh paths
// start. Configs are small: load_scene_config refuses files over kMaxConfigBytes unread.
inline constexpr uint64_t kMaxConfigBytes = kConfigFileLimit.max_bytes;
Status parse_scene_config(std::string_view text, const std::filesystem::path& file,
                          const std::filesystem::path& data_dir, SceneConfig& out, bool objects_optional = false);

// The data directory the set-up fills (Debian's CGAL meshes), compiled in.
std::filesystem::path default_data_dir();

}  // namespace lod
