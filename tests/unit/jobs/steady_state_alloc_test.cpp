// Steady-state updates allocate nothing: once a scene's object count, update rate and frame
// contents have been seen, staging, committing, stepping and reading frames make no
// operator-new allocation on any thread. Counted by replacing the global operator new for
// this test binary (the count only runs while a test switches it on).
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>

#include "jobs/service.h"
#include "unit/jobs/service_fixture.h"

// Sanitizers bring their own operator new and delete (in every variant, and they check that
// each pointer goes back the way it came), so the count runs in plain builds only.
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define LOD_COUNT_ALLOCATIONS 0
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
#define LOD_COUNT_ALLOCATIONS 0
#endif
#endif
#ifndef LOD_COUNT_ALLOCATIONS
#define LOD_COUNT_ALLOCATIONS 1
#endif

namespace {
std::atomic<bool> g_counting{false};
std::atomic<uint64_t> g_allocations{0};
}  // namespace

#if LOD_COUNT_ALLOCATIONS
void* operator new(std::size_t n) {
  if (g_counting.load(std::memory_order_relaxed)) g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n) { return operator new(n); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void* operator new(std::size_t n, const std::nothrow_t&) noexcept {
  if (g_counting.load(std::memory_order_relaxed)) g_allocations.fetch_add(1, std::memory_order_relaxed);
  return std::malloc(n ? n : 1);
}
void* operator new[](std::size_t n, const std::nothrow_t& t) noexcept { return operator new(n, t); }
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { std::free(p); }
#endif

namespace lod {
namespace {

using test::placed;

TEST(SteadyState, UpdatesCommitsFramesAllocateNothing) {
  if (!LOD_COUNT_ALLOCATIONS) GTEST_SKIP() << "allocations are counted in plain builds (a sanitizer owns operator new)";
  test::DynamicService d(2, 200000);
  Service& s = d.service();
  std::vector<ObjectHandle> handles;
  for (int i = 0; i < 5000; ++i) handles.push_back(s.create(uint32_t(i % 3), placed(float(i % 50) - 25, 0, -float(i / 50))));
  std::vector<ObjectHandle> moving(handles.begin(), handles.begin() + 500);
  std::vector<Transform> next(moving.size());
  auto tick = [&](uint64_t t) {
    for (size_t k = 0; k < moving.size(); ++k) next[k] = placed(float(k % 50) - 25 + 0.01f * float(t % 7), 0, -float(k / 50));
    // Half one call per object, half batched: both paths.
    for (size_t k = 0; k < moving.size() / 2; ++k) s.set_transform(moving[k], next[k]);
    s.set_transforms(std::span(moving).subspan(moving.size() / 2), std::span(next).subspan(moving.size() / 2));
    s.commit(t);
    ASSERT_TRUE(s.step(1.0 / 60));
    const FrameRef f = s.acquire_frame();
    ASSERT_TRUE(f);
    ASSERT_EQ(f->tick, t);
  };
  for (uint64_t t = 1; t <= 30; ++t) tick(t);  // capacities grow to what the scene needs
  g_counting.store(true);  // the counter itself counts
  delete new std::vector<int>(3);
  g_counting.store(false);
  ASSERT_EQ(g_allocations.load(), 2u);
  g_allocations.store(0);
  g_counting.store(true);
  for (uint64_t t = 31; t <= 130; ++t) tick(t);
  g_counting.store(false);
  EXPECT_EQ(g_allocations.load(), 0u) << "allocations in 100 steady ticks";
}

}  // namespace
}  // namespace lod
