// FramePool: frames shared by any number of consumers while the LOD thread writes the next.
// Each slot counts its readers. A consumer takes the newest published slot by counting itself
// in and checking the slot is still the newest (else it steps back and retries: the writer may
// have reused it meanwhile). The writer writes into a slot no one reads that is not the newest,
// and makes a new slot when every one is held, so it never waits for a consumer; slots are
// kept, so a steady number of consumers allocates nothing.
#pragma once
#include <atomic>
#include <cstdint>
#include <memory>
#include <vector>

#include "lodkit/frame.hpp"

namespace lod {

struct FrameSlot {
  Frame frame;
  std::atomic<uint32_t> readers{0};
};

class FramePool {
 public:
  // Writer side (one thread at a time).
  Frame& back();   // a slot to fill; stays the writer's until publish()
  void publish();  // the filled slot becomes the newest
  size_t slots() const { return slots_.size(); }

  // Any thread. nullptr before the first publish.
  FrameSlot* acquire() const;
  static void release(FrameSlot* slot) { slot->readers.fetch_sub(1, std::memory_order_seq_cst); }

 private:
  std::vector<std::unique_ptr<FrameSlot>> slots_;  // the writer's; consumers only hold pointers
  FrameSlot* back_ = nullptr;
  std::atomic<FrameSlot*> latest_{nullptr};
};

}  // namespace lod
