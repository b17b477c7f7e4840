// lod::Service: staged objects, a frame graph fired by step() or by its own thread, frames
// shared through a FramePool.
#include "jobs/service.h"

#include <cmath>
#include <cstdio>
#include <string_view>

#include "jobs/service_impl.h"
#include "runtime/lod_asset.h"
#include "runtime/object_controls.h"
#include "runtime/scene_hlod_tree.h"

namespace lod {

namespace {
thread_local std::string t_last_error;

bool fail(std::string message) {
  t_last_error = std::move(message);
  return false;
}

// A value as a message shows it: six significant digits, "nan" and "inf" spelled out.
std::string value_text(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}
}  // namespace

// ---- FrameRef ------------------------------------------------------------------------------

FrameRef& FrameRef::operator=(FrameRef&& other) noexcept {
  if (this != &other) {
    reset();
    slot_ = other.slot_;
    other.slot_ = nullptr;
  }
  return *this;
}

const Frame* FrameRef::get() const { return slot_ ? &slot_->frame : nullptr; }

void FrameRef::reset() {
  if (slot_) FramePool::release(slot_);
  slot_ = nullptr;
}

// ---- Service -------------------------------------------------------------------------------

namespace {

FrameGraphOptions graph_options_of(const ServiceOptions& o) {
  FrameGraphOptions g;
  g.threads = o.threads;
  g.selection.budget = o.budget;
  g.selection.count = o.budget_unit == BudgetUnit::levels ? BudgetCount::levels : BudgetCount::triangles;
  g.selection.reserve_blends = o.reserve_blends;
  g.selection.strict = o.strict_budget;
  g.selection.selector = o.selector == BudgetSelector::greedy_multi   ? Selector::greedy_multi
                         : o.selector == BudgetSelector::benefit_cost ? Selector::benefit_cost
                                                                      : Selector::greedy;
  g.max_distance = o.max_distance;
  g.occlusion.enabled = o.occlusion;
  g.pixel_error = o.pixel_error;
  g.hysteresis = o.hysteresis;
  g.geomorph_seconds = o.blend_seconds;
  return g;
}

}  // namespace

Service::Service(const ServiceOptions& options)
    : impl_(std::make_unique<Impl>(options, graph_options_of(options))) {}

Service::~Service() { stop(); }

bool Service::add_model(const std::filesystem::path& path, ModelId* out) {
  LodChain chain;
  if (path.extension() == ".lod") {
    if (auto st = read_lod_asset(path, chain); !st) return fail(st.message);
  } else {
    if (!impl_->options.baker) {
      return fail(path.string() + ": a mesh file needs a baker (ServiceOptions::baker = lod::mesh_baker(), "
                                  "in lodkit::lodkit); lodkit::engine loads .lod assets only");
    }
    std::string error;
    std::vector<uint8_t> asset;
    if (!impl_->options.baker(path, impl_->options.cache_dir, asset, error)) return fail(error);
    if (auto st = decode_lod_asset(asset, path.string(), chain); !st) return fail(st.message);
  }
  if (std::string why; !validate_chain(chain, &why)) return fail(path.string() + ": " + why);
  const ModelId id = impl_->add_chain(std::move(chain));
  if (out) *out = id;
  return true;
}

uint32_t Service::model_count() const { return impl_->model_count(); }

uint32_t Service::level_count(ModelId model) const {
  std::lock_guard lock(impl_->models_mutex);
  return model < impl_->chains.size() ? static_cast<uint32_t>(impl_->chains[model]->levels.size()) : 0;
}

uint64_t Service::level_triangles(ModelId model, uint32_t level) const {
  std::lock_guard lock(impl_->models_mutex);
  if (model >= impl_->chains.size() || level >= impl_->chains[model]->levels.size()) return 0;
  return impl_->chains[model]->levels[level].triangles();
}

std::optional<LevelMeshView> Service::level_mesh(ModelId model, uint32_t level) const {
  const std::shared_ptr<const ModelSurfaces> s = impl_->surfaces_of(model);
  if (!s) return fail("level_mesh: unknown model " + std::to_string(model)), std::nullopt;
  const size_t levels = s->chain->levels.size();
  if (level >= levels)
    return fail("level_mesh: model " + std::to_string(model) + " has levels 0.." + std::to_string(levels - 1) +
                ", not " + std::to_string(level)),
           std::nullopt;
  return level_mesh_view(*s, model, level);  // views into *s, which the service keeps
}

std::span<const Material> Service::materials(ModelId model) const {
  const std::shared_ptr<const ModelSurfaces> s = impl_->surfaces_of(model);
  return s ? std::span<const Material>(s->materials) : std::span<const Material>();
}

uint32_t Service::material_count(ModelId model) const { return static_cast<uint32_t>(materials(model).size()); }

const Material* Service::material(ModelId model, uint32_t index) const {
  const std::shared_ptr<const ModelSurfaces> s = impl_->surfaces_of(model);
  if (!s) return fail("material: unknown model " + std::to_string(model)), nullptr;
  if (index >= s->materials.size())
    return fail("material: model " + std::to_string(model) + " has " + std::to_string(s->materials.size()) +
                " materials, no material " + std::to_string(index)),
           nullptr;
  return &s->materials[index];
}

ObjectHandle Service::create(ModelId model, const Transform& transform, const ObjectOptions& options) {
  const ObjectHandle h = impl_->queue.create(model, impl_->model_count(), transform, options);
  if (h == 0) {
    if (model >= impl_->model_count())
      fail("create: unknown model " + std::to_string(model));
    else if (!transform_valid(transform))
      fail("create: transform must be finite with scale > 0 and a non-zero quaternion");
    else
      fail("create: options need a finite lod_bias and a finite priority > 0");
  }
  return h;
}

bool Service::destroy(ObjectHandle object) {
  return impl_->queue.destroy(object) || fail("destroy: stale or unknown handle " + std::to_string(object));
}

bool Service::set_transform(ObjectHandle object, const Transform& transform) {
  if (impl_->queue.set_transform(object, transform)) return true;
  return fail(transform_valid(transform) ? "set_transform: stale or unknown handle " + std::to_string(object)
                                         : std::string("set_transform: transform must be finite with scale > 0 "
                                                       "and a non-zero quaternion"));
}

bool Service::set_options(ObjectHandle object, const ObjectOptions& options) {
  if (impl_->queue.set_options(object, options)) return true;
  return fail(options_valid(options) ? "set_options: stale or unknown handle " + std::to_string(object)
                                     : std::string("set_options: need a finite lod_bias and a finite priority > 0"));
}

size_t Service::set_transforms(std::span<const ObjectHandle> objects, std::span<const Transform> transforms) {
  return impl_->queue.set_transforms(objects, transforms);
}

bool Service::alive(ObjectHandle object) const { return impl_->queue.live(object); }

bool Service::commit(uint64_t tick) {
  uint64_t last = 0;
  if (impl_->queue.commit(tick, &last)) return true;
  return fail("commit: tick " + std::to_string(tick) + " is below the last committed tick " + std::to_string(last) +
              " (ticks never decrease); the staged changes stay staged");
}

bool Service::set_view(uint32_t index, const Camera& camera) {
  if (index >= kMaxViews) return fail("set_view: view index " + std::to_string(index) + " is not below 8");
  if (const char* why = nullptr; !camera_valid(camera, &why)) {
    std::string message = "set_view: view " + std::to_string(index) + ": " + why;
    if (std::string_view(why).starts_with("fov_y_deg")) message += ", got " + value_text(camera.fov_y_deg);
    return fail(message);
  }
  std::lock_guard lock(impl_->view_mutex);
  impl_->views[index] = view_of(camera);
  impl_->view_count = std::max(impl_->view_count, index + 1);
  return true;
}

bool Service::set_view_count(uint32_t count) {
  if (count < 1 || count > kMaxViews) return fail("set_view_count: " + std::to_string(count) + " is not 1..8");
  std::lock_guard lock(impl_->view_mutex);
  impl_->view_count = count;
  return true;
}

bool Service::set_budget(uint64_t triangles) {
  if (triangles < kMinBudget) return fail("set_budget: " + std::to_string(triangles) + " is below 1");
  impl_->budget.store(triangles);
  return true;
}

bool Service::set_pixel_error(float pixels) {
  if (!(pixels > 0 && pixels <= kMaxPixelError))
    return fail("set_pixel_error: " + value_text(pixels) + " is not in (0, " + value_text(kMaxPixelError) + "] pixels");
  impl_->pixel_error.store(pixels);
  return true;
}

bool Service::set_hysteresis(float band) {
  if (!(band >= 0 && band <= kMaxHysteresis))
    return fail("set_hysteresis: " + value_text(band) + " is not in [0, " + value_text(kMaxHysteresis) + "]");
  impl_->hysteresis.store(band);
  return true;
}

bool Service::set_blend_seconds(float seconds) {
  if (!(seconds >= 0 && seconds <= kMaxBlendSeconds))
    return fail("set_blend_seconds: " + value_text(seconds) + " is not in [0, " + value_text(kMaxBlendSeconds) +
                "] seconds");
  impl_->blend_seconds.store(seconds);
  return true;
}

bool Service::start() {
  Impl& m = *impl_;
  if (m.is_running.exchange(true)) return fail("start: already running");
  {
    std::lock_guard lock(m.mutex);
    m.stop_requested = false;
  }
  m.thread = std::thread([&m] { m.loop(); });
  return true;
}

void Service::stop() {
  Impl& m = *impl_;
  if (!m.is_running.load()) return;
  {
    std::lock_guard lock(m.mutex);
    m.stop_requested = true;
  }
  m.wake.notify_all();
  if (m.thread.joinable()) m.thread.join();
  m.is_running.store(false);
}

bool Service::running() const { return impl_->is_running.load(); }

bool Service::step(double dt_seconds) {
  if (impl_->is_running.load()) return fail("step: the service thread is running (stop() first)");
  if (!(dt_seconds >= 0) || !std::isfinite(dt_seconds)) return fail("step: dt must be finite and >= 0");
  return impl_->run_frame(dt_seconds) || fail("step: a frame graph node failed; the last good frame is kept");
}

FrameRef Service::acquire_frame() const { return FrameRef(impl_->pool.acquire()); }

ServiceStats Service::stats() const {
  ServiceStats s;
  {
    std::lock_guard lock(impl_->mutex);
    s = impl_->stats;
  }
  s.commits = impl_->queue.commits();
  s.live_objects = impl_->queue.live_count();
  s.handle_slots = impl_->queue.slots();
  s.commit_buffers = impl_->queue.buffers();
  return s;
}

std::string Service::last_error() const { return t_last_error; }

// ---- lodkit's own tools --------------------------------------------------------------------

std::unique_ptr<Service> make_service(const Scene& scene, const FrameGraphOptions& graph, double rate_hz,
                                      std::vector<ObjectHandle>* handles) {
  ServiceOptions o;
  o.threads = graph.threads;
  o.rate_hz = rate_hz;
  auto s = std::unique_ptr<Service>(new Service(o));
  // The graph's own options (hook, grain, vd hysteresis) replace those derived from `o`.
  Service::Impl& m = s->impl();
  m.graph_options = graph;
  m.graph = std::make_unique<FrameGraph>(make_model_set({}), graph);
  m.budget = graph.selection.budget;
  m.pixel_error = graph.pixel_error;
  m.hysteresis = graph.hysteresis;
  m.blend_seconds = graph.geomorph_seconds;
  for (const LodChain& c : scene.chains) m.add_chain(c);
  const uint32_t models = m.model_count();
  std::vector<ObjectHandle> created;
  for (size_t i = 0; i < scene.objects.size(); ++i)
    created.push_back(m.queue.create(scene.objects.model[i], models, transform_of(scene.objects, i), {}));
  if (graph.scene_hlod && !graph.scene_hlod->empty()) {  // its objects by the handles just given
    auto bound = std::make_shared<SceneHlodTree>(*graph.scene_hlod);
    bind_scene_hlod_handles(*bound, created);
    m.graph_options.scene_hlod = bound;
    m.graph->set_scene_hlod(bound);
  }
  if (handles) *handles = std::move(created);
  m.queue.commit(0);
  return s;
}

ModelId add_chain(Service& service, LodChain chain) { return service.impl().add_chain(std::move(chain)); }

bool set_view(Service& service, uint32_t index, const View& view) { return service.set_view(index, camera_of(view)); }

}  // namespace lod
