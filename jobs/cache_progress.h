// Rank 0's view of a distributed bake: the cache entries it waits for appearing on shared
// storage (every rank writes there, so nothing needs sending), reported as "subtrees 61/108
// (54 cached), 0.46 M triangles/s" from a thread of its own, four times a second at most.
#pragma once
#include <condition_variable>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace lod {

class CacheProgress {
 public:
  // `paths[i]` holds `triangles[i]` once written; `noun` names the units ("subtrees").
  CacheProgress(std::string noun, std::vector<std::filesystem::path> paths, std::vector<uint64_t> triangles,
                size_t total, size_t cached, std::function<void(const std::string&)> say);
  ~CacheProgress();  // one last look, then the thread ends
  CacheProgress(const CacheProgress&) = delete;
  CacheProgress& operator=(const CacheProgress&) = delete;

 private:
  void watch();

  std::string noun_;
  std::vector<std::filesystem::path> paths_;
  std::vector<uint64_t> triangles_;
  size_t total_, cached_;
  std::function<void(const std::string&)> say_;
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stopping_ = false;
  std::thread thread_;
};

}  // namespace lod
