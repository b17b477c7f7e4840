#include "runtime/host_turn.h"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "test_support.h"

namespace {

int open_file(const std::filesystem::path& p) {
  return ::open(p.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
}

// flock is per open file description, so two threads opening the file themselves contend as
// two processes would.
TEST(HostTurn, WritersOfOneFileTakeTurnsAndTheLockFileGoes) {
  const auto dir = lod::test::temp_dir("host_turn");
  const auto file = dir / "shared.bin";
  const int a = open_file(file), b = open_file(file);
  ASSERT_GE(a, 0);
  ASSERT_GE(b, 0);
  std::filesystem::path lock;
  std::atomic<bool> first_holds{false}, second_holds{false}, first_released{false}, overlap{false};
  std::thread second;
  {
    const lod::HostTurn turn(a);
    ASSERT_TRUE(turn.held());
    lock = turn.lock_file();
    EXPECT_TRUE(std::filesystem::exists(lock));
    first_holds = true;
    second = std::thread([&] {
      const lod::HostTurn other(b);
      EXPECT_TRUE(other.held());
      if (!first_released.load()) overlap = true;
      second_holds = true;
    });
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    EXPECT_FALSE(second_holds.load()) << "the second writer went ahead while the first held the turn";
    first_released = true;
  }
  second.join();
  EXPECT_TRUE(second_holds.load());
  EXPECT_FALSE(overlap.load());
  EXPECT_FALSE(std::filesystem::exists(lock)) << "the last holder removes the lock file";
  ::close(a);
  ::close(b);
}

TEST(HostTurn, ManyRacingWritersHoldItOneAtATime) {
  const auto dir = lod::test::temp_dir("host_turn_race");
  const auto file = dir / "shared.bin";
  std::atomic<int> holders{0}, most{0}, turns{0};
  std::vector<std::thread> writers;
  for (int w = 0; w < 4; ++w)
    writers.emplace_back([&] {
      const int fd = open_file(file);
      ASSERT_GE(fd, 0);
      for (int k = 0; k < 50; ++k) {
        const lod::HostTurn turn(fd);
        EXPECT_TRUE(turn.held());
        const int now = ++holders;
        int seen = most.load();
        while (now > seen && !most.compare_exchange_weak(seen, now)) {
        }
        std::this_thread::yield();
        --holders;
        ++turns;
      }
      ::close(fd);
    });
  for (std::thread& t : writers) t.join();
  EXPECT_EQ(turns.load(), 200);
  EXPECT_EQ(most.load(), 1);
}

// Another user could plant a link under the lock's name in the shared temporary folder: the turn
// is then skipped (the write goes ahead unserialised), the link's target untouched.
TEST(HostTurn, PlantedLinkIsNotFollowed) {
  const auto dir = lod::test::temp_dir("host_turn_link");
  const auto file = dir / "shared.bin", victim = dir / "victim.txt";
  lod::test::write_text(victim, "keep me");
  const int fd = open_file(file);
  ASSERT_GE(fd, 0);
  struct stat st {};
  ASSERT_EQ(::fstat(fd, &st), 0);
  const auto lock =
      std::filesystem::temp_directory_path() / ("lodkit-write-" + std::to_string(uint64_t(st.st_dev)) + "-" +
                                                std::to_string(uint64_t(st.st_ino)) + ".lock");
  std::filesystem::remove(lock);
  std::filesystem::create_symlink(victim, lock);
  {
    const lod::HostTurn turn(fd);
    EXPECT_FALSE(turn.held());
    EXPECT_EQ(turn.lock_file(), lock);
  }
  EXPECT_TRUE(std::filesystem::is_symlink(lock));
  EXPECT_EQ(lod::test::read_bytes(victim), (std::vector<uint8_t>{'k', 'e', 'e', 'p', ' ', 'm', 'e'}));
  std::filesystem::remove(lock);
  ::close(fd);
}

TEST(HostTurn, OtherFilesDoNotWait) {
  const auto dir = lod::test::temp_dir("host_turn_other");
  const int a = open_file(dir / "one.bin"), b = open_file(dir / "two.bin");
  ASSERT_GE(a, 0);
  ASSERT_GE(b, 0);
  const lod::HostTurn first(a);
  const lod::HostTurn second(b);  // would block forever if the files shared a turn
  EXPECT_TRUE(first.held());
  EXPECT_TRUE(second.held());
  EXPECT_NE(first.lock_file(), second.lock_file());
  ::close(a);
  ::close(b);
}

}  // namespace
