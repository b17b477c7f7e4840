// HlodStream: the streamed HLOD models of a scene, as one frame-graph node. Owns the models'
// trees and cuts and one pager (one byte budget, one pool of loader threads) for all of them:
// their nodes are numbered one after another in the pager. Each frame selects every model's
// cut from what is resident, then hands all their requests, merged in one priority order
// (screen-space error deficit, then distance), and all their kept nodes to the pager:
//
//   view, per model: transform + share of M
//     --> select_hlod_cut(model's residency) per model --> cuts (drawn layers + boundaries)
//     --> requests merged by priority, kept nodes --> pager.update (never waits on I/O)
//
// Not thread-safe: one frame thread calls frame(); the payloads of the cuts' nodes stay valid
// until the next frame().
#pragma once
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "jobs/stream_pager.h"
#include "runtime/hlod_select.h"
#include "runtime/hlod_tree.h"

namespace lod {

// Reads one node of one model (called on the loader threads, possibly several at once).
using ModelNodeLoader = std::function<Status(uint32_t model, uint32_t node, HlodPayload& out)>;

// One model's inputs for a frame.
struct HlodModelInput {
  Transform transform;
  HlodSelectParams params;  // pixel error, its share of M
};

// The figures `lod run --json` reports per frame, summed over the models.
struct HlodStreamFigures {
  uint32_t hlod_nodes_drawn = 0;
  uint64_t hlod_triangles = 0;  // drawn layers + opened boundaries
  uint64_t resident_bytes = 0;
  uint64_t stream_requests = 0;  // loads issued so far
  uint64_t stream_loads = 0;     // completed so far
  uint64_t stream_failures = 0;
  uint64_t stream_evictions = 0;
  uint32_t holes = 0;   // requested nodes with no drawn ancestor (only missing roots)
  uint32_t wanted = 0;  // this frame's requests
};

// A node of a model that failed for good (its parent stays drawn).
struct HlodStreamFailure {
  uint32_t model = 0;
  uint32_t node = 0;  // in the model's tree
  std::string why;    // the loader's message (or the pager's reason)
};

class HlodStream {
 public:
  HlodStream(std::vector<HlodTree> trees, const StreamPagerConfig& config, ModelNodeLoader load);
  // One model.
  HlodStream(HlodTree tree, const StreamPagerConfig& config, NodeLoader load);

  // One frame: `models` has one entry per model. `frame` must increase from call to call.
  void frame(uint64_t frame, const HlodView& view, std::span<const HlodModelInput> models);
  // One model's frame.
  const HlodCut& frame(uint64_t frame, const Transform& transform, const HlodView& view,
                       const HlodSelectParams& params);

  // Set-up, before the first frame (the per-frame calls never wait): loads every model's root
  // and waits for them, so that no frame starts with a hole. False when a root failed or
  // `timeout_s` passed; frames then show the hole until the pager loads it.
  bool load_roots(double timeout_s);

  uint32_t model_count() const { return uint32_t(models_.size()); }
  const HlodTree& tree(uint32_t model) const { return models_[model].tree; }
  const HlodCut& cut(uint32_t model) const { return models_[model].cut; }
  std::span<const uint8_t> residency(uint32_t model) const;
  const std::shared_ptr<const HlodPayload>& payload(uint32_t model, uint32_t node) const {
    return pager_.payload(models_[model].first + node);
  }
  const StreamPager& pager() const { return pager_; }
  const StreamUpdate& last_update() const { return *update_; }  // pager-wide node ids
  // Every node that failed so far, load_roots' included, in the order they failed.
  std::span<const HlodStreamFailure> failures() const { return failures_; }
  HlodStreamFigures figures() const;

 private:
  struct Model {
    HlodTree tree;
    HlodCut cut;
    HlodCutScratch scratch;
    uint32_t first = 0;  // its node 0 in the pager
  };
  static std::vector<Model> models_of(std::vector<HlodTree> trees);
  static std::vector<uint64_t> bytes_of(const std::vector<Model>& models);
  Status load_node(uint32_t node, HlodPayload& out) const;
  void keep_failures(const StreamUpdate& update);

  // Declared before pager_: its loader threads read them (never written after construction).
  std::vector<Model> models_;
  std::vector<uint32_t> model_of_;  // per pager node
  ModelNodeLoader load_;
  StreamPager pager_;
  std::vector<HlodRequest> wanted_;
  std::vector<uint32_t> in_use_;
  StreamUpdate none_;
  const StreamUpdate* update_ = &none_;
  uint64_t frame_offset_ = 0;  // pager frames load_roots used
  std::vector<HlodStreamFailure> failures_;
};

}  // namespace lod
