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
#else
inline void tsan_acquire(char&) {}
inline void tsan_release(char&) {}
#endif

}  // namespace lod::detail
