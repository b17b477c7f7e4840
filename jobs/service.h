// lod::Service: the LOD thread a simulator embeds. It owns a FrameGraph and publishes
// frames through a FrameHandoff; the consumer reads the newest frame without waiting.
#pragma once
#include <cstdint>
#include <memory>

#include "jobs/frame_graph.h"
#include "jobs/scene.h"
#include "runtime/frame.h"
#include "runtime/view.h"

namespace lod {

struct ServiceStats {
  uint64_t frames = 0;        // frames published
  uint64_t errors = 0;        // frames lost to an exception in a node (last good frame kept)
  double last_ms = 0;
  double mean_ms = 0;
};

class Service {
 public:
  Service(const Scene& scene, const FrameGraphOptions& options, double rate_hz);
  ~Service();  // stops the thread
  Service(const Service&) = delete;
  Service& operator=(const Service&) = delete;

  // Free-running mode: a thread runs the graph at rate_hz with the latest view.
  void start();
  void stop();
  bool running() const;

  // Driven mode: run exactly one frame on the caller's thread and publish it.
  // Must not be mixed with start(). Returns false if the frame failed (error counted), or
  // without doing anything while the service thread is running.
  bool step(const View& view);

  void set_view(const View& view);        // any thread
  void set_budget(uint64_t budget);       // any thread; applied on the next frame

  // The newest complete frame; valid until the next call from the same (single) consumer.
  const Frame& latest_frame();
  ServiceStats stats() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace lod
