// The C API (include/lodkit/lodkit.h) over lod::Service.
//
// Every entry point catches everything: no C++ exception crosses into C. A failure returns
// nonzero / 0 / NULL, writes the message into the caller's buffer where there is one
// (always NUL-terminated, truncated to fit) and into a per-thread buffer lod_last_error()
// returns. The per-thread buffer is a fixed array so that reporting an error cannot itself
// fail (no allocation while handling bad_alloc).
#include "lodkit/lodkit.h"

#include <cstddef>
#include <cstring>
#include <exception>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>
#include <unordered_set>

#include "lodkit/service.hpp"

// lodkit.h promises its structs are laid out exactly like their C++ twins (so a binding may
// hand over arrays of either); the copies below go field by field all the same.
static_assert(std::is_same_v<lod_object, lod::ObjectHandle>);
static_assert(std::is_same_v<lod_model, lod::ModelId>);
static_assert(sizeof(lod_transform) == sizeof(lod::Transform));
static_assert(offsetof(lod_transform, position) == offsetof(lod::Transform, position));
static_assert(offsetof(lod_transform, rotation) == offsetof(lod::Transform, rotation));
static_assert(offsetof(lod_transform, scale) == offsetof(lod::Transform, scale));
static_assert(sizeof(lod_view) == sizeof(lod::Camera));
static_assert(offsetof(lod_view, eye) == offsetof(lod::Camera, eye));
static_assert(offsetof(lod_view, forward) == offsetof(lod::Camera, forward));
static_assert(offsetof(lod_view, up) == offsetof(lod::Camera, up));
static_assert(offsetof(lod_view, fov_y_deg) == offsetof(lod::Camera, fov_y_deg));
static_assert(offsetof(lod_view, width) == offsetof(lod::Camera, width));
static_assert(offsetof(lod_view, height) == offsetof(lod::Camera, height));
static_assert(offsetof(lod_view, near_z) == offsetof(lod::Camera, near_z));
static_assert(offsetof(lod_view, far_z) == offsetof(lod::Camera, far_z));
// Level meshes hand the service's submesh runs over in place.
static_assert(sizeof(lod_submesh) == sizeof(lod::MeshSubmesh) && alignof(lod_submesh) == alignof(lod::MeshSubmesh));
static_assert(offsetof(lod_submesh, first_index) == offsetof(lod::MeshSubmesh, first_index));
static_assert(offsetof(lod_submesh, index_count) == offsetof(lod::MeshSubmesh, index_count));
static_assert(offsetof(lod_submesh, material) == offsetof(lod::MeshSubmesh, material));
static_assert(std::is_standard_layout_v<lod_submesh> && std::is_standard_layout_v<lod::MeshSubmesh>);
static_assert(int(lod::MaterialAlpha::opaque) == 0 && int(lod::MaterialAlpha::mask) == 1 &&
              int(lod::MaterialAlpha::blend) == 2);
// lodkit.h's ranges are the service's.
static_assert(LOD_MIN_BUDGET == lod::kMinBudget);
static_assert(LOD_MAX_PIXEL_ERROR == lod::kMaxPixelError);
static_assert(LOD_MAX_HYSTERESIS == lod::kMaxHysteresis);
static_assert(LOD_MAX_BLEND_SECONDS == lod::kMaxBlendSeconds);
static_assert(LOD_MIN_FOV_Y_DEG == lod::kMinFovYDeg);
static_assert(LOD_MAX_FOV_Y_DEG == lod::kMaxFovYDeg);

// A frame handed to C: the FrameRef keeps the frame unchanged until lod_frame_release.
struct lod_frame {
  lod::FrameRef ref;
};

struct lod_service {
  std::unique_ptr<lod::Service> service;
  // Frames handed out and not yet released. Lets release refuse a pointer it never gave out
  // (or gave out and took back), and lets destroy release what the caller forgot, which the
  // Service's destructor requires.
  std::mutex frames_mutex;
  std::unordered_set<const lod_frame*> frames;
};

namespace {

constexpr size_t kErrorCapacity = 1024;
thread_local char tls_error[kErrorCapacity] = "";

// Out of line: inlined into callers that pass a temporary std::string, GCC 12's -O3
// -Warray-bounds mistakes the copy for a read past the string's small buffer.
[[gnu::noinline]] void copy_truncated(std::string_view text, char* out, size_t size) noexcept {
  if (!out || size == 0) return;
  const size_t n = text.size() < size - 1 ? text.size() : size - 1;
  std::memcpy(out, text.data(), n);
  out[n] = '\0';
}

// Records a failure; returns the nonzero status of the int-returning calls.
int fail(std::string_view message, char* error = nullptr, size_t error_size = 0) noexcept {
  if (message.empty()) message = "failed (no reason given)";
  copy_truncated(message, tls_error, kErrorCapacity);
  copy_truncated(message, error, error_size);
  return 1;
}

// The service's own reason for the failure of its last call on this thread.
int fail_from(const lod_service* s, std::string_view what, char* error = nullptr, size_t error_size = 0) noexcept {
  try {
    const std::string why = s->service->last_error();
    return fail(why.empty() ? std::string(what) : why, error, error_size);
  } catch (...) {
    return fail(what, error, error_size);
  }
}

// Runs `body`, turning any exception into a recorded failure and `on_error`.
template <class R, class Body>
R guarded(R on_error, char* error, size_t error_size, Body&& body) noexcept {
  try {
    return body();
  } catch (const std::exception& e) {
    fail(e.what(), error, error_size);
  } catch (...) {
    fail("unknown exception", error, error_size);
  }
  return on_error;
}

template <class Body>
void guarded_void(Body&& body) noexcept {
  try {
    body();
  } catch (const std::exception& e) {
    fail(e.what());
  } catch (...) {
    fail("unknown exception");
  }
}

bool usable(const lod_service* s) noexcept { return s && s->service; }

template <class T, size_t N>
void copy_array(T (&to)[N], const T (&from)[N]) noexcept {
  for (size_t k = 0; k < N; ++k) to[k] = from[k];
}

lod::Transform to_transform(const lod_transform& t) noexcept {
  lod::Transform out;
  copy_array(out.position, t.position);
  copy_array(out.rotation, t.rotation);
  out.scale = t.scale;
  return out;
}

lod_transform to_c(const lod::Transform& t) noexcept {
  lod_transform out;
  copy_array(out.position, t.position);
  copy_array(out.rotation, t.rotation);
  out.scale = t.scale;
  return out;
}

lod::Camera to_camera(const lod_view& v) noexcept {
  lod::Camera out;
  copy_array(out.eye, v.eye);
  copy_array(out.forward, v.forward);
  copy_array(out.up, v.up);
  out.fov_y_deg = v.fov_y_deg;
  out.width = v.width;
  out.height = v.height;
  out.near_z = v.near_z;
  out.far_z = v.far_z;
  return out;
}

template <class T>
const T* data_or_null(std::span<const T> a) noexcept {
  return a.empty() ? nullptr : a.data();
}

// A string_view the service made from a std::string (so NUL-terminated), NULL when empty.
const char* c_string_or_null(std::string_view s) noexcept { return s.empty() ? nullptr : s.data(); }

lod_texture to_c(const lod::MaterialTexture& t) noexcept {
  lod_texture out{};
  if (t.empty()) return out;
  out.path = c_string_or_null(t.path);
  out.bytes = data_or_null(t.bytes);
  out.size = t.bytes.size();
  out.mime = c_string_or_null(t.mime);
  out.texcoord = t.texcoord;
  return out;
}

}  // namespace

extern "C" {

lod_service* lod_service_create(const char* config_path, char* error, size_t error_size) {
  copy_truncated("", error, error_size);
  if (!config_path) return fail("lod_service_create: config_path is NULL", error, error_size), nullptr;
  return guarded<lod_service*>(nullptr, error, error_size, [&]() -> lod_service* {
    std::string why;
    std::unique_ptr<lod::Service> service = lod::Service::from_config(config_path, &why);
    if (!service) {
      fail(why.empty() ? std::string(config_path) + ": could not create the service" : why, error, error_size);
      return nullptr;
    }
    auto* s = new lod_service;
    s->service = std::move(service);
    return s;
  });
}

void lod_service_destroy(lod_service* s) {
  if (!s) return;
  guarded_void([&] {
    {
      const std::lock_guard<std::mutex> lock(s->frames_mutex);
      for (const lod_frame* f : s->frames) delete f;
      s->frames.clear();
    }
    delete s;  // stops the LOD thread
  });
}

int lod_model_add(lod_service* s, const char* path, lod_model* out, char* error, size_t error_size) {
  copy_truncated("", error, error_size);
  if (!usable(s)) return fail("lod_model_add: service is NULL", error, error_size);
  if (!path) return fail("lod_model_add: path is NULL", error, error_size);
  if (!out) return fail("lod_model_add: out is NULL", error, error_size);
  return guarded(1, error, error_size, [&] {
    lod::ModelId id = 0;
    if (!s->service->add_model(path, &id)) return fail_from(s, std::string(path) + ": could not be added", error, error_size);
    *out = id;
    return 0;
  });
}

uint32_t lod_model_level_count(lod_service* s, lod_model model) {
  if (!usable(s)) return fail("lod_model_level_count: service is NULL"), 0u;
  return guarded(0u, nullptr, 0, [&] { return s->service->level_count(model); });
}

uint64_t lod_model_level_triangles(lod_service* s, lod_model model, uint32_t level) {
  if (!usable(s)) return fail("lod_model_level_triangles: service is NULL"), uint64_t(0);
  return guarded(uint64_t(0), nullptr, 0, [&] { return s->service->level_triangles(model, level); });
}

int lod_model_level_mesh(lod_service* s, lod_model model, uint32_t level, lod_mesh* out) {
  if (!usable(s)) return fail("lod_model_level_mesh: service is NULL");
  if (!out) return fail("lod_model_level_mesh: out is NULL");
  return guarded(1, nullptr, 0, [&] {
    const std::optional<lod::LevelMeshView> m = s->service->level_mesh(model, level);
    if (!m) return fail_from(s, "lod_model_level_mesh: model " + std::to_string(model) + " level " + std::to_string(level));
    lod_mesh c{};
    c.id = m->id;
    c.vertex_count = m->vertex_count;
    c.index_count = m->index_count();
    c.positions = data_or_null(m->positions);
    c.normals = data_or_null(m->normals);
    c.uvs = data_or_null(m->uvs);
    c.colors = data_or_null(m->colors);
    c.morph_positions = data_or_null(m->morph_positions);
    c.indices = data_or_null(m->indices);
    c.submesh_count = static_cast<uint32_t>(m->submeshes.size());
    c.submeshes = reinterpret_cast<const lod_submesh*>(data_or_null(m->submeshes));  // same layout (asserted above)
    *out = c;
    return 0;
  });
}

uint32_t lod_model_material_count(lod_service* s, lod_model model) {
  if (!usable(s)) return fail("lod_model_material_count: service is NULL"), 0u;
  return guarded(0u, nullptr, 0, [&] {
    if (model >= s->service->model_count()) return fail("lod_model_material_count: unknown model " + std::to_string(model)), 0u;
    return s->service->material_count(model);
  });
}

int lod_model_material(lod_service* s, lod_model model, uint32_t index, lod_material* out) {
  if (!usable(s)) return fail("lod_model_material: service is NULL");
  if (!out) return fail("lod_model_material: out is NULL");
  return guarded(1, nullptr, 0, [&] {
    const lod::Material* m = s->service->material(model, index);
    if (!m) return fail_from(s, "lod_model_material: model " + std::to_string(model) + " material " + std::to_string(index));
    lod_material c{};
    copy_array(c.base_color, m->base_color);
    c.metallic = m->metallic;
    c.roughness = m->roughness;
    copy_array(c.emissive, m->emissive);
    c.alpha_mode = static_cast<int>(m->alpha_mode);
    c.alpha_cutoff = m->alpha_cutoff;
    c.double_sided = m->double_sided ? 1 : 0;
    c.base_color_texture = to_c(m->base_color_texture);
    c.metallic_roughness_texture = to_c(m->metallic_roughness_texture);
    c.normal_texture = to_c(m->normal_texture);
    c.occlusion_texture = to_c(m->occlusion_texture);
    c.emissive_texture = to_c(m->emissive_texture);
    *out = c;
    return 0;
  });
}

lod_object lod_object_create(lod_service* s, lod_model model, const lod_transform* transform) {
  if (!usable(s)) return fail("lod_object_create: service is NULL"), lod_object(0);
  if (!transform) return fail("lod_object_create: transform is NULL"), lod_object(0);
  return guarded(lod_object(0), nullptr, 0, [&] {
    const lod::ObjectHandle h = s->service->create(model, to_transform(*transform));
    if (h == 0) fail_from(s, "lod_object_create: model " + std::to_string(model) + " or transform refused");
    return h;
  });
}

int lod_object_destroy(lod_service* s, lod_object object) {
  if (!usable(s)) return fail("lod_object_destroy: service is NULL");
  return guarded(1, nullptr, 0, [&] {
    return s->service->destroy(object) ? 0 : fail_from(s, "lod_object_destroy: stale or unknown handle");
  });
}

int lod_object_set_transform(lod_service* s, lod_object object, const lod_transform* transform) {
  if (!usable(s)) return fail("lod_object_set_transform: service is NULL");
  if (!transform) return fail("lod_object_set_transform: transform is NULL");
  return guarded(1, nullptr, 0, [&] {
    return s->service->set_transform(object, to_transform(*transform))
               ? 0
               : fail_from(s, "lod_object_set_transform: stale or unknown handle, or a transform that is not finite");
  });
}

void lod_object_options_default(lod_object_options* out) {
  if (!out) return;
  const lod::ObjectOptions d;
  out->lod_bias = d.lod_bias;
  out->min_level = d.min_level;
  out->max_level = d.max_level;
  out->priority = d.priority;
  out->forced_level = d.forced_level;
  out->never_cull = d.never_cull ? 1 : 0;
}

int lod_object_set_options(lod_service* s, lod_object object, const lod_object_options* options) {
  if (!usable(s)) return fail("lod_object_set_options: service is NULL");
  if (!options) return fail("lod_object_set_options: options is NULL");
  return guarded(1, nullptr, 0, [&] {
    // The C fields are wider than the C++ ones: a finest level beyond 255 names no level; a
    // coarsest level beyond it means "the chain's last" (the service clamps to the chain).
    if (options->min_level > 255)
      return fail("lod_object_set_options: min_level " + std::to_string(options->min_level) +
                  " is beyond any chain (max 255)");
    if (options->forced_level < -1 || options->forced_level > 255)
      return fail("lod_object_set_options: forced_level " + std::to_string(options->forced_level) +
                  " is neither -1 (not forced) nor a level 0..255");
    lod::ObjectOptions o;
    o.lod_bias = options->lod_bias;
    o.min_level = uint8_t(options->min_level);
    o.max_level = uint8_t(options->max_level > 255 ? 255 : options->max_level);
    o.priority = options->priority;
    o.forced_level = int16_t(options->forced_level);
    o.never_cull = options->never_cull != 0;
    return s->service->set_options(object, o) ? 0
                                              : fail_from(s, "lod_object_set_options: stale or unknown handle, or bad options");
  });
}

int lod_commit(lod_service* s, uint64_t tick) {
  if (!usable(s)) return fail("lod_commit: service is NULL");
  return guarded(1, nullptr, 0, [&] { return s->service->commit(tick) ? 0 : fail_from(s, "lod_commit: refused"); });
}

int lod_set_view(lod_service* s, uint32_t view_index, const lod_view* view) {
  if (!usable(s)) return fail("lod_set_view: service is NULL");
  if (!view) return fail("lod_set_view: view is NULL");
  return guarded(1, nullptr, 0, [&] {
    if (view_index >= lod::kMaxViews)
      return fail("lod_set_view: view index " + std::to_string(view_index) + " >= " + std::to_string(lod::kMaxViews));
    return s->service->set_view(view_index, to_camera(*view)) ? 0 : fail_from(s, "lod_set_view: bad view");
  });
}

int lod_set_view_count(lod_service* s, uint32_t count) {
  if (!usable(s)) return fail("lod_set_view_count: service is NULL");
  return guarded(1, nullptr, 0, [&] {
    if (count < 1 || count > lod::kMaxViews)
      return fail("lod_set_view_count: " + std::to_string(count) + " is not in 1.." + std::to_string(lod::kMaxViews));
    return s->service->set_view_count(count) ? 0 : fail_from(s, "lod_set_view_count: refused");
  });
}

int lod_set_budget(lod_service* s, uint64_t triangles) {
  if (!usable(s)) return fail("lod_set_budget: service is NULL");
  return guarded(1, nullptr, 0, [&] {
    return s->service->set_budget(triangles) ? 0 : fail_from(s, "lod_set_budget: refused");
  });
}

int lod_set_pixel_error(lod_service* s, float pixels) {
  if (!usable(s)) return fail("lod_set_pixel_error: service is NULL");
  return guarded(1, nullptr, 0, [&] {
    return s->service->set_pixel_error(pixels) ? 0 : fail_from(s, "lod_set_pixel_error: refused");
  });
}

int lod_set_hysteresis(lod_service* s, float band) {
  if (!usable(s)) return fail("lod_set_hysteresis: service is NULL");
  return guarded(1, nullptr, 0, [&] {
    return s->service->set_hysteresis(band) ? 0 : fail_from(s, "lod_set_hysteresis: refused");
  });
}

int lod_set_blend_seconds(lod_service* s, float seconds) {
  if (!usable(s)) return fail("lod_set_blend_seconds: service is NULL");
  return guarded(1, nullptr, 0, [&] {
    return s->service->set_blend_seconds(seconds) ? 0 : fail_from(s, "lod_set_blend_seconds: refused");
  });
}

int lod_start(lod_service* s) {
  if (!usable(s)) return fail("lod_start: service is NULL");
  return guarded(1, nullptr, 0, [&] { return s->service->start() ? 0 : fail_from(s, "lod_start: already running"); });
}

void lod_stop(lod_service* s) {
  if (!usable(s)) return (void)fail("lod_stop: service is NULL");
  guarded_void([&] { s->service->stop(); });
}

int lod_step(lod_service* s, double dt_seconds) {
  if (!usable(s)) return fail("lod_step: service is NULL");
  return guarded(1, nullptr, 0, [&] {
    return s->service->step(dt_seconds) ? 0 : fail_from(s, "lod_step: running, a bad dt, or the frame failed");
  });
}

const lod_frame* lod_frame_acquire(lod_service* s) {
  if (!usable(s)) return fail("lod_frame_acquire: service is NULL"), nullptr;
  return guarded<const lod_frame*>(nullptr, nullptr, 0, [&]() -> const lod_frame* {
    lod::FrameRef ref = s->service->acquire_frame();
    if (!ref || !ref.get()) return fail("lod_frame_acquire: no frame published yet"), nullptr;
    auto holder = std::make_unique<lod_frame>();
    holder->ref = std::move(ref);
    const std::lock_guard<std::mutex> lock(s->frames_mutex);
    s->frames.insert(holder.get());
    return holder.release();
  });
}

void lod_frame_release(lod_service* s, const lod_frame* frame) {
  if (!frame) return;
  if (!usable(s)) return (void)fail("lod_frame_release: service is NULL");
  guarded_void([&] {
    {
      const std::lock_guard<std::mutex> lock(s->frames_mutex);
      if (s->frames.erase(frame) == 0) {
        fail("lod_frame_release: not a frame this service handed out, or released already");
        return;
      }
    }
    delete frame;  // the FrameRef inside releases the frame
  });
}

void lod_frame_info_get(const lod_frame* frame, lod_frame_info* info) {
  if (!info) return;
  *info = lod_frame_info{};
  if (!frame || !frame->ref) return (void)fail("lod_frame_info_get: frame is NULL");
  const lod::Frame& f = *frame->ref;
  info->index = f.index;
  info->tick = f.tick;
  info->objects = f.object_count;
  info->visible = uint32_t(f.handles.size());  // the entries lod_frame_entry_get serves
  info->tris_selected = f.tris_selected;
  info->budget = f.budget;
  info->over_budget = f.over_budget ? 1 : 0;
}

int lod_frame_entry_get(const lod_frame* frame, uint32_t i, lod_frame_entry* entry) {
  if (!entry) return fail("lod_frame_entry_get: entry is NULL");
  if (!frame || !frame->ref) return fail("lod_frame_entry_get: frame is NULL");
  return guarded(1, nullptr, 0, [&] {
    const lod::Frame& f = *frame->ref;
    const size_t n = f.handles.size();
    if (i >= n) return fail("lod_frame_entry_get: entry " + std::to_string(i) + " of " + std::to_string(n));
    // Every per-entry column must cover entry i; a frame whose columns disagree is refused
    // rather than read past an end.
    if (f.levels.size() < n || f.from_levels.size() < n || f.morph.size() < n || f.view_masks.size() < n ||
        f.transforms.size() < n)
      return fail("lod_frame_entry_get: the frame's per-entry columns are shorter than its handles");
    entry->object = f.handles[i];
    entry->level = f.levels[i];
    entry->from_level = f.from_levels[i];
    entry->morph = f.morph[i];
    entry->view_mask = f.view_masks[i];
    entry->transform = to_c(f.transforms[i]);
    return 0;
  });
}

const char* lod_last_error(void) { return tls_error; }

}  // extern "C"
