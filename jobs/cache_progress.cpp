#include "jobs/cache_progress.h"

#include <algorithm>
#include <chrono>
#include <cstdio>

namespace lod {

CacheProgress::CacheProgress(std::string noun, std::vector<std::filesystem::path> paths,
                             std::vector<uint64_t> triangles, size_t total, size_t cached,
                             std::function<void(const std::string&)> say)
    : noun_(std::move(noun)), paths_(std::move(paths)), triangles_(std::move(triangles)), total_(total),
      cached_(cached), say_(std::move(say)) {
  if (say_) thread_ = std::thread([this] { watch(); });
}

CacheProgress::~CacheProgress() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void CacheProgress::watch() {
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<uint8_t> seen(paths_.size(), 0);
  size_t done = 0, reported = SIZE_MAX;
  uint64_t tris = 0;
  std::unique_lock lock(mutex_);
  for (bool last = false; !last;) {
    last = stopping_;
    lock.unlock();
    for (size_t i = 0; i < paths_.size(); ++i) {
      std::error_code ec;
      if (!seen[i] && std::filesystem::is_regular_file(paths_[i], ec)) seen[i] = 1, ++done, tris += triangles_[i];
    }
    if (done != reported) {
      reported = done;
      const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      char line[200];
      std::snprintf(line, sizeof line, "%s %zu/%zu (%zu cached), %.2f M triangles/s", noun_.c_str(), cached_ + done,
                    total_, cached_, 1e-6 * double(tris) / std::max(1e-3, seconds));
      say_(line);
    }
    lock.lock();
    if (!last) wake_.wait_for(lock, std::chrono::milliseconds(250), [this] { return stopping_; });
  }
}

}  // namespace lod
