// Object commands applied to the store.
#include "runtime/object_commands.h"

namespace lod {

ApplyCounts apply_commands(ObjectStore& store, std::span<const ObjectCommand> commands, uint32_t model_count,
                           std::vector<uint32_t>& freed_slots) {
  ApplyCounts n;
  for (const ObjectCommand& c : commands) {
    if (c.kind == CommandKind::create) {
      const uint32_t slot = handle_slot(c.handle);
      if (c.handle == 0 || c.model >= model_count || (slot < store.index_of_slot.size() && store.index_of_slot[slot] != kNoIndex)) {
        ++n.refused;
        continue;
      }
      store.insert(c.handle, c.model, c.transform, ObjectOptions{});
      ++n.created;
      continue;
    }
    const uint32_t i = store.find(c.handle);
    if (i == kNoIndex) {
      ++n.refused;
      continue;
    }
    switch (c.kind) {
      case CommandKind::destroy:
        store.erase(i);
        freed_slots.push_back(handle_slot(c.handle));
        ++n.destroyed;
        break;
      case CommandKind::transform:
        store.transform[i] = c.transform;
        store.mark_dirty(i);
        ++n.moved;
        break;
      case CommandKind::options:
        store.options[i] = c.options;
        store.mark_dirty(i);
        ++n.changed;
        break;
      case CommandKind::create:
        break;
    }
  }
  return n;
}

}  // namespace lod
