// Scene config: configs/*.toml parsed with toml++ into a SceneConfig, every key checked.
// Errors read "file: key: why" (or "file:line:col: why" for TOML syntax), and `out` is
// written only when the whole file is good.
#include "jobs/scene_config.h"

#include "runtime/regular_file.h"

#include <toml++/toml.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <initializer_list>
#include <optional>
#include <sstream>
#include <string_view>

namespace lod {
namespace {

inline constexpr int kMaxWindowPixels = 16384;  // per side
inline constexpr uint32_t kMaxThreads = 1024;
inline constexpr uint64_t kMaxObjects = 10000000;  // all [[instances]] together
// Float-fed values: squares and products of two stay finite and normal in float.
inline constexpr double kMinFloatValue = 1e-15, kMaxFloatValue = 1e15;

// The seed of an [[instances]] block without one: block 0 keeps 1 (as before); later blocks
// mix their index in, so two blocks in one box do not stack their objects on each other.
uint64_t default_seed(size_t block) {
  if (block == 0) return 1;
  uint64_t z = 1 + 0x9e3779b97f4a7c15ull * block;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return (z ^ (z >> 31)) & 0x7fffffffffffffffull;  // a value `seed = ...` could also give
}

// Thrown inside the parser only; load_scene_config turns it into a Status.
struct ConfigError {
  std::string message;
};

std::string number_text(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

enum class Fit { float32, any };

class Reader {
 public:
  explicit Reader(std::string file) : file_(std::move(file)) {}

  [[noreturn]] void fail(const std::string& key, const std::string& why) const {
    throw ConfigError{file_ + ": " + key + ": " + why};
  }

  // Refuses keys a table does not know: a typo must not silently fall back to a default.
  void only_keys(const toml::table& t, const std::string& where,
                 std::initializer_list<std::string_view> known) const {
    for (auto&& [k, v] : t) {
      if (std::find(known.begin(), known.end(), k.str()) != known.end()) continue;
      std::string list;
      for (auto n : known) list += (list.empty() ? "" : ", ") + std::string(n);
      fail(where.empty() ? std::string(k.str()) : where + "." + std::string(k.str()),
           "unknown key (known here: " + list + ")");
    }
  }

  const toml::table* table(const toml::table& t, std::string_view name, const std::string& key) const {
    const toml::node* n = t.get(name);
    if (!n) return nullptr;
    if (!n->is_table()) fail(key, "expected a table");
    return n->as_table();
  }

  std::optional<int64_t> integer(const toml::table& t, std::string_view name, const std::string& key) const {
    const toml::node* n = t.get(name);
    if (!n) return std::nullopt;
    if (!n->is_integer()) fail(key, "expected an integer");
    return n->as_integer()->get();
  }

  // Integer in [lo, hi]; absent keeps `value`.
  template <class T>
  void integer_in(const toml::table& t, std::string_view name, const std::string& key, int64_t lo, int64_t hi,
                  T& value) const {
    if (auto v = integer(t, name, key)) {
      if (*v < lo || *v > hi)
        fail(key, "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got " +
                      std::to_string(*v));
      value = static_cast<T>(*v);
    }
  }

  // A number; `as_float` (every key but run.rate_hz feeds a 32-bit float): also within what
  // that float and the math on it hold, 0 or a magnitude in [kMinFloatValue, kMaxFloatValue]
  // (near = 1e-50 would become 0, far = 1e39 infinity, and squares of 1e20 overflow).
  std::optional<double> number(const toml::node& n, const std::string& key, Fit fit = Fit::float32) const {
    double v = 0;
    if (n.is_integer())
      v = static_cast<double>(n.as_integer()->get());
    else if (n.is_floating_point())
      v = n.as_floating_point()->get();
    else
      fail(key, "expected a number");
    if (!std::isfinite(v)) fail(key, "must be finite, got " + number_text(v));
    if (fit == Fit::float32 && v != 0 && (std::abs(v) < kMinFloatValue || std::abs(v) > kMaxFloatValue))
      fail(key, number_text(v) + " does not fit the 32-bit float it feeds (0 or a magnitude in [" +
                    number_text(kMinFloatValue) + ", " + number_text(kMaxFloatValue) + "])");
    return v;
  }
  std::optional<double> number(const toml::table& t, std::string_view name, const std::string& key,
                               Fit fit = Fit::float32) const {
    const toml::node* n = t.get(name);
    if (!n) return std::nullopt;
    return number(*n, key, fit);
  }

  std::optional<std::string> string(const toml::table& t, std::string_view name,
                                    const std::string& key) const {
    const toml::node* n = t.get(name);
    if (!n) return std::nullopt;
    if (!n->is_string()) fail(key, "expected a string");
    return n->as_string()->get();
  }

  const toml::array* array(const toml::table& t, std::string_view name, const std::string& key) const {
    const toml::node* n = t.get(name);
    if (!n) return nullptr;
    if (!n->is_array()) fail(key, "expected an array");
    return n->as_array();
  }

  // [x, y, z] of numbers.
  bool vec3(const toml::table& t, std::string_view name, const std::string& key, float out[3]) const {
    const toml::array* a = array(t, name, key);
    if (!a) return false;
    if (a->size() != 3) fail(key, "expected 3 numbers [x, y, z], got " + std::to_string(a->size()));
    for (size_t i = 0; i < 3; ++i)
      out[i] = static_cast<float>(*number(*a->get(i), key + "[" + std::to_string(i) + "]"));
    return true;
  }
  bool vec3(const toml::table& t, std::string_view name, const std::string& key, glm::vec3& out) const {
    float v[3];
    if (!vec3(t, name, key, v)) return false;
    out = glm::vec3(v[0], v[1], v[2]);
    return true;
  }

  // Array of tables ([[name]]); an empty vector when absent.
  std::vector<const toml::table*> tables(const toml::table& t, std::string_view name,
                                         const std::string& key) const {
    std::vector<const toml::table*> out;
    const toml::array* a = array(t, name, key);
    if (!a) return out;
    for (size_t i = 0; i < a->size(); ++i) {
      const toml::node* n = a->get(i);
      if (!n->is_table())
        fail(key + "[" + std::to_string(i) + "]", "expected a table (write [[" + key + "]])");
      out.push_back(n->as_table());
    }
    return out;
  }

 private:
  std::string file_;
};

std::string indexed(const std::string& base, size_t i) { return base + "[" + std::to_string(i) + "]"; }

bool valid_model_name(const std::string& name) {
  if (name.empty() || name.size() > 64) return false;
  return std::all_of(name.begin(), name.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
           c == '-' || c == '.';
  });
}

void read_run(const Reader& r, const toml::table& root, SceneConfig& c) {
  const toml::table* t = r.table(root, "run", "run");
  if (!t) return;
  r.only_keys(*t, "run", {"frames", "threads", "rate_hz"});
  r.integer_in(*t, "frames", "run.frames", 1, 100000000, c.frames);
  r.integer_in(*t, "threads", "run.threads", 0, kMaxThreads, c.threads);
  if (auto v = r.number(*t, "rate_hz", "run.rate_hz", Fit::any)) {
    if (*v <= 0 || *v > 10000)
      r.fail("run.rate_hz", "must be in (0, 10000] frames per second, got " + number_text(*v));
    c.rate_hz = *v;
  }
}

void read_budget(const Reader& r, const toml::table& root, SceneConfig& c) {
  const toml::table* t = r.table(root, "budget", "budget");
  if (!t) return;
  r.only_keys(*t, "budget", {"triangles", "count", "reserve_blends", "strict", "selector"});
  if (auto v = r.integer(*t, "triangles", "budget.triangles")) {
    if (*v <= 0) r.fail("budget.triangles", "must be at least 1, got " + std::to_string(*v));
    c.selection.budget = static_cast<uint64_t>(*v);
  }
  if (auto v = r.string(*t, "count", "budget.count")) {
    if (*v == "triangles")
      c.selection.count = BudgetCount::triangles;
    else if (*v == "levels")
      c.selection.count = BudgetCount::levels;
    else
      r.fail("budget.count", "must be \"triangles\" or \"levels\", got \"" + *v + "\"");
  }
  if (const toml::node* n = t->get("reserve_blends")) {
    const auto* b = n->as_boolean();
    if (!b) r.fail("budget.reserve_blends", "must be true or false");
    else c.selection.reserve_blends = b->get();
  }
  if (const toml::node* n = t->get("strict")) {
    const auto* b = n->as_boolean();
    if (!b) r.fail("budget.strict", "must be true or false");
    else c.selection.strict = b->get();
  }
  if (auto v = r.string(*t, "selector", "budget.selector")) {
    if (*v == "greedy")
      c.selection.selector = Selector::greedy;
    else if (*v == "greedy_multi")
      c.selection.selector = Selector::greedy_multi;
    else if (*v == "benefit_cost")
      c.selection.selector = Selector::benefit_cost;
    else
      r.fail("budget.selector", "must be \"greedy\", \"greedy_multi\" or \"benefit_cost\", got \"" + *v + "\"");
  }
  if (c.selection.strict && c.selection.count != BudgetCount::triangles)
    r.fail("budget.strict", "needs count = \"triangles\" (blends are counted in triangles)");
}

void read_lod(const Reader& r, const toml::table& root, SceneConfig& c) {
  const toml::table* t = r.table(root, "lod", "lod");
  if (!t) return;
  r.only_keys(*t, "lod", {"pixel_error", "hysteresis", "max_distance"});
  if (auto v = r.number(*t, "pixel_error", "lod.pixel_error")) {
    if (*v <= 0 || *v > 10000)
      r.fail("lod.pixel_error", "must be in (0, 10000] pixels, got " + number_text(*v));
    c.pixel_error = static_cast<float>(*v);
  }
  if (auto v = r.number(*t, "hysteresis", "lod.hysteresis")) {
    if (*v < 0 || *v > 10) r.fail("lod.hysteresis", "must be in [0, 10], got " + number_text(*v));
    c.hysteresis = static_cast<float>(*v);
  }
  if (auto v = r.number(*t, "max_distance", "lod.max_distance")) {
    if (!(*v > 0)) r.fail("lod.max_distance", "must be > 0 world units, got " + number_text(*v));
    c.max_distance = static_cast<float>(*v);
  }
}

// [visibility] occlusion = true: cull what large nearby objects hide (view 0); occluders =
// how many objects are rasterised as occluders per frame; occlusion_method = "raster" (default,
// the faster: docs/performance.md, "Culling") or "embree" (rays through every buffer sample).
void read_visibility(const Reader& r, const toml::table& root, SceneConfig& c) {
  const toml::table* t = r.table(root, "visibility", "visibility");
  if (!t) return;
  r.only_keys(*t, "visibility", {"occlusion", "occluders", "occlusion_method"});
  if (auto v = r.string(*t, "occlusion_method", "visibility.occlusion_method")) {
    if (*v == "raster" || *v == "embree")
      c.occlusion_embree = *v == "embree";
    else
      r.fail("visibility.occlusion_method", "must be \"raster\" or \"embree\", got \"" + *v + "\"");
  }
  if (const toml::node* n = t->get("occlusion")) {
    const auto* b = n->as_boolean();
    if (!b) r.fail("visibility.occlusion", "must be true or false");
    else c.occlusion = b->get();
  }
  r.integer_in(*t, "occluders", "visibility.occluders", 1, 4096, c.occluders);
}

void read_camera(const Reader& r, const toml::table& root, SceneConfig& c) {
  const toml::table* t = r.table(root, "camera", "camera");
  if (!t) return;
  r.only_keys(*t, "camera",
              {"fov_deg", "width", "height", "path", "center", "radius", "height_above", "period_frames",
               "near", "far", "keyframe"});
  CameraPath& cam = c.camera;
  if (auto v = r.number(*t, "fov_deg", "camera.fov_deg")) {
    if (*v <= 1 || *v >= 179) r.fail("camera.fov_deg", "must be in (1, 179) degrees, got " + number_text(*v));
    cam.lens.fov_y_deg = static_cast<float>(*v);
  }
  r.integer_in(*t, "width", "camera.width", 1, kMaxWindowPixels, cam.lens.width);
  r.integer_in(*t, "height", "camera.height", 1, kMaxWindowPixels, cam.lens.height);
  if (auto v = r.string(*t, "path", "camera.path")) {
    if (*v == "orbit")
      cam.kind = PathKind::orbit;
    else if (*v == "flythrough")
      cam.kind = PathKind::flythrough;
    else if (*v == "keyframes")
      cam.kind = PathKind::keyframes;
    else
      r.fail("camera.path", "must be \"orbit\", \"flythrough\" or \"keyframes\", got \"" + *v + "\"");
  }
  r.vec3(*t, "center", "camera.center", cam.center);
  if (auto v = r.number(*t, "radius", "camera.radius")) {
    if (*v <= 0) r.fail("camera.radius", "must be > 0, got " + number_text(*v));
    cam.radius = static_cast<float>(*v);
  }
  if (auto v = r.number(*t, "height_above", "camera.height_above")) cam.height_above = static_cast<float>(*v);
  r.integer_in(*t, "period_frames", "camera.period_frames", 1, 100000000, cam.period_frames);
  if (auto v = r.number(*t, "near", "camera.near")) {
    if (*v <= 0) r.fail("camera.near", "must be > 0, got " + number_text(*v));
    cam.lens.near_plane = static_cast<float>(*v);
  }
  if (auto v = r.number(*t, "far", "camera.far")) cam.lens.far_plane = static_cast<float>(*v);
  if (!(cam.lens.far_plane > cam.lens.near_plane))
    r.fail("camera.far", "must be greater than camera.near (" + number_text(cam.lens.near_plane) + "), got " +
                             number_text(cam.lens.far_plane));

  const auto keys = r.tables(*t, "keyframe", "camera.keyframe");
  std::vector<CameraKeyframe> frames;
  for (size_t i = 0; i < keys.size(); ++i) {
    const std::string key = indexed("camera.keyframe", i);
    r.only_keys(*keys[i], key, {"frame", "position", "look_at"});
    CameraKeyframe k;
    if (!r.integer(*keys[i], "frame", key + ".frame")) r.fail(key + ".frame", "missing");
    r.integer_in(*keys[i], "frame", key + ".frame", 0, 100000000, k.frame);
    if (!r.vec3(*keys[i], "position", key + ".position", k.position)) r.fail(key + ".position", "missing");
    if (!r.vec3(*keys[i], "look_at", key + ".look_at", k.look_at)) r.fail(key + ".look_at", "missing");
    if (k.position == k.look_at) r.fail(key + ".look_at", "equals position: no view direction");
    for (const CameraKeyframe& other : frames)
      if (other.frame == k.frame)
        r.fail(key + ".frame", "frame " + std::to_string(k.frame) + " appears twice");
    frames.push_back(k);
  }
  std::stable_sort(frames.begin(), frames.end(),
                   [](const auto& a, const auto& b) { return a.frame < b.frame; });
  if (cam.kind == PathKind::keyframes && frames.empty())
    r.fail("camera.keyframe", "path = \"keyframes\" needs at least one [[camera.keyframe]]");
  cam.keyframes = std::move(frames);
}

// Config folder first, then the data directory; absolute paths are taken as they are.
std::filesystem::path resolve_mesh(const Reader& r, const std::string& key, const std::string& file,
                                   const std::filesystem::path& config_dir,
                                   const std::filesystem::path& data_dir) {
  std::error_code ec;
  const std::filesystem::path p(file);
  if (p.is_absolute()) {
    if (!std::filesystem::is_regular_file(p, ec)) r.fail(key, "mesh file not found: " + p.string());
    return p;
  }
  const std::filesystem::path first = (config_dir / p).lexically_normal();
  if (std::filesystem::is_regular_file(first, ec)) return first;
  std::string tried = first.string();
  if (!data_dir.empty()) {
    const std::filesystem::path second = (data_dir / p).lexically_normal();
    if (std::filesystem::is_regular_file(second, ec)) return second;
    tried += " and " + second.string();
  } else {
    tried += " (no data directory given)";
  }
  r.fail(key, "mesh file \"" + file + "\" not found; tried " + tried);
}

// hlod = true (drawn through its HLOD tree) and its leaf size.
void read_hlod_model(const Reader& r, const toml::table& t, const std::string& key, ModelConfig& m) {
  if (const toml::node* n = t.get("hlod")) {
    const auto* b = n->as_boolean();
    if (!b) r.fail(key + ".hlod", "must be true or false");
    m.hlod = b->get();
  }
  // A baked .hlod is drawn through its tree as it is (never rebaked).
  if (m.file.extension() == ".hlod") {
    if (t.contains("hlod") && !m.hlod) r.fail(key + ".hlod", "a .hlod file is drawn through its tree: hlod cannot be false");
    if (t.contains("min_verts")) r.fail(key + ".min_verts", "a .hlod file is already built (its leaf size is in the file)");
    m.hlod = true;
  }
  r.integer_in(t, "min_verts", key + ".min_verts", 3, 100000000, m.min_verts);
  if (t.contains("min_verts") && !m.hlod) r.fail(key + ".min_verts", "needs hlod = true");
  if (m.hlod && m.view_dependent) r.fail(key + ".hlod", "a model is either hlod or view_dependent, not both");
}

// [stream]: the HLOD pager's byte budget and loader threads.
void read_stream(const Reader& r, const toml::table& root, SceneConfig& c) {
  const toml::table* t = r.table(root, "stream", "stream");
  if (!t) return;
  r.only_keys(*t, "stream", {"budget_mb", "loader_threads"});
  r.integer_in(*t, "budget_mb", "stream.budget_mb", 1, 1 << 20, c.stream.budget_mb);
  r.integer_in(*t, "loader_threads", "stream.loader_threads", 1, 64, c.stream.loader_threads);
}

// [cache] dir: where baked models are cached; relative to the config's folder.
void read_cache(const Reader& r, const toml::table& root, const std::filesystem::path& config_dir, SceneConfig& c) {
  const toml::table* t = r.table(root, "cache", "cache");
  if (!t) return;
  r.only_keys(*t, "cache", {"dir"});
  if (auto dir = r.string(*t, "dir", "cache.dir")) {
    if (dir->empty()) r.fail("cache.dir", "must not be empty (leave the key out for the default folder)");
    if (dir->find('\0') != std::string::npos) r.fail("cache.dir", "must not contain a NUL character");
    const std::filesystem::path p(*dir);
    c.cache_dir = p.is_absolute() ? p : (config_dir / p).lexically_normal();
  }
}

// [scene_hlod]: proxies over the static instances.
void read_scene_hlod(const Reader& r, const toml::table& root, SceneConfig& c) {
  const toml::table* t = r.table(root, "scene_hlod", "scene_hlod");
  if (!t) return;
  r.only_keys(*t, "scene_hlod", {"enabled", "min_objects", "reduction"});
  if (const toml::node* n = t->get("enabled")) {
    const auto* b = n->as_boolean();
    if (!b) r.fail("scene_hlod.enabled", "must be true or false");
    else c.scene_hlod.enabled = b->get();
  }
  r.integer_in(*t, "min_objects", "scene_hlod.min_objects", 2, 1 << 20, c.scene_hlod.min_objects);
  if (auto v = r.number(*t, "reduction", "scene_hlod.reduction")) {
    if (!(*v > 0 && *v < 1)) r.fail("scene_hlod.reduction", "must be between 0 and 1 (exclusive), got " + std::to_string(*v));
    else c.scene_hlod.reduction = float(*v);
  }
}

void read_models(const Reader& r, const toml::table& root, const std::filesystem::path& config_dir,
                 const std::filesystem::path& data_dir, bool required, SceneConfig& c) {
  const auto models = r.tables(root, "model", "model");
  if (models.empty() && required) r.fail("model", "no [[model]] given: a scene needs at least one");
  for (size_t i = 0; i < models.size(); ++i) {
    const toml::table& t = *models[i];
    const std::string key = indexed("model", i);
    r.only_keys(t, key,
                {"name", "file", "ratios", "method", "extreme_threshold", "view_dependent", "vd_parts", "hlod",
                 "min_verts"});
    ModelConfig m;
    auto name = r.string(t, "name", key + ".name");
    if (!name) r.fail(key + ".name", "missing");
    if (!valid_model_name(*name))
      r.fail(key + ".name",
             "\"" + *name + "\" must be 1-64 characters of A-Z a-z 0-9 _ - . (it names cache files)");
    for (const ModelConfig& other : c.models)
      if (other.name == *name) r.fail(key + ".name", "model \"" + *name + "\" is defined twice");
    m.name = *name;
    auto file = r.string(t, "file", key + ".file");
    if (!file || file->empty()) r.fail(key + ".file", "missing");
    m.file = resolve_mesh(r, key + ".file", *file, config_dir, data_dir);

    if (const toml::array* a = r.array(t, "ratios", key + ".ratios")) {
      if (a->empty()) r.fail(key + ".ratios", "is empty (omit the key for the default ratios)");
      if (a->size() > 16) r.fail(key + ".ratios", "has " + std::to_string(a->size()) + " levels; at most 16");
      for (size_t j = 0; j < a->size(); ++j) {
        const std::string rk = indexed(key + ".ratios", j);
        const double v = *r.number(*a->get(j), rk);
        // A last ratio of 0 is the culled level: the object is not drawn there.
        const bool culled = v == 0 && j > 0 && j + 1 == a->size();
        if (!culled && !(v > 0 && v <= 1))
          r.fail(rk, v == 0 ? "0 (the culled level) may only be the last ratio" : "must be in (0, 1], got " + number_text(v));
        if (j == 0 && v != 1) r.fail(rk, "must be 1.0: level 0 is the full mesh, got " + number_text(v));
        if (j > 0 && !(v < m.bake.ratios.back()))
          r.fail(rk, "ratios must decrease, but " + number_text(v) + " follows " +
                         number_text(m.bake.ratios.back()));
        m.bake.ratios.push_back(static_cast<float>(v));
      }
    }
    if (auto v = r.string(t, "method", key + ".method")) {
      if (*v == "qem")
        m.bake.method = SimplifyMethod::qem;
      else if (*v == "extreme")
        m.bake.method = SimplifyMethod::extreme;
      else if (*v == "auto")
        m.bake.method = SimplifyMethod::automatic;
      else
        r.fail(key + ".method", "must be \"qem\", \"extreme\" or \"auto\", got \"" + *v + "\"");
    }
    r.integer_in(t, "extreme_threshold", key + ".extreme_threshold", 1, INT64_MAX, m.bake.extreme_threshold);
    if (const toml::node* n = t.get("view_dependent")) {
      const auto* b = n->as_boolean();
      if (!b) r.fail(key + ".view_dependent", "must be true or false");
      m.view_dependent = b->get();
    }
    r.integer_in(t, "vd_parts", key + ".vd_parts", 1, 64, m.vd_parts);
    if (m.view_dependent && !m.bake.ratios.empty() && m.bake.ratios.back() == 0)
      r.fail(key + ".ratios", "a culled level (last ratio 0) needs view_dependent = false");
    if (m.vd_parts > 1 && !m.view_dependent) r.fail(key + ".vd_parts", "needs view_dependent = true");
    read_hlod_model(r, t, key, m);
    c.models.push_back(std::move(m));
  }
}

// motion = "none" | "wander" | "orbit", speed in world units per second (> 0 when moving).
void read_motion(const Reader& r, const toml::table& t, const std::string& key, InstanceConfig& inst) {
  if (auto v = r.string(t, "motion", key + ".motion")) {
    if (*v == "wander")
      inst.motion.kind = MotionKind::wander;
    else if (*v == "orbit")
      inst.motion.kind = MotionKind::orbit;
    else if (*v != "none")
      r.fail(key + ".motion", "must be \"none\", \"wander\" or \"orbit\", got \"" + *v + "\"");
  }
  if (auto v = r.number(t, "speed", key + ".speed")) {
    if (!(*v > 0 && *v <= 1e6)) r.fail(key + ".speed", "must be in (0, 1e6] units per second, got " + number_text(*v));
    inst.motion.speed = static_cast<float>(*v);
  }
  if (inst.motion.kind != MotionKind::none && !t.contains("speed")) r.fail(key + ".speed", "missing (motion needs a speed)");
  if (inst.motion.kind == MotionKind::none && t.contains("speed")) r.fail(key + ".speed", "needs motion = \"wander\" or \"orbit\"");
}

void read_instances(const Reader& r, const toml::table& root, bool required, SceneConfig& c) {
  const auto blocks = r.tables(root, "instances", "instances");
  if (blocks.empty() && required) r.fail("instances", "no [[instances]] given: a scene needs at least one object");
  uint64_t total = 0;
  for (size_t i = 0; i < blocks.size(); ++i) {
    const toml::table& t = *blocks[i];
    const std::string key = indexed("instances", i);
    r.only_keys(t, key,
                {"model", "count", "placement", "box_min", "box_max", "scale", "scale_range", "seed", "motion",
                 "speed", "on_terrain"});
    InstanceConfig inst;
    auto model = r.string(t, "model", key + ".model");
    if (!model) r.fail(key + ".model", "missing");
    auto it = std::find_if(c.models.begin(), c.models.end(),
                           [&](const ModelConfig& m) { return m.name == *model; });
    if (it == c.models.end())
      r.fail(key + ".model", "unknown model \"" + *model + "\" (no [[model]] has that name)");
    inst.model = static_cast<uint32_t>(it - c.models.begin());
    if (it->hlod && r.integer(t, "count", key + ".count").value_or(0) != 1)
      r.fail(key + ".count", "model \"" + *model + "\" is hlod = true: its block places exactly one object (count = 1)");

    if (!r.integer(t, "count", key + ".count")) r.fail(key + ".count", "missing");
    r.integer_in(t, "count", key + ".count", 1, static_cast<int64_t>(kMaxObjects), inst.count);
    total += inst.count;
    if (total > kMaxObjects)
      r.fail(key + ".count", "brings the scene to " + std::to_string(total) + " objects; at most " +
                                 std::to_string(kMaxObjects));

    if (auto v = r.string(t, "placement", key + ".placement")) {
      if (*v == "grid")
        inst.grid = true;
      else if (*v != "random")
        r.fail(key + ".placement", "must be \"random\" or \"grid\", got \"" + *v + "\"");
    }
    r.vec3(t, "box_min", key + ".box_min", inst.box_min);
    r.vec3(t, "box_max", key + ".box_max", inst.box_max);
    for (int a = 0; a < 3; ++a)
      if (inst.box_min[a] > inst.box_max[a])
        r.fail(key + ".box_max", std::string("is below box_min on ") + "xyz"[a] + " (" +
                                     number_text(inst.box_max[a]) + " < " + number_text(inst.box_min[a]) +
                                     ")");

    const bool has_scale = t.contains("scale");
    if (has_scale && t.contains("scale_range"))
      r.fail(key + ".scale_range", "give either scale or scale_range, not both");
    if (auto v = r.number(t, "scale", key + ".scale")) {
      if (*v <= 0) r.fail(key + ".scale", "must be > 0, got " + number_text(*v));
      inst.scale_min = inst.scale_max = static_cast<float>(*v);
    }
    if (const toml::array* a = r.array(t, "scale_range", key + ".scale_range")) {
      if (a->size() != 2)
        r.fail(key + ".scale_range", "expected [min, max], got " + std::to_string(a->size()) + " values");
      const double lo = *r.number(*a->get(0), key + ".scale_range[0]");
      const double hi = *r.number(*a->get(1), key + ".scale_range[1]");
      if (lo <= 0) r.fail(key + ".scale_range[0]", "must be > 0, got " + number_text(lo));
      if (hi < lo) r.fail(key + ".scale_range[1]", "must be >= scale_range[0], got " + number_text(hi));
      inst.scale_min = static_cast<float>(lo);
      inst.scale_max = static_cast<float>(hi);
    }
    inst.seed = default_seed(i);
    r.integer_in(t, "seed", key + ".seed", 0, INT64_MAX, inst.seed);
    read_motion(r, t, key, inst);
    if (const toml::node* n = t.get("on_terrain")) {
      const auto* b = n->as_boolean();
      if (!b) r.fail(key + ".on_terrain", "must be true or false");
      inst.on_terrain = b->get();
      if (inst.on_terrain && inst.motion.kind != MotionKind::none)
        r.fail(key + ".on_terrain", "needs a static block (a moving object would leave the ground)");
    }
    c.instances.push_back(inst);
  }
}

// [[terrain]]: at most one; its file is found like a mesh; numbers checked as they feed ROAM.
void read_terrain_shares(const Reader& r, const toml::table& t, const std::string& key, TerrainConfig& c) {
  const toml::array* a = r.array(t, "share", key + ".share");
  if (!a) return;
  if (a->size() != 3) r.fail(key + ".share", "expected [min, initial, max] fractions of the budget");
  double v[3];
  for (size_t i = 0; i < 3; ++i) v[i] = *r.number(*a->get(i), indexed(key + ".share", i));
  if (!(v[0] > 0 && v[0] <= v[1] && v[1] <= v[2] && v[2] < 1))
    r.fail(key + ".share", "needs 0 < min <= initial <= max < 1, got [" + number_text(v[0]) + ", " +
                               number_text(v[1]) + ", " + number_text(v[2]) + "]");
  c.min_share = float(v[0]), c.initial_share = float(v[1]), c.max_share = float(v[2]);
}

// Driver short names as GDAL spells them ("GTiff", "SRTMHGT"); whether this GDAL has each is
// checked when the file is read (the config reader does not link GDAL).
void read_gdal_drivers(const Reader& r, const toml::table& t, const std::string& key, TerrainConfig& c) {
  const toml::array* a = r.array(t, "gdal_drivers", key + ".gdal_drivers");
  if (!a) return;
  if (a->empty()) r.fail(key + ".gdal_drivers", "is empty; leave it out to allow every driver");
  if (a->size() > 64) r.fail(key + ".gdal_drivers", "lists " + std::to_string(a->size()) + " drivers, at most 64");
  for (size_t i = 0; i < a->size(); ++i) {
    const std::string at = indexed(key + ".gdal_drivers", i);
    const toml::value<std::string>* v = a->get(i)->as_string();
    if (!v) r.fail(at, "expected a driver name (a string such as \"GTiff\")");
    const std::string& name = v->get();
    const bool plain = !name.empty() && name.size() <= 32 &&
                       std::all_of(name.begin(), name.end(), [](char ch) { return std::isalnum(uint8_t(ch)) || ch == '_' || ch == '-'; });
    if (!plain) r.fail(at, "\"" + name.substr(0, 40) + "\" is not a GDAL driver name (letters, digits, _ and -, at most 32)");
    c.gdal_drivers.push_back(name);
  }
}

void read_terrain_grid(const Reader& r, const toml::table& t, const std::string& key, TerrainConfig& c) {
  if (auto v = r.string(t, "coordinates", key + ".coordinates")) {
    if (*v == "metres") c.coordinates = GridCoordinates::metres;
    else if (*v == "lon_lat") c.coordinates = GridCoordinates::degrees_lon_lat;
    else if (*v == "lat_lon") c.coordinates = GridCoordinates::degrees_lat_lon;
    else r.fail(key + ".coordinates", "must be \"metres\", \"lon_lat\" or \"lat_lon\", got \"" + *v + "\"");
  }
  if (const toml::node* n = t.get("cell_size")) {
    const toml::array* a = n->as_array();
    if (a && a->size() != 2) r.fail(key + ".cell_size", "expected a number or [x, y] metres");
    for (int i = 0; i < 2; ++i) {
      const double v = a ? *r.number(*a->get(size_t(i)), indexed(key + ".cell_size", size_t(i)))
                         : *r.number(*n, key + ".cell_size");
      if (!(v > 0)) r.fail(key + ".cell_size", "must be > 0 metres, got " + number_text(v));
      c.cell_size[i] = float(v);
    }
  }
  if (auto v = r.number(t, "vertical_scale", key + ".vertical_scale")) {
    if (!(*v > 0)) r.fail(key + ".vertical_scale", "must be > 0, got " + number_text(*v));
    c.vertical_scale = float(*v);
  }
  if (auto v = r.number(t, "no_data", key + ".no_data", Fit::any)) c.no_data = *v;
  if (auto v = r.string(t, "placement", key + ".placement")) {
    if (*v == "corner") c.centered = false;
    else if (*v != "center") r.fail(key + ".placement", "must be \"center\" or \"corner\", got \"" + *v + "\"");
  }
  r.vec3(t, "position", key + ".position", c.position);
  read_gdal_drivers(r, t, key, c);
  r.integer_in(t, "samples", key + ".samples", 3, 4097, c.samples);
  if (c.samples && !roam_size_valid(c.samples, c.samples))
    r.fail(key + ".samples", "must be 2^n + 1 (3, 5, 9, ..., 4097), got " + std::to_string(c.samples));
}

void read_terrain(const Reader& r, const toml::table& root, const std::filesystem::path& config_dir,
                  const std::filesystem::path& data_dir, SceneConfig& c) {
  const auto blocks = r.tables(root, "terrain", "terrain");
  if (blocks.empty()) return;
  if (blocks.size() > 1) r.fail("terrain[1]", "a scene has at most one [[terrain]]");
  const toml::table& t = *blocks[0];
  const std::string key = "terrain[0]";
  r.only_keys(t, key,
              {"file", "coordinates", "cell_size", "vertical_scale", "no_data", "placement", "position", "samples",
               "pixel_error", "target", "max_ms", "max_triangles", "share", "gdal_drivers"});
  TerrainConfig tc;
  auto file = r.string(t, "file", key + ".file");
  if (!file || file->empty()) r.fail(key + ".file", "missing");
  tc.file = resolve_mesh(r, key + ".file", *file, config_dir, data_dir);
  read_terrain_grid(r, t, key, tc);
  if (auto v = r.number(t, "pixel_error", key + ".pixel_error")) {
    if (*v <= 0 || *v > 10000) r.fail(key + ".pixel_error", "must be in (0, 10000] pixels, got " + number_text(*v));
    tc.pixel_error = float(*v);
  }
  if (auto v = r.string(t, "target", key + ".target")) {
    if (*v == "triangles") tc.target = RoamTarget::triangle_count;
    else if (*v == "time") tc.target = RoamTarget::time_limit;
    else if (*v != "pixel_error")
      r.fail(key + ".target", "must be \"pixel_error\", \"triangles\" or \"time\", got \"" + *v + "\"");
  }
  if (auto v = r.number(t, "max_ms", key + ".max_ms")) {
    if (!(*v >= 0 && *v <= 1000)) r.fail(key + ".max_ms", "must be in [0, 1000] milliseconds, got " + number_text(*v));
    else tc.max_ms = float(*v);
  }
  if (tc.target == RoamTarget::time_limit && !(tc.max_ms > 0))
    r.fail(key + ".max_ms", "target = \"time\" needs max_ms > 0 (the update's time limit per frame, milliseconds)");
  r.integer_in(t, "max_triangles", key + ".max_triangles", 2, int64_t{1} << 30, tc.max_triangles);
  read_terrain_shares(r, t, key, tc);
  c.terrain = std::move(tc);
}

}  // namespace

Status load_scene_config(const std::filesystem::path& file, const std::filesystem::path& data_dir,
                         SceneConfig& out, bool objects_optional) {
  const std::string name = file.string();
  std::error_code ec;
  if (!std::filesystem::exists(file, ec)) return Status::error(name + ": config file not found");
  std::string text;
  if (Status s = read_regular_file(file, kConfigFileLimit, text); !s) return s;
  return parse_scene_config(text, file, data_dir, out, objects_optional);
}

Status parse_scene_config(std::string_view text, const std::filesystem::path& file,
                          const std::filesystem::path& data_dir, SceneConfig& out, bool objects_optional) {
  const std::string name = file.string();
  toml::table root;
  try {
    root = toml::parse(text, name);
  } catch (const toml::parse_error& e) {
    const auto& at = e.source().begin;
    return Status::error(name + ":" + std::to_string(at.line) + ":" + std::to_string(at.column) + ": " +
                         std::string(e.description()));
  }
  SceneConfig c;
  c.file = file;
  const Reader r(name);
  try {
    r.only_keys(root, "", {"run", "budget", "lod", "visibility", "camera", "stream", "scene_hlod", "cache", "model",
                           "instances", "terrain"});
    read_run(r, root, c);
    read_budget(r, root, c);
    read_lod(r, root, c);
    read_visibility(r, root, c);
    read_camera(r, root, c);
    read_stream(r, root, c);
    read_scene_hlod(r, root, c);
    const std::filesystem::path dir =
        file.has_parent_path() ? file.parent_path() : std::filesystem::path(".");
    read_cache(r, root, dir, c);
    read_models(r, root, dir, data_dir, !objects_optional, c);
    read_instances(r, root, !objects_optional, c);
    read_terrain(r, root, dir, data_dir, c);
    for (size_t i = 0; i < c.instances.size(); ++i)
      if (c.instances[i].on_terrain && !c.terrain)
        r.fail(indexed("instances", i) + ".on_terrain", "the scene has no [[terrain]]");
  } catch (const ConfigError& e) {
    return Status::error(e.message);
  }
  out = std::move(c);
  return Status::success();
}

std::filesystem::path default_data_dir() { return LOD_DEFAULT_DATA_DIR; }

}  // namespace lod
