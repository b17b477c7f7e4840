// StopSignals: while one is alive, SIGINT and SIGTERM ask `lod run` to stop instead of killing
// it, so it can finish its files and print its summary for the frames it ran. requested() is
// the signal that asked (0: none). The handler only stores the number (async-signal-safe),
// and goes back to the default on delivery: a second signal kills the process as usual. The
// handlers found at construction come back when it goes; a signal found ignored (SIG_IGN, as
// a shell's background job has SIGINT) stays ignored.
#pragma once
#include <csignal>

namespace lod::cli {

class StopSignals {
 public:
  StopSignals();
  ~StopSignals();
  StopSignals(const StopSignals&) = delete;
  StopSignals& operator=(const StopSignals&) = delete;

  int requested() const;

 private:
  struct sigaction old_int_{}, old_term_{};
};

}  // namespace lod::cli
