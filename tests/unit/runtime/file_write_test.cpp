#include "runtime/file_write.h"

#include <fcntl.h>
#include <signal.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <span>
#include <sstream>
#include <string>
#include <vector>

#include "test_support.h"

namespace {

std::string read_text(const std::filesystem::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

size_t leftover_temporaries(const std::filesystem::path& dir) {
  size_t n = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir))
    if (e.path().extension() == ".tmp") ++n;
  return n;
}

}  // namespace

TEST(FileWrite, FullDiskSaysSoInPlainWords) {
  // /dev/full fails every write with ENOSPC, as a full file system does.
  const int fd = ::open("/dev/full", O_WRONLY | O_CLOEXEC);
  if (fd < 0) GTEST_SKIP() << "/dev/full is not available here";
  const std::vector<uint8_t> bytes(9000, 7);
  const lod::Status st = lod::write_all(fd, bytes, "cache/bunny.lod");
  ::close(fd);
  ASSERT_FALSE(st.ok);
  EXPECT_NE(st.message.find("cache/bunny.lod: the disk is full"), std::string::npos) << st.message;
  EXPECT_NE(st.message.find("after writing 0 of 9000 bytes"), std::string::npos) << st.message;
}

TEST(FileWrite, ErrnoWordsForTheCommonFailures) {
  EXPECT_EQ(lod::describe_write_errno(ENOSPC), "the disk is full (no space left on device)");
  EXPECT_EQ(lod::describe_write_errno(EROFS), "the file system is read-only");
  EXPECT_EQ(lod::describe_write_errno(EACCES), "permission denied");
  EXPECT_FALSE(lod::describe_write_errno(ENOENT).empty());
}

TEST(FileWrite, ReplacesTheFileWholeAndLeavesNoTemporary) {
  const auto dir = lod::test::temp_dir("file_write_replace");
  const auto file = dir / "out.txt";
  ASSERT_TRUE(lod::write_file_atomic(file, std::string("first version, longer")).ok);
  ASSERT_TRUE(lod::write_file_atomic(file, std::string("second")).ok);
  EXPECT_EQ(read_text(file), "second");
  EXPECT_EQ(leftover_temporaries(dir), 0u);
}

TEST(FileWrite, MissingFolderIsRefusedNamingTheFile) {
  const auto dir = lod::test::temp_dir("file_write_missing");
  const auto file = dir / "no-such-folder" / "out.lod";
  const lod::Status st = lod::write_file_atomic(file, std::string("x"));
  ASSERT_FALSE(st.ok);
  EXPECT_EQ(st.message.rfind(file.string(), 0), 0u) << st.message;
  EXPECT_FALSE(std::filesystem::exists(file));
}

TEST(FileWrite, FailedRenameKeepsWhatWasThereAndRemovesTheTemporary) {
  // The target is a non-empty folder: the rename fails after the bytes were written.
  const auto dir = lod::test::temp_dir("file_write_rename");
  const auto target = dir / "taken";
  std::filesystem::create_directories(target / "inside");
  const lod::Status st = lod::write_file_atomic(target, std::string("payload"));
  ASSERT_FALSE(st.ok);
  EXPECT_NE(st.message.find("cannot rename"), std::string::npos) << st.message;
  EXPECT_TRUE(std::filesystem::is_directory(target / "inside"));
  EXPECT_EQ(leftover_temporaries(dir), 0u);
}

TEST(FileWrite, PiecesFromSeveralWritersMakeTheFileOnlyWhenCommitted) {
  const auto dir = lod::test::temp_dir("file_write_pieces");
  const auto path = dir / "out.bin";
  std::filesystem::path temp;
  ASSERT_TRUE(lod::create_sized_temporary(path, 10, temp));
  EXPECT_EQ(std::filesystem::file_size(temp), 10u);
  const std::vector<uint8_t> a{1, 2, 3}, b{9, 8, 7, 6, 5, 4, 3};
  const lod::FilePiece first[] = {{0, a}};
  const lod::FilePiece second[] = {{3, b}};
  ASSERT_TRUE(lod::write_pieces(temp, second, "out.bin"));  // any order, any writer
  ASSERT_TRUE(lod::write_pieces(temp, first, "out.bin"));
  EXPECT_FALSE(std::filesystem::exists(path)) << "nothing under the name before the commit";
  ASSERT_TRUE(lod::commit_temporary(temp, path));
  EXPECT_EQ(lod::test::read_bytes(path), (std::vector<uint8_t>{1, 2, 3, 9, 8, 7, 6, 5, 4, 3}));
  EXPECT_FALSE(std::filesystem::exists(temp));
  const lod::Status gone = lod::write_pieces(dir / "no-such.tmp", first, "out.bin");
  EXPECT_FALSE(gone);
  EXPECT_NE(gone.message.find("out.bin"), std::string::npos) << gone.message;
}

TEST(FileWrite, CoveredRangesAreSortedAndJoined) {
  const std::vector<uint8_t> b(4, 0);
  const std::span<const uint8_t> four(b), two(b.data(), 2), none;
  const lod::FilePiece pieces[] = {{20, four}, {0, two}, {2, four}, {30, none}, {8, two}, {21, two}};
  using R = std::pair<uint64_t, uint64_t>;
  // [0,2) and [2,6) touch; [8,10) stands apart; [21,23) lies inside [20,24); the empty one is nothing.
  EXPECT_EQ(lod::detail::covered_ranges(pieces), (std::vector<R>{{0, 6}, {8, 10}, {20, 24}}));
  EXPECT_TRUE(lod::detail::covered_ranges({}).empty());
}

TEST(FileWrite, CheckedNewFilesHoldEveryByteAtEverySizeDirectOrNot) {
  const auto dir = lod::test::temp_dir("file_write_checked");
  // Around the 4 KB blocks O_DIRECT writes and the 4 MB chunks it copies through.
  for (const size_t size : {size_t(0), size_t(1), size_t(4095), size_t(4096), size_t(4097), (size_t(4) << 20) + 4099})
    for (const bool direct : {true, false}) {
      std::vector<uint8_t> bytes(size);
      for (size_t i = 0; i < size; ++i) bytes[i] = uint8_t((i * 2654435761u) >> 13);
      std::string name = std::to_string(size);  // not "f" + to_string: GCC 12 warns (-Wrestrict)
      name += direct ? ".direct" : ".buffered";
      const auto file = dir / name;
      const lod::Status st = lod::write_new_file_checked(file, bytes, "entry", direct);
      ASSERT_TRUE(st.ok) << size << ": " << st.message;
      const std::string back = read_text(file);
      ASSERT_EQ(back.size(), size);
      EXPECT_TRUE(std::equal(back.begin(), back.end(), bytes.begin(), [](char a, uint8_t b) { return uint8_t(a) == b; }))
          << size;
    }
}

// A file in parts (the cleaned mesh's columns, an .hlod): its whole blocks go past the page
// cache, the last partial one buffered; parts of odd sizes, empty ones among them, across the
// 4 KB blocks and the 4 MB chunks, make the exact concatenation, and it replaces a longer file.
TEST(FileWrite, PartsAcrossBlocksAndChunksMakeTheExactFile) {
  const auto dir = lod::test::temp_dir("file_write_parts");
  const auto file = dir / "parts.bin";
  ASSERT_TRUE(lod::write_file_atomic(file, std::string(size_t(9) << 20, 'x')).ok);
  for (const std::vector<size_t>& sizes : {std::vector<size_t>{1, 4095, 0, 4097, (size_t(4) << 20) + 3, 8191, 5},
                                           std::vector<size_t>{8192}, std::vector<size_t>{3, 8190},
                                           std::vector<size_t>{100}}) {
    std::vector<std::vector<uint8_t>> parts;
    std::vector<std::span<const uint8_t>> spans;
    std::string expected;
    size_t seed = 0;
    for (size_t n : sizes) {
      std::vector<uint8_t>& part = parts.emplace_back(n);
      for (uint8_t& b : part) b = uint8_t((seed++ * 2654435761u) >> 13);
      expected.append(part.begin(), part.end());
    }
    for (const std::vector<uint8_t>& part : parts) spans.emplace_back(part);
    const lod::Status st = lod::write_file_atomic(file, spans);
    ASSERT_TRUE(st.ok) << st.message;
    EXPECT_EQ(read_text(file), expected) << sizes.size() << " parts";
  }
  EXPECT_EQ(leftover_temporaries(dir), 0u);
}

TEST(FileWrite, CheckedNewFileNeverReplacesOneAndSaysWhy) {
  const auto dir = lod::test::temp_dir("file_write_checked_exists");
  const auto file = dir / "entry.hsub";
  ASSERT_TRUE(lod::write_file_atomic(file, std::string("someone else's")).ok);
  const std::vector<uint8_t> bytes(10000, 3);
  const lod::Status st = lod::write_new_file_checked(file, bytes, "cache/entry.hsub");
  ASSERT_FALSE(st.ok);
  EXPECT_NE(st.message.find("cache/entry.hsub: cannot create"), std::string::npos) << st.message;
  EXPECT_EQ(read_text(file), "someone else's");  // left as it was
  const lod::Status missing = lod::write_new_file_checked(dir / "no" / "such", bytes, "cache/x.hsub");
  ASSERT_FALSE(missing.ok);
  EXPECT_NE(missing.message.find("cache/x.hsub: cannot create"), std::string::npos) << missing.message;
}

TEST(FileWrite, InterleavedWritersOwningPartsOfTheSameBlocksMakeTheExactFile) {
  // Two writers own alternating runs of odd-sized pieces (most blocks of 4 KB hold bytes of
  // both, some runs span several 4 MB chunks): whole blocks go past the page cache, the partial
  // ones at each run's ends through it, and every byte must land where it belongs.
  const auto dir = lod::test::temp_dir("file_write_interleaved");
  std::vector<uint8_t> whole;
  std::vector<std::vector<lod::FilePiece>> writer(2);
  std::vector<std::vector<uint8_t>> storage;
  storage.reserve(64);
  uint64_t at = 0;
  for (size_t k = 0; k < 60; ++k) {
    const size_t size = k % 13 == 3 ? (size_t(5) << 20) + 123 : 1 + (k * 7919) % 20000;
    storage.emplace_back(size);
    for (size_t i = 0; i < size; ++i) storage.back()[i] = uint8_t((at + i) * 40503u >> 7);
    whole.insert(whole.end(), storage.back().begin(), storage.back().end());
    writer[(k / 3) % 2].push_back({at, storage.back()});  // runs of three pieces each
    at += size;
  }
  const auto path = dir / "out.bin";
  std::filesystem::path temp;
  ASSERT_TRUE(lod::create_sized_temporary(path, at, temp));
  ASSERT_TRUE(lod::write_pieces(temp, writer[1], "out.bin"));
  ASSERT_TRUE(lod::write_pieces(temp, writer[0], "out.bin"));
  ASSERT_TRUE(lod::commit_temporary(temp, path));
  const std::vector<uint8_t> back = lod::test::read_bytes(path);
  ASSERT_EQ(back.size(), whole.size());
  EXPECT_TRUE(back == whole);
}

// Temporaries beside a cache entry on shared storage: ranks on two nodes can have one pid, and
// a forked child keeps its parent's statics; neither may draw the other's name.
TEST(FileWrite, TemporarySuffixesDifferWithinAProcessAndInAForkedChild) {
  std::vector<std::string> seen;
  for (int i = 0; i < 1000; ++i) seen.push_back(lod::unique_temporary_suffix());
  for (const std::string& s : seen) {
    EXPECT_EQ(s.front(), '.');
    EXPECT_EQ(s.substr(s.size() - 4), ".tmp");
  }
  std::sort(seen.begin(), seen.end());
  EXPECT_EQ(std::unique(seen.begin(), seen.end()), seen.end()) << "a suffix repeated";
  const std::string parent = lod::unique_temporary_suffix();
  int fds[2];
  ASSERT_EQ(pipe(fds), 0);
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    const std::string mine = lod::unique_temporary_suffix();
    const ssize_t n = write(fds[1], mine.data(), mine.size());
    _exit(n == ssize_t(mine.size()) ? 0 : 1);
  }
  close(fds[1]);
  char buf[64] = {};
  const ssize_t n = read(fds[0], buf, sizeof buf - 1);
  close(fds[0]);
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
  ASSERT_GT(n, 0);
  const std::string theirs(buf, size_t(n));
  // The writer (scope and pid, before the last '-') differs, not only the count after it.
  EXPECT_NE(theirs.substr(0, theirs.rfind('-')), parent.substr(0, parent.rfind('-'))) << theirs << " vs " << parent;
}

namespace {

// A child that makes `path`'s sized temporary and then either is killed (SIGKILL, as a write cut
// short) or waits on `hold` until the parent closes it. Its temporary's path is returned.
std::filesystem::path temporary_of_child(const std::filesystem::path& path, bool killed, pid_t& child, int& hold) {
  int names[2], wait_fds[2];
  EXPECT_EQ(pipe(names), 0);
  EXPECT_EQ(pipe(wait_fds), 0);
  child = fork();
  if (child == 0) {
    close(names[0]);
    close(wait_fds[1]);
    std::filesystem::path temp;
    if (!lod::create_sized_temporary(path, 1 << 16, temp)) _exit(1);
    const std::string name = temp.string();
    if (write(names[1], name.data(), name.size()) != ssize_t(name.size())) _exit(1);
    close(names[1]);
    if (killed) raise(SIGKILL);
    char c;
    while (read(wait_fds[0], &c, 1) > 0) {
    }
    _exit(0);
  }
  close(names[1]);
  close(wait_fds[0]);
  hold = wait_fds[1];
  std::string name;
  char buf[512];
  for (ssize_t n; (n = read(names[0], buf, sizeof buf)) > 0;) name.append(buf, size_t(n));
  close(names[0]);
  return name;
}

}  // namespace

// A writer killed mid-write leaves its full-size temporary; the next write of the same file
// removes it. A live writer's, another file's and another host's (scope) are left alone.
TEST(FileWrite, TheNextWriteRemovesADeadWritersTemporaryOfTheSameFile) {
  const auto dir = lod::test::temp_dir("file_write_dead_temps");
  const auto path = dir / "entry.hlod";
  pid_t dead = 0, live = 0;
  int dead_hold = -1, live_hold = -1;
  const std::filesystem::path dead_temp = temporary_of_child(path, true, dead, dead_hold);
  const std::filesystem::path live_temp = temporary_of_child(path, false, live, live_hold);
  int status = 0;
  ASSERT_EQ(waitpid(dead, &status, 0), dead);
  ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL);
  close(dead_hold);
  ASSERT_TRUE(std::filesystem::exists(dead_temp)) << dead_temp;
  ASSERT_TRUE(std::filesystem::exists(live_temp)) << live_temp;
  EXPECT_EQ(std::filesystem::file_size(dead_temp), 1u << 16) << "a killed write leaves it full-size";

  // The dead writer's suffix on another file, and under another scope (another host's).
  const std::string suffix = dead_temp.filename().string().substr(path.filename().string().size());
  const auto other_file = dir / ("other.hlod" + suffix);
  std::string foreign = suffix;
  foreign[1] = foreign[1] == '0' ? '1' : '0';
  const auto other_scope = dir / ("entry.hlod" + foreign);
  lod::test::write_text(other_file, "x");
  lod::test::write_text(other_scope, "x");

  ASSERT_TRUE(lod::write_file_atomic(path, std::string("fresh")));
  EXPECT_FALSE(std::filesystem::exists(dead_temp)) << "the dead writer's temporary is removed";
  EXPECT_TRUE(std::filesystem::exists(live_temp)) << "a live writer's is not";
  EXPECT_TRUE(std::filesystem::exists(other_file)) << "another file's is not";
  EXPECT_TRUE(std::filesystem::exists(other_scope)) << "another scope's is not";
  EXPECT_EQ(read_text(path), "fresh");

  close(live_hold);  // the live writer ends without renaming its temporary
  ASSERT_EQ(waitpid(live, &status, 0), live);
  std::filesystem::path temp;
  ASSERT_TRUE(lod::create_sized_temporary(path, 16, temp));  // the other way of writing
  EXPECT_FALSE(std::filesystem::exists(live_temp)) << "removed once its writer is gone";
  ASSERT_TRUE(lod::commit_temporary(temp, path));
  EXPECT_EQ(lod::remove_dead_temporaries(dir, "entry.hlod"), 0u);
  EXPECT_EQ(leftover_temporaries(dir), 2u) << "the other file's and the other scope's";
}
