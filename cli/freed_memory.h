// Freed memory kept for the next phase of a bake. glibc hands a block over its mmap threshold
// (at most 32 MB) back to the kernel when it is freed, and trims the heap's free top; every page
// the kernel hands out again is faulted and zeroed anew. A bake frees and allocates gigabytes
// phase after phase (load, clean, plan, BVH, subtrees), so those pages are better kept.
#pragma once

namespace lod::cli {

// Every block from the heap and the heap never trimmed (glibc's M_MMAP_MAX 0, M_TRIM_THRESHOLD
// at its greatest), unless LOD_KEEP_FREED_MEMORY is "0". Call before the first large allocation.
// Peak memory stays what it was (the pages are reused, not added); the process just does not
// give them back until it exits, as suits a batch bake and not a long-running service.
void keep_freed_memory();

// Whether this process's malloc keeps what is freed (keep_freed_memory took effect).
bool malloc_keeps_freed_memory();

}  // namespace lod::cli
