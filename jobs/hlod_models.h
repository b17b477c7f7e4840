// HlodModels: the streamed HLOD models a frame graph draws (config models with hlod = true):
// each one's tree (always resident), the .hlod file its nodes are read from, and the one
// transform its single object is placed with. Immutable once made; shared by the graph.
#pragma once
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "jobs/hlod_stream.h"  // ModelNodeLoader
#include "jobs/stream_pager.h"
#include "lodkit/types.hpp"
#include "runtime/hlod_select.h"
#include "runtime/hlod_tree.h"

namespace lod {

struct HlodModels {
  std::vector<std::string> names;
  std::vector<HlodTree> trees;
  std::vector<std::filesystem::path> files;  // the cached .hlod of each
  // Per model: 1 when files[m] is a cache entry the bake made (bake_hlod_models): a node that
  // cannot be read marks it bad, and the next bake rebakes it (jobs/hlod_read_failures.h);
  // 0 (or missing) for a .hlod the config names itself.
  std::vector<uint8_t> cache_entry;
  std::vector<Transform> transforms;
  StreamPagerConfig stream;                  // [stream] budget_mb, loader_threads
  // skip: what the camera does not see is neither drawn nor loaded (Cesium). cover: a closed
  // cut (lod run --validate checks every boundary edge; hlod_select.h).
  HlodCulledNodes culled = HlodCulledNodes::skip;
  // Reads one node (on the loader threads, several at once); empty: read_hlod_node on `files`.
  // Tests inject slow or failing storage here.
  ModelNodeLoader load;
  bool empty() const { return trees.empty(); }
};

}  // namespace lod
