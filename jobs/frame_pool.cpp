// FramePool: reader counts per slot; seq_cst on both sides of the count-then-check handshake,
// so a reader either sees the writer's newer pointer or the writer sees the reader's count.
#include "jobs/frame_pool.h"

namespace lod {

Frame& FramePool::back() {
  if (back_) return back_->frame;
  const FrameSlot* newest = latest_.load(std::memory_order_seq_cst);
  for (const auto& s : slots_) {
    if (s.get() != newest && s->readers.load(std::memory_order_seq_cst) == 0) {
      back_ = s.get();
      return back_->frame;
    }
  }
  slots_.push_back(std::make_unique<FrameSlot>());
  back_ = slots_.back().get();
  return back_->frame;
}

void FramePool::publish() {
  if (!back_) return;
  latest_.store(back_, std::memory_order_seq_cst);
  back_ = nullptr;
}

FrameSlot* FramePool::acquire() const {
  for (;;) {
    FrameSlot* s = latest_.load(std::memory_order_seq_cst);
    if (!s) return nullptr;
    s->readers.fetch_add(1, std::memory_order_seq_cst);
    if (latest_.load(std::memory_order_seq_cst) == s) return s;
    s->readers.fetch_sub(1, std::memory_order_seq_cst);
  }
}

}  // namespace lod
