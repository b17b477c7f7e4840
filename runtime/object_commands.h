// Object commands: what the simulation thread stages (create, destroy, move, options) and a
// frame applies, in staging order, to its ObjectStore at the start of the frame.
#pragma once
#include <cstdint>
#include <span>
#include <vector>

#include "lodkit/types.hpp"
#include "runtime/object_store.h"

namespace lod {

enum class CommandKind : uint32_t { create, destroy, transform, options };

struct ObjectCommand {
  ObjectHandle handle = 0;
  CommandKind kind = CommandKind::transform;
  uint32_t model = 0;  // create
  union {
    Transform transform;    // create, transform
    ObjectOptions options;  // options
  };
  ObjectCommand() : transform() {}
};

// One committed batch: the commands staged before commit(tick).
struct CommitBatchRef {
  uint64_t tick = 0;
  std::span<const ObjectCommand> commands;
};

struct ApplyCounts {
  uint32_t created = 0, destroyed = 0, moved = 0, changed = 0;
  uint32_t refused = 0;  // handles not live here (a bug upstream: staging validates them)
};

// Applies `commands` in order; a create naming a model >= model_count is refused. Destroyed
// handles' slots are appended to `freed_slots` (so per-slot state elsewhere can be dropped).
// Allocates only when the store grows.
ApplyCounts apply_commands(ObjectStore& store, std::span<const ObjectCommand> commands, uint32_t model_count,
                           std::vector<uint32_t>& freed_slots);

}  // namespace lod
