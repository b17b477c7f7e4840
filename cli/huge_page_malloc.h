// Huge pages for the bakes' malloc. A bake touches gigabytes of fresh memory; where the kernel
// gives transparent huge pages only to memory that asks (its "madvise" mode, Debian's default),
// glibc's malloc asks only under the tunable glibc.malloc.hugetlb=1, read once at start-up.
#pragma once

namespace lod::cli {

// Starts this program again (same pid, arguments and environment) with glibc.malloc.hugetlb=1
// added to GLIBC_TUNABLES, where that helps: THP in madvise mode, glibc 2.35 or later, not under
// a sanitizer's allocator, the tunable not set yet, LOD_HUGE_PAGES not "0". Returns when the
// process goes on as it is (including when the exec fails). Call first thing in main.
void restart_with_huge_page_malloc(char** argv);

// Whether malloc is a sanitizer's (ASan, TSan, MSan): glibc's tunables and mallopt do not reach it.
bool sanitizer_allocator();

// Whether this process's malloc gets transparent huge pages (the tunable above, or THP "always").
bool malloc_uses_huge_pages();

}  // namespace lod::cli
