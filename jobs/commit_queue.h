// CommitQueue: the hand-over of object updates from the simulation thread(s) to the LOD thread.
// Calls stage commands under a short lock (validating handles at once, so a stale handle is
// refused at the call); commit(tick) closes the staged batch in O(1) by swapping buffers; the
// LOD thread takes every closed batch at the start of a frame, applies them in order, and gives
// the buffers back for reuse. Neither side ever holds a lock while the other works on a frame,
// and a steady rate of updates allocates nothing.
#pragma once
#include <atomic>
#include <cstdint>
#include <mutex>
#include <span>
#include <vector>

#include "jobs/spin_lock.h"
#include "runtime/handle_table.h"
#include "runtime/object_commands.h"

namespace lod {

class CommitQueue {
 public:
  struct Batch {
    uint64_t tick = 0;
    std::vector<ObjectCommand> commands;
  };

  // Simulation side: any thread, serialised. `model_count` bounds create's model.
  ObjectHandle create(uint32_t model, uint32_t model_count, const Transform& t, const ObjectOptions& o);
  bool destroy(ObjectHandle h);
  bool set_transform(ObjectHandle h, const Transform& t);
  bool set_options(ObjectHandle h, const ObjectOptions& o);
  size_t set_transforms(std::span<const ObjectHandle> h, std::span<const Transform> t);
  bool live(ObjectHandle h) const;
  uint64_t live_count() const;
  uint64_t slots() const;
  uint64_t commits() const;
  // Staging buffers made so far (each grows to the largest batch it carried): 1 + the most
  // batches ever pending or in use at once, when commits outpace frames.
  uint64_t buffers() const { return buffers_.load(std::memory_order_relaxed); }
  // Closes the staged batch under `tick`. Ticks never decrease: a tick below the last
  // accepted one returns false, leaves the staged commands staged and sets *last to it.
  bool commit(uint64_t tick, uint64_t* last = nullptr);

  // LOD side (one thread): every batch committed so far, oldest first, swapped into `out`
  // (which must be empty); then hand them back with recycle().
  void take(std::vector<Batch>& out);
  void recycle(std::vector<Batch>& used);

 private:
  mutable SpinLock stage_mutex_;  // staged_, handles_, commits_
  std::vector<ObjectCommand> staged_;
  HandleTable handles_;
  uint64_t commits_ = 0;  // accepted
  uint64_t last_tick_ = 0;  // of the last accepted commit (none yet: any tick is accepted)
  std::atomic<uint64_t> buffers_{1};

  std::mutex pending_mutex_;  // pending_, spare_
  std::vector<Batch> pending_;
  std::vector<std::vector<ObjectCommand>> spare_;
};

// A transform is usable when finite, with scale > 0 and a non-zero quaternion.
bool transform_valid(const Transform& t);

}  // namespace lod
