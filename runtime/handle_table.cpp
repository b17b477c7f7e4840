// HandleTable: generations per slot, a free list.
#include "runtime/handle_table.h"

#include "runtime/object_store.h"

namespace lod {

ObjectHandle HandleTable::allocate() {
  uint32_t slot;
  if (!free_.empty()) {
    slot = free_.back();
    free_.pop_back();
  } else {
    slot = static_cast<uint32_t>(generation_.size());
    generation_.push_back(1);
    live_.push_back(0);
  }
  live_[slot] = 1;
  ++live_count_;
  return make_handle(slot, generation_[slot]);
}

bool HandleTable::release(ObjectHandle h) {
  if (!live(h)) return false;
  const uint32_t slot = handle_slot(h);
  live_[slot] = 0;
  // Generation 0 would make the slot's handle 0 for slot 0: skip it when wrapping.
  if (++generation_[slot] == 0) generation_[slot] = 1;
  free_.push_back(slot);
  --live_count_;
  return true;
}

}  // namespace lod
