// Service::Impl: the service's state, for jobs/ files that build services (service.cpp,
// service_config.cpp). Not installed.
#pragma once
#include <array>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include "jobs/commit_queue.h"
#include "jobs/frame_graph.h"
#include "jobs/frame_pool.h"
#include "jobs/model_surfaces.h"
#include "lodkit/service.hpp"
#include "runtime/view.h"

namespace lod {

struct Service::Impl {
  ServiceOptions options;
  FrameGraphOptions graph_options;
  CommitQueue queue;

  mutable std::mutex models_mutex;  // chains, surfaces, models_version
  std::vector<std::shared_ptr<const LodChain>> chains;
  std::vector<std::shared_ptr<const ModelSurfaces>> surfaces;  // per model, built when it is added
  uint64_t models_version = 0;

  // The LOD side: one frame at a time, on the service thread or step()'s caller.
  std::mutex frame_mutex;
  std::unique_ptr<FrameGraph> graph;
  uint64_t graph_models_version = 0;
  ObjectStore store;
  std::vector<CommitQueue::Batch> taken;
  std::vector<CommitBatchRef> refs;
  std::vector<std::shared_ptr<const LodChain>> chains_copy;
  FramePool pool;
  double clock = 0;
  std::array<View, kMaxViews> frame_views{};

  std::atomic<uint64_t> budget;
  std::atomic<float> pixel_error, hysteresis, blend_seconds;
  mutable std::mutex view_mutex;  // views, view_count
  std::array<View, kMaxViews> views{};
  uint32_t view_count = 1;

  mutable std::mutex mutex;  // stop_requested, stats
  std::condition_variable wake;
  bool stop_requested = false;
  ServiceStats stats;
  std::thread thread;
  std::atomic<bool> is_running{false};

  Impl(const ServiceOptions& o, const FrameGraphOptions& g)
      : options(o),
        graph_options(g),
        budget(g.selection.budget),
        pixel_error(g.pixel_error),
        hysteresis(g.hysteresis),
        blend_seconds(g.geomorph_seconds) {
    graph = std::make_unique<FrameGraph>(make_model_set({}), graph_options);
  }

  // Model `model`'s surfaces, or null for an unknown model.
  std::shared_ptr<const ModelSurfaces> surfaces_of(ModelId model) const {
    std::lock_guard lock(models_mutex);
    return model < surfaces.size() ? surfaces[model] : nullptr;
  }

  uint32_t model_count() const {
    std::lock_guard lock(models_mutex);
    return static_cast<uint32_t>(chains.size());
  }

  ModelId add_chain(LodChain chain) {
    auto c = std::make_shared<const LodChain>(std::move(chain));
    std::shared_ptr<const ModelSurfaces> s = build_model_surfaces(c);
    std::lock_guard lock(models_mutex);
    chains.push_back(std::move(c));
    surfaces.push_back(std::move(s));
    ++models_version;
    return static_cast<ModelId>(chains.size() - 1);
  }

  // Batches first, models second: a create in a batch names a model added before it was
  // staged, so the models read after the batches include it.
  void gather_inputs() {
    queue.take(taken);
    refs.clear();
    for (const CommitQueue::Batch& b : taken) refs.push_back({b.tick, b.commands});
    {
      std::lock_guard lock(models_mutex);
      if (models_version != graph_models_version) {
        chains_copy = chains;
        graph_models_version = models_version;
      } else {
        chains_copy.clear();
      }
    }
    if (!chains_copy.empty()) graph->set_models(make_model_set(chains_copy));
    graph->set_budget(budget.load(std::memory_order_relaxed));
    graph->set_pixel_error(pixel_error.load(std::memory_order_relaxed));
    graph->set_hysteresis(hysteresis.load(std::memory_order_relaxed));
    graph->set_geomorph_seconds(blend_seconds.load(std::memory_order_relaxed));
  }

  // One frame into a pool slot; published only when every node succeeded, so consumers keep
  // the last good frame when one fails.
  bool run_frame(double dt) {
    std::lock_guard frame_lock(frame_mutex);
    gather_inputs();
    uint32_t vc;
    {
      std::lock_guard lock(view_mutex);
      vc = view_count;
      frame_views = views;
    }
    clock += dt;
    Frame& back = pool.back();
    FrameInput in;
    in.views = std::span<const View>(frame_views.data(), vc);
    in.time = clock;
    in.commits = refs;
    bool ok = true;
    try {
      graph->run(in, store, back);  // resets its own state before rethrowing
    } catch (...) {
      ok = false;
    }
    queue.recycle(taken);
    std::lock_guard lock(mutex);
    if (!ok) {
      ++stats.errors;
      return false;
    }
    const double ms = back.total_ms;
    pool.publish();
    stats.frame_slots = pool.slots();
    ++stats.frames;
    stats.last_ms = ms;
    stats.mean_ms += (ms - stats.mean_ms) / static_cast<double>(stats.frames);
    return true;
  }

  void loop() {
    using Clock = std::chrono::steady_clock;
    const double rate = options.rate_hz;
    // rate_hz <= 0 means free-running as fast as frames complete.
    const Clock::duration period =
        rate > 0 ? std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / rate))
                 : Clock::duration::zero();
    Clock::time_point last = Clock::now() - period;  // the first frame advances one period
    Clock::time_point next = Clock::now();
    for (;;) {
      {
        std::lock_guard lock(mutex);
        if (stop_requested) break;
      }
      const Clock::time_point now = Clock::now();
      run_frame(std::chrono::duration<double>(now - last).count());
      last = now;
      next += period;
      const Clock::time_point after = Clock::now();
      if (next < after) next = after;  // fell behind: start the next frame now, never burst to catch up
      std::unique_lock lock(mutex);
      // A condition variable rather than sleep_until, so that stop() wakes it at once.
      if (wake.wait_until(lock, next, [&] { return stop_requested; })) break;
    }
  }
};

}  // namespace lod
