#include "sbaslam/core/stop_signal.h"

#include <gtest/gtest.h>

#include <csignal>
#include <cstdlib>

namespace sbaslam {
namespace {

volatile std::sig_atomic_t g_caught_by_test_handler = 0;
extern "C" void test_handler(int) {
  g_caught_by_test_handler = 1;
}

TEST(StopSignalGuard, RecordsTheSignalInsteadOfDyingAndRestoresTheOldHandler) {
  std::signal(SIGTERM, test_handler);
  {
    const StopSignalGuard guard;
    EXPECT_EQ(guard.received(), 0);
    std::raise(SIGTERM);
    EXPECT_EQ(guard.received(), SIGTERM);
    EXPECT_STREQ(stop_signal_name(guard.received()), "SIGTERM");
  }
  EXPECT_EQ(g_caught_by_test_handler, 0);
  std::raise(SIGTERM);
  EXPECT_EQ(g_caught_by_test_handler, 1);
  std::signal(SIGTERM, SIG_DFL);
}

TEST(StopSignalGuard, OverlappingGuardsShareTheFlagAndTheLastOneRestores) {
  std::signal(SIGINT, test_handler);
  g_caught_by_test_handler = 0;
  {
    const StopSignalGuard first;
    {
      const StopSignalGuard second;
      std::raise(SIGINT);
      EXPECT_EQ(second.received(), SIGINT);
    }
    EXPECT_EQ(first.received(), SIGINT);  // still installed: the signal did not reach the old one
    EXPECT_EQ(g_caught_by_test_handler, 0);
  }
  {
    const StopSignalGuard next;
    EXPECT_EQ(next.received(), 0);
    std::raise(SIGINT);  // reaches `next`, not the old handler
    EXPECT_EQ(g_caught_by_test_handler, 0);
  }
  std::signal(SIGINT, SIG_DFL);
}

TEST(StopSignalGuardDeathTest, ASecondSignalEndsTheProcess) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  EXPECT_EXIT(
      {
        const StopSignalGuard guard;
        std::raise(SIGINT);
        std::raise(SIGINT);
        std::exit(0);
      },
      testing::KilledBySignal(SIGINT), "");
}

}  // namespace
}  // namespace sbaslam
