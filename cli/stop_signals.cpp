#include "cli/stop_signals.h"

#include <atomic>

namespace lod::cli {
namespace {

std::atomic<int> g_requested{0};
static_assert(std::atomic<int>::is_always_lock_free, "stored from a signal handler");

extern "C" void on_stop_signal(int sig) { g_requested.store(sig, std::memory_order_relaxed); }

}  // namespace

StopSignals::StopSignals() {
  g_requested.store(0);
  struct sigaction sa {};
  sa.sa_handler = on_stop_signal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESTART | SA_RESETHAND;  // interrupted reads and writes carry on; a second signal kills
  sigaction(SIGINT, &sa, &old_int_);
  sigaction(SIGTERM, &sa, &old_term_);
  // A signal the process was started ignoring (a background job's SIGINT) stays ignored.
  if (old_int_.sa_handler == SIG_IGN) sigaction(SIGINT, &old_int_, nullptr);
  if (old_term_.sa_handler == SIG_IGN) sigaction(SIGTERM, &old_term_, nullptr);
}

StopSignals::~StopSignals() {
  sigaction(SIGINT, &old_int_, nullptr);
  sigaction(SIGTERM, &old_term_, nullptr);
}

int StopSignals::requested() const { return g_requested.load(std::memory_order_relaxed); }

}  // namespace lod::cli
