// tbb::parallel_for over [0, count) with its hand-overs marked for ThreadSanitizer (libtbb's own
// synchronisation is invisible to it, jobs/tsan_annotations.h): each call's tasks acquire what
// the caller released before the loop, on a byte of that call's own, and the caller acquires
// what they released after the join. Two loops, or a loop and anything else, are not ordered
// by it. For the bake jobs; the frame graph marks its loops per stage itself.
#pragma once
#include <oneapi/tbb/parallel_for.h>

#include <cstddef>

#include "jobs/tsan_annotations.h"

namespace lod::detail {

template <class Body>
void annotated_parallel_for(size_t count, const Body& body) {
  char sync[2] = {0, 0};  // spawn, join
  struct Loop {
    char* spawn;
    char* join;
    const Body* body;
  };
  const Loop loop{&sync[0], &sync[1], &body};
  const auto task = [loop](size_t i) {
    const Loop l = tsan_unseen_copy(loop);  // TBB's copy of the task, handed to this thread
    tsan_acquire(*l.spawn);
    (*l.body)(i);
    tsan_release(*l.join);
  };
  tsan_release(sync[0]);  // after everything the body reads is written
  tbb::parallel_for(size_t(0), count, task);
  tsan_acquire(sync[1]);
}

}  // namespace lod::detail
