// StopSignals: SIGINT/SIGTERM are recorded, not fatal, while one lives; the old handlers return.
#include "cli/stop_signals.h"

#include <gtest/gtest.h>

#include <csignal>

namespace {

using lod::cli::StopSignals;

int g_seen = 0;
extern "C" void remember(int sig) { g_seen = sig; }

TEST(StopSignals, RecordsTheSignalAndRestoresTheHandlersFoundBefore) {
  struct sigaction mine {}, before {};
  mine.sa_handler = remember;
  sigemptyset(&mine.sa_mask);
  ASSERT_EQ(sigaction(SIGTERM, &mine, &before), 0);
  {
    StopSignals stop;
    EXPECT_EQ(stop.requested(), 0);
    std::raise(SIGTERM);
    EXPECT_EQ(stop.requested(), SIGTERM) << "asked to stop, still running";
    EXPECT_EQ(g_seen, 0) << "the earlier handler is not called meanwhile";
  }
  std::raise(SIGTERM);
  EXPECT_EQ(g_seen, SIGTERM) << "the handler found before is back";
  sigaction(SIGTERM, &before, nullptr);
}

TEST(StopSignals, LeavesAnIgnoredSignalIgnored) {
  struct sigaction ign {}, before {};
  ign.sa_handler = SIG_IGN;
  sigemptyset(&ign.sa_mask);
  ASSERT_EQ(sigaction(SIGINT, &ign, &before), 0);
  {
    StopSignals stop;
    std::raise(SIGINT);
    EXPECT_EQ(stop.requested(), 0);
  }
  sigaction(SIGINT, &before, nullptr);
}

}  // namespace
