// lod::Service: a thread that fires the frame graph at a fixed rate and hands frames over.
#include "jobs/service.h"

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <thread>

#include "jobs/frame_handoff.h"

namespace lod {

struct Service::Impl {
  FrameGraph graph;
  FrameHandoff<Frame> handoff;  // the service thread (or step's caller) writes, one consumer reads
  double rate_hz;
  std::atomic<uint64_t> budget;
  std::atomic<bool> is_running{false};

  mutable std::mutex mutex;  // guards view, stop_requested and stats
  std::condition_variable wake;
  View view;
  bool stop_requested = false;
  ServiceStats stats;
  std::thread thread;

  Impl(const Scene& scene, const FrameGraphOptions& options, double rate)
      : graph(scene, options), rate_hz(rate), budget(options.selection.budget) {}

  // One frame into the back buffer; published only when every stage succeeded, so the
  // consumer keeps the last good frame when one fails.
  bool run_frame(const View& v) {
    Frame& back = handoff.back();
    try {
      graph.set_budget(budget.load(std::memory_order_relaxed));
      graph.run(v, back);  // resets its own state before rethrowing
    } catch (...) {
      std::lock_guard lock(mutex);
      ++stats.errors;
      return false;
    }
    const double ms = back.total_ms;
    handoff.publish();
    std::lock_guard lock(mutex);
    ++stats.frames;
    stats.last_ms = ms;
    stats.mean_ms += (ms - stats.mean_ms) / static_cast<double>(stats.frames);
    return true;
  }

  void loop() {
    using Clock = std::chrono::steady_clock;
    // rate_hz <= 0 means free-running as fast as frames complete.
    const Clock::duration period =
        rate_hz > 0
            ? std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / rate_hz))
            : Clock::duration::zero();
    Clock::time_point next = Clock::now();
    for (;;) {
      View v;
      {
        std::lock_guard lock(mutex);
        if (stop_requested) break;
        v = view;
      }
      run_frame(v);
      next += period;
      const Clock::time_point now = Clock::now();
      if (next < now) next = now;  // fell behind: start the next frame now, never burst to catch up
      std::unique_lock lock(mutex);
      // A condition variable rather than sleep_until, so that stop() wakes it at once.
      if (wake.wait_until(lock, next, [&] { return stop_requested; })) break;
    }
  }
};

Service::Service(const Scene& scene, const FrameGraphOptions& options, double rate_hz)
    : impl_(std::make_unique<Impl>(scene, options, rate_hz)) {}

Service::~Service() { stop(); }

void Service::start() {
  Impl& m = *impl_;
  if (m.is_running.load()) return;
  {
    std::lock_guard lock(m.mutex);
    m.stop_requested = false;
  }
  m.is_running.store(true);
  m.thread = std::thread([&m] { m.loop(); });
}

void Service::stop() {
  Impl& m = *impl_;
  if (!m.is_running.load()) return;
  {
    std::lock_guard lock(m.mutex);
    m.stop_requested = true;
  }
  m.wake.notify_all();
  m.thread.join();
  m.is_running.store(false);
}

bool Service::running() const { return impl_->is_running.load(); }

bool Service::step(const View& view) {
  if (impl_->is_running.load()) return false;  // the service thread owns the graph
  return impl_->run_frame(view);
}

void Service::set_view(const View& view) {
  std::lock_guard lock(impl_->mutex);
  impl_->view = view;
}

void Service::set_budget(uint64_t budget) { impl_->budget.store(budget, std::memory_order_relaxed); }

const Frame& Service::latest_frame() { return impl_->handoff.acquire(); }

ServiceStats Service::stats() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->stats;
}

}  // namespace lod
