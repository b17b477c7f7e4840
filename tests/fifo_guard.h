// A FIFO for tests that expect it to be refused unopened, and a guard that keeps the test from
// hanging when the code under test opens it anyway: after `timeout` the guard opens the FIFO for
// writing and closes it at once, which lets a blocked open (and the read after it, now at end of
// file) return. fired() then says the FIFO was opened for reading: the test fails instead of
// hanging.
#pragma once
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <filesystem>
#include <mutex>
#include <thread>

namespace lod::test {

class FifoGuard {
 public:
  explicit FifoGuard(std::filesystem::path fifo, std::chrono::milliseconds timeout = std::chrono::seconds(10))
      : fifo_(std::move(fifo)) {
    std::filesystem::remove(fifo_);
    made_ = ::mkfifo(fifo_.c_str(), 0600) == 0;
    thread_ = std::thread([this, timeout] { watch(timeout); });
  }
  ~FifoGuard() {
    {
      std::lock_guard lock(mutex_);
      done_ = true;
    }
    wake_.notify_all();
    thread_.join();
    std::error_code ec;
    std::filesystem::remove(fifo_, ec);
  }
  FifoGuard(const FifoGuard&) = delete;
  FifoGuard& operator=(const FifoGuard&) = delete;

  bool made() const { return made_; }
  // True when a reader opened the FIFO (the guard's writer got in).
  bool fired() const { return fired_; }
  const std::filesystem::path& path() const { return fifo_; }

 private:
  void watch(std::chrono::milliseconds timeout) {
    std::unique_lock lock(mutex_);
    if (wake_.wait_for(lock, timeout, [this] { return done_; })) return;
    // Time is up and the test is still running: release any reader until the test ends.
    while (!done_) {
      // O_NONBLOCK: succeeds only while a reader has the FIFO open (ENXIO otherwise).
      const int fd = ::open(fifo_.c_str(), O_WRONLY | O_NONBLOCK | O_CLOEXEC);
      if (fd >= 0) {
        fired_ = true;
        ::close(fd);
      }
      wake_.wait_for(lock, std::chrono::milliseconds(20), [this] { return done_; });
    }
  }

  std::filesystem::path fifo_;
  bool made_ = false;
  std::atomic<bool> fired_{false};
  std::mutex mutex_;
  std::condition_variable wake_;
  bool done_ = false;
  std::thread thread_;
};

}  // namespace lod::test
