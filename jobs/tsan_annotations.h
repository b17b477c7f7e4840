// ThreadSanitizer annotations for hand-overs inside libtbb (not built with TSan, so its
// synchronisation is invisible): release before spawning, acquire where a task starts,
// release where it ends, acquire after the join. No-ops in other builds.
#pragma once

#if defined(__SANITIZE_THREAD__)
#define LOD_TSAN 1
#elif defined(__has_feature)
#if __has_feature(thread_sanitizer)
#define LOD_TSAN 1
#endif
#endif

namespace lod::detail {

#ifdef LOD_TSAN
extern "C" void __tsan_acquire(void* addr);
extern "C" void __tsan_release(void* addr);
inline void tsan_acquire(char& at) { __tsan_acquire(&at); }
inline void tsan_release(char& at) { __tsan_release(&at); }
// A copy of what libtbb copied into a task on one thread and ran on another (a node's or a
// loop's body, a loop's range), read without TSan seeing it: that copy and its hand-over happen
// inside libtbb. Everything the body reads through it is ordered by the annotations, taken
// before it reads anything else. (GCC keeps a no_sanitize function out of instrumented callers.)
template <class T>
[[gnu::no_sanitize_thread, gnu::noinline]] T tsan_unseen_copy(const T& v) {
  return v;
}
#else
inline void tsan_acquire(char&) {}
inline void tsan_release(char&) {}
template <class T>
T tsan_unseen_copy(const T& v) {
  return v;
}
#endif

}  // namespace lod::detail
