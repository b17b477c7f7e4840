// FrameHandoff: the reader always holds one complete frame and never sees one go backwards.
#include "jobs/frame_handoff.h"

#include <gtest/gtest.h>

#include <atomic>
#include <thread>
#include <vector>

namespace lod {
namespace {

struct Numbered {
  uint64_t index = 0;
  std::vector<uint64_t> payload;  // every element == index, length depends on index
};

size_t payload_size(uint64_t index) { return 1 + (index * 7919) % 257; }

void write_frame(FrameHandoff<Numbered>& h, uint64_t index) {
  Numbered& b = h.back();
  b.index = index;
  b.payload.assign(payload_size(index), index);
  h.publish();
}

bool consistent(const Numbered& f) {
  if (f.index == 0) return f.payload.empty();
  if (f.payload.size() != payload_size(f.index)) return false;
  for (uint64_t v : f.payload)
    if (v != f.index) return false;
  return true;
}

TEST(FrameHandoff, ReaderGetsDefaultFrameBeforeFirstPublish) {
  FrameHandoff<Numbered> h;
  EXPECT_FALSE(h.has_fresh());
  const Numbered& f = h.acquire();
  EXPECT_EQ(f.index, 0u);
  EXPECT_TRUE(f.payload.empty());
}

TEST(FrameHandoff, ReaderGetsTheNewestPublishedFrame) {
  FrameHandoff<Numbered> h;
  for (uint64_t i = 1; i <= 5; ++i) write_frame(h, i);
  EXPECT_TRUE(h.has_fresh());
  const Numbered& f = h.acquire();
  EXPECT_EQ(f.index, 5u);
  EXPECT_TRUE(consistent(f));
  EXPECT_FALSE(h.has_fresh());
}

TEST(FrameHandoff, AcquiredFrameStaysUnchangedWhileTheWriterGoesOn) {
  FrameHandoff<Numbered> h;
  write_frame(h, 1);
  const Numbered& held = h.acquire();
  // The writer keeps cycling through its two other slots; the reader's slot is never touched.
  for (uint64_t i = 2; i < 50; ++i) write_frame(h, i);
  EXPECT_EQ(held.index, 1u);
  EXPECT_TRUE(consistent(held));
  EXPECT_EQ(h.acquire().index, 49u);
}

TEST(FrameHandoff, AcquireWithoutNewFrameKeepsTheSameFrame) {
  FrameHandoff<Numbered> h;
  write_frame(h, 3);
  const Numbered* a = &h.acquire();
  const Numbered* b = &h.acquire();
  EXPECT_EQ(a, b);
  EXPECT_EQ(b->index, 3u);
}

TEST(FrameHandoff, ConcurrentWriterAndReaderSeeOnlyCompleteIncreasingFrames) {
  FrameHandoff<Numbered> h;
  constexpr uint64_t kFrames = 20000;
  std::atomic<bool> done{false};
  std::thread writer([&] {
    for (uint64_t i = 1; i <= kFrames; ++i) write_frame(h, i);
    done.store(true);
  });
  uint64_t last = 0, reads = 0, distinct = 0, bad = 0, backwards = 0;
  for (;;) {
    const bool finished = done.load();
    const Numbered& f = h.acquire();
    ++reads;
    if (!consistent(f)) ++bad;
    if (f.index < last) ++backwards;
    if (f.index != last) ++distinct;
    last = f.index;
    if (finished) break;
  }
  writer.join();
  EXPECT_EQ(bad, 0u);
  EXPECT_EQ(backwards, 0u);
  // Read after the writer finished: the very last frame must have arrived.
  EXPECT_EQ(h.acquire().index, kFrames);
  EXPECT_GE(distinct, 1u);
  EXPECT_GE(reads, distinct);
}

}  // namespace
}  // namespace lod
