// FrameHandoff: the double-buffered hand-off of frames from the LOD thread to one consumer.
// The writer fills its back buffer and publishes it; the reader takes the newest published
// frame. A third, in-flight slot sits between them so that neither side ever waits: the
// writer never blocks on a slow reader, and the reader always holds one complete frame.
#pragma once
#include <atomic>
#include <cstdint>

namespace lod {

template <class T>
class FrameHandoff {
 public:
  // Writer side (one thread).
  T& back() { return slots_[back_]; }
  void publish() {
    const uint32_t prev = middle_.exchange(back_ | kFresh, std::memory_order_acq_rel);
    back_ = prev & kIndex;
  }

  // Reader side (one thread). Returns the newest complete frame; it stays valid and
  // unchanged until the next call to acquire(). Before the first publish it is a
  // default-constructed T.
  const T& acquire() {
    if (middle_.load(std::memory_order_acquire) & kFresh) {
      const uint32_t prev = middle_.exchange(front_, std::memory_order_acq_rel);
      front_ = prev & kIndex;
    }
    return slots_[front_];
  }
  // True when a frame newer than the one acquire() last returned is waiting.
  bool has_fresh() const { return (middle_.load(std::memory_order_acquire) & kFresh) != 0; }

 private:
  static constexpr uint32_t kIndex = 3;
  static constexpr uint32_t kFresh = 4;
  T slots_[3];
  uint32_t back_ = 0;                  // writer's slot
  std::atomic<uint32_t> middle_{1};    // hand-off slot, with the fresh bit
  uint32_t front_ = 2;                 // reader's slot
};

}  // namespace lod
