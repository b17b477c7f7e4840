// lod::Service: the LOD thread a simulator embeds.
//
// Threading contract
// - Object calls (create, destroy, set_transform, set_options) and commit() may come from any
//   thread; the service serialises them with a short lock that is never held across a frame.
//   They are staged: nothing a frame sees changes until commit(tick) publishes everything
//   staged since the last commit. The next frame computed after a commit uses exactly that
//   state and carries its tick (Frame::tick). Ticks never decrease: a commit whose tick is
//   below the last committed one is refused and what was staged stays staged.
// - Runtime settings (budget, pixel error, hysteresis, blend time, views) may be set from any
//   thread and apply from the next frame on. A value outside its documented range (NaN and
//   infinities included) is refused and the setting keeps its previous value.
// - Frames: acquire_frame() from any thread, by any number of consumers; a FrameRef keeps its
//   frame unchanged until it is released (destroyed). The LOD thread never waits for a
//   consumer: when every frame is held it writes a new one.
// - step(dt) runs one frame on the caller's thread (driven mode); start() runs frames on the
//   service's own thread at rate_hz (free-running). A service may be stepped, then started,
//   stopped and stepped again; step() while running returns false.
// - Errors never abort the host: calls return false / 0 and say why through last_error().
#pragma once
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "lodkit/frame.hpp"
#include "lodkit/mesh.hpp"
#include "lodkit/types.hpp"

namespace lod {

struct FrameSlot;  // where a published frame lives (internal)

// Shared read access to one published frame; move-only, released on destruction.
class FrameRef {
 public:
  FrameRef() = default;
  FrameRef(FrameRef&& other) noexcept : slot_(other.slot_) { other.slot_ = nullptr; }
  FrameRef& operator=(FrameRef&& other) noexcept;
  FrameRef(const FrameRef&) = delete;
  FrameRef& operator=(const FrameRef&) = delete;
  ~FrameRef() { reset(); }

  const Frame* get() const;  // nullptr when empty (before the first frame)
  const Frame& operator*() const { return *get(); }
  const Frame* operator->() const { return get(); }
  explicit operator bool() const { return slot_ != nullptr; }
  void reset();

 private:
  friend class Service;
  explicit FrameRef(FrameSlot* slot) : slot_(slot) {}
  FrameSlot* slot_ = nullptr;
};

enum class BudgetUnit : uint8_t {
  triangles,  // sum of selected triangles <= M
  levels,     // Yu, Liang and Chen's sum of 2^l <= M
};

// Which selector chooses levels under the budget (all meet the same M):
enum class BudgetSelector : uint8_t {
  greedy,        // Yu, Liang and Chen's max-heap, one level per pop
  greedy_multi,  // several levels per pop: far fewer pops on a cold start, about the same benefit
  benefit_cost,  // Funkhouser-Sequin's benefit/cost greedy from the coarsest levels (>= 1/2 of optimal)
};

// Turns a mesh file into the bytes of a baked .lod asset (cached in cache_dir when not empty).
// lod::mesh_baker() (in lodkit::lodkit) is lodkit's own; lodkit::engine alone has none and
// loads .lod assets only.
using ModelBaker = std::function<bool(const std::filesystem::path& mesh, const std::filesystem::path& cache_dir,
                                      std::vector<uint8_t>& asset, std::string& error)>;
// `ratios`: the levels' triangle counts as fractions of the mesh's, 1.0 first and decreasing
// (empty: lodkit's defaults by size, which stop near 6 %; scenes of tens of thousands of
// objects want deeper chains, e.g. down to 0.5 %).
ModelBaker mesh_baker(std::vector<float> ratios = {});

struct ServiceOptions {
  uint32_t threads = 0;              // task arena size; 0 = all cores
  double rate_hz = 60;               // free-running frame rate; <= 0 = as fast as frames finish
  uint64_t budget = 2000000;         // M
  BudgetUnit budget_unit = BudgetUnit::triangles;
  bool reserve_blends = true;        // hold last frame's blend extra back from M
  bool strict_budget = false;        // drawn triangles, blends included, <= M whenever the coarsest levels fit
  BudgetSelector selector = BudgetSelector::greedy;
  float max_distance = 0;            // objects farther from the camera are not drawn; 0 = no limit
  bool occlusion = false;            // cull objects hidden behind large nearby ones (view 0)
  float pixel_error = 1.0f;          // screen-space error wanted before the budget applies
  float hysteresis = 0.25f;          // relative band against level flicker
  float blend_seconds = 0.25f;       // level changes, splits and collapses blend this long
  std::filesystem::path cache_dir;   // baked assets of add_model(mesh); empty = no cache
  ModelBaker baker;                  // for add_model(mesh); from_config sets mesh_baker()
};

struct ServiceStats {
  uint64_t frames = 0;        // frames published
  uint64_t errors = 0;        // frames lost to an exception in a node (last good frame kept)
  double last_ms = 0;
  double mean_ms = 0;
  uint64_t commits = 0;       // commits accepted (a refused tick is not counted)
  uint64_t live_objects = 0;  // objects created and not destroyed (as staged)
  uint64_t handle_slots = 0;  // slots the handle table holds: its peak of live objects
  // Frames the pool holds: one more than the most ever held at once by consumers, plus the
  // one being written (each as large as the largest frame it held).
  uint64_t frame_slots = 0;
  // Commit buffers made: 1 + the most committed batches ever waiting for a frame at once.
  uint64_t commit_buffers = 0;
};

// The ranges the runtime setters accept, both ends included unless stated.
inline constexpr uint64_t kMinBudget = 1;          // set_budget: >= 1 (triangles or levels, as budget_unit)
inline constexpr float kMaxPixelError = 10000.0f;  // set_pixel_error: (0, 10000] pixels (0 excluded)
inline constexpr float kMaxHysteresis = 10.0f;     // set_hysteresis: [0, 10], a fraction of the error
inline constexpr float kMaxBlendSeconds = 60.0f;   // set_blend_seconds: [0, 60] seconds (0 = switch at once)

class Service {
 public:
  explicit Service(const ServiceOptions& options = {});
  ~Service();  // stops the thread; outstanding FrameRefs must be released first
  Service(const Service&) = delete;
  Service& operator=(const Service&) = delete;

  // A scene config (TOML): its [run]/[budget]/[lod] settings, its [[model]]s baked and its
  // [[instances]] created and committed at tick 0. Baked models are cached in the first of:
  // `cache_dir`, the config's [cache] dir, $LOD_CACHE_DIR, $XDG_CACHE_HOME/lodkit,
  // $HOME/.cache/lodkit, a lodkit-cache folder in the temp directory.
  // nullptr on error, with the message (naming the file and key) in *error.
  static std::unique_ptr<Service> from_config(const std::filesystem::path& config, std::string* error,
                                              const std::filesystem::path& data_dir = {},
                                              const std::filesystem::path& cache_dir = {});

  // Models: a mesh (OBJ, PLY, OFF, STL: baked, cached in cache_dir) or a baked .lod asset.
  // Returns false with last_error() naming the file. Models are never removed.
  bool add_model(const std::filesystem::path& path, ModelId* out);
  uint32_t model_count() const;
  uint32_t level_count(ModelId model) const;                   // 0 for an unknown model
  uint64_t level_triangles(ModelId model, uint32_t level) const;  // 0 when out of range

  // Geometry and materials for a renderer (lodkit/mesh.hpp): views into the service's own
  // immutable arrays, never copies, valid and unchanged for the service's lifetime. Safe from
  // any thread, concurrently with frames and object calls, once add_model has returned.
  // level_mesh: level `level` (0 = full detail) of `model`; its triangle count is
  // level_triangles(model, level) (the culled level, 0 triangles: every array empty).
  // nullopt, with last_error() naming the model or level, when either is out of range.
  std::optional<LevelMeshView> level_mesh(ModelId model, uint32_t level) const;
  // The materials MeshSubmesh::material indexes, in the model's order; empty for a model without
  // materials (one default surface) and for an unknown model.
  std::span<const Material> materials(ModelId model) const;
  uint32_t material_count(ModelId model) const;  // materials(model).size()
  // materials(model)[index], or nullptr with last_error() naming the model or index.
  const Material* material(ModelId model, uint32_t index) const;

  // Objects (staged until commit). 0 / false for an unknown model, a stale or unknown handle,
  // or a transform that is not finite (scale <= 0, zero quaternion).
  ObjectHandle create(ModelId model, const Transform& transform, const ObjectOptions& options = {});
  bool destroy(ObjectHandle object);
  bool set_transform(ObjectHandle object, const Transform& transform);
  bool set_options(ObjectHandle object, const ObjectOptions& options);
  // Many transforms under one lock; returns how many were accepted (stale handles skipped).
  size_t set_transforms(std::span<const ObjectHandle> objects, std::span<const Transform> transforms);
  bool alive(ObjectHandle object) const;  // as staged
  // Publishes everything staged since the last commit under `tick`. Ticks never decrease:
  // a tick below the last committed one (from_config's services commit their instances at 0)
  // returns false, last_error() names both ticks, and the staged changes stay staged for the
  // next commit. An equal tick is accepted.
  bool commit(uint64_t tick);

  // Views: up to kMaxViews; an object's level is the finest any view needs and it counts once
  // against M. set_view_count(n) uses views 0..n-1 (set_view(i) raises the count to i + 1).
  // A camera is refused (false, last_error() naming the value) unless its vectors are finite,
  // up is not parallel to forward, fov_y_deg is in [kMinFovYDeg, kMaxFovYDeg], width and height
  // are 1..65536 and 0 < near_z < far_z, far_z finite.
  bool set_view(uint32_t index, const Camera& camera);
  bool set_view_count(uint32_t count);

  // Runtime settings: false (the setting unchanged, last_error() naming the value) unless
  // budget >= kMinBudget, pixel error in (0, kMaxPixelError], hysteresis in [0, kMaxHysteresis],
  // blend time in [0, kMaxBlendSeconds]; NaN and infinities are always refused.
  bool set_budget(uint64_t triangles);
  bool set_pixel_error(float pixels);
  bool set_hysteresis(float band);
  bool set_blend_seconds(float seconds);

  bool start();  // free-running at rate_hz; false when already running
  void stop();
  bool running() const;
  // Driven mode: one frame on the caller's thread, the clock advanced by dt_seconds (>= 0).
  // False while running, or when the frame failed (counted in stats().errors).
  bool step(double dt_seconds);

  FrameRef acquire_frame() const;  // newest complete frame; empty before the first
  ServiceStats stats() const;
  std::string last_error() const;  // of the calling thread's last failed call

  struct Impl;
  Impl& impl() { return *impl_; }  // for lodkit's own tools (internal)

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace lod
