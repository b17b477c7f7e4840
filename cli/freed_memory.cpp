// On the 13.9M-triangle HLOD bake at 2 ranks x 1 thread, each rank's critical CPU fell from
// 17.5-18.0 s to 16.7-16.9 s, its kernel time from 1.9-2.6 s to 1.7-1.8 s, peak RSS unchanged
// (docs/distributed-bake-measurements.md, "Stop 35").
#include "cli/freed_memory.h"

#include <climits>
#include <cstdlib>
#include <string>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace lod::cli {
namespace {
bool kept = false;
}  // namespace

void keep_freed_memory() {
  const char* off = std::getenv("LOD_KEEP_FREED_MEMORY");
  if (off && std::string(off) == "0") return;
#if defined(__GLIBC__)
  // Both or neither: without the trim threshold the heap's free top still goes back (and a
  // sanitizer's allocator refuses both, returning 0).
  if (mallopt(M_TRIM_THRESHOLD, INT_MAX) != 1) return;
  if (mallopt(M_MMAP_MAX, 0) != 1) {
    mallopt(M_TRIM_THRESHOLD, 128 * 1024);  // glibc's default
    return;
  }
  kept = true;
#endif
}

bool malloc_keeps_freed_memory() { return kept; }

}  // namespace lod::cli
