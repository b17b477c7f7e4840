// ThreadSanitizer suppressions compiled into test_jobs and test_stress (the sanitizer asks for them at start).
//
// Debian's libtbb is not built with ThreadSanitizer, so the synchronisation of its scheduler
// (work stealing, task hand-over, waiting) is invisible, and TSan reports TBB's own task and
// node objects, written on one thread and read on another. Suppressed here: races whose
// innermost frame is in oneTBB's headers, and races with a stack inside one of TBB's internal
// helpers under which lodkit code never runs. A race between two accesses made by lodkit
// code is still reported; the frame graph marks TBB's spawn and join edges for TSan itself
// (frame_graph.cpp) and the bake jobs' loops (jobs/annotated_parallel_for.h).
#if defined(__SANITIZE_THREAD__)
#define LOD_TEST_TSAN 1
#elif defined(__has_feature)
#if __has_feature(thread_sanitizer)
#define LOD_TEST_TSAN 1
#endif
#endif

#ifdef LOD_TEST_TSAN
extern "C" const char* __tsan_default_suppressions() {
  return "race_top:/oneapi/tbb/\n"
         "race:tbb::detail::d1::fold_tree\n"          // parallel_for's partition tree
         "race:tbb::detail::d1::tree_node::\n"
         "race:tbb::detail::d1::wait_node\n"          // ... its root, on the spawning task's stack
         "race:tbb::detail::d1::node::node\n"
         "race:tbb::detail::d1::wait_context::\n"     // completion counters
         "race:tbb::detail::d1::broadcast_cache\n"    // flow-graph successor lists
         "race:tbb::detail::d1::spin_rw_mutex\n"
         "race:tbb::detail::d1::task_group_context\n"  // cancellation state, read by every task
         "race:tbb::detail::d1::dynamic_grainsize_mode\n"  // the partitioner's stolen-child flag
         // Frees libtbb makes itself (e.g. the exception a throwing task left for the waiting
         // thread, freed after it was rethrown): intercepted calls from uninstrumented code
         // whose hand-over TSan cannot see. lodkit's own accesses are instrumented and still checked.
         "called_from_lib:libtbb.so\n"
         // Embree builds its BVHs with its own (uninstrumented) TBB: memory it allocates on one
         // thread and frees on another, inside the library.
         "race:libembree3.so\n"
         // ... and reads, on a worker running Embree's build tasks (no lodkit frame: all of it
         // uninstrumented), the configuration strings of a device made on the spawning thread:
         // Embree's own task hand-over, which TSan cannot see (libstdc++'s compare is its only frame).
         "race:std::__cxx11::basic_string<char, std::char_traits<char>, std::allocator<char> >::compare(char const*) const\n";
}
#endif
