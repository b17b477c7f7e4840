// SpinLock: the staging lock of the simulation side. Its critical sections are a handful of
// stores (one staged command), where a futex mutex's lock and unlock cost more than the work;
// a waiter spins briefly, then yields, so a descheduled holder is not starved.
#pragma once
#include <atomic>
#include <thread>

namespace lod {

class SpinLock {
 public:
  void lock() {
    for (int spins = 0; flag_.exchange(true, std::memory_order_acquire);) {
      while (flag_.load(std::memory_order_relaxed)) {
        if (++spins < 64)
          pause();
        else
          std::this_thread::yield();
      }
    }
  }
  void unlock() { flag_.store(false, std::memory_order_release); }

 private:
  static void pause() {
#if defined(__x86_64__) || defined(__i386__)
    __builtin_ia32_pause();
#endif
  }
  std::atomic<bool> flag_{false};
};

}  // namespace lod
