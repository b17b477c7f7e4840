// Processes on one host that write into one file take turns (every rank writes its
// payloads into the shared .hlod). The kernel serialises buffered writes into one file anyway
// (its inode lock), and a writer waiting for that lock spins on its core: at 2 ranks a third of
// each rank's write phase went to spinning. A turn is an flock on a lock file in this host's
// temporary folder named by the file's device and inode, so processes on other hosts (a shared
// file system) keep writing in parallel. Taking a turn never fails a write: without a lock file
// (an unwritable temporary folder) the writer goes ahead unserialised.
#pragma once
#include <sys/types.h>

#include <filesystem>

namespace lod {

class HostTurn {
 public:
  // Blocks (sleeping, not spinning) until no other process on this host holds the turn for the
  // file open as `fd`.
  explicit HostTurn(int fd);
  ~HostTurn();
  HostTurn(const HostTurn&) = delete;
  HostTurn& operator=(const HostTurn&) = delete;
  bool held() const { return fd_ >= 0; }
  const std::filesystem::path& lock_file() const { return path_; }

 private:
  int fd_ = -1;
  std::filesystem::path path_;
};

}  // namespace lod
