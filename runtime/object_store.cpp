// ObjectStore: handle lookup and swap-erase over every column.
#include "runtime/object_store.h"

#include <algorithm>
#include <cassert>

namespace lod {

namespace {

template <class T>
void move_last_into(std::vector<T>& column, uint32_t index) {
  column[index] = column.back();
  column.pop_back();
}

}  // namespace

uint32_t ObjectStore::find(ObjectHandle h) const {
  const uint32_t slot = handle_slot(h);
  if (h == 0 || slot >= index_of_slot.size()) return kNoIndex;
  const uint32_t index = index_of_slot[slot];
  return index != kNoIndex && handle[index] == h ? index : kNoIndex;
}

uint32_t ObjectStore::insert(ObjectHandle h, uint32_t m, const Transform& t, const ObjectOptions& o) {
  const uint32_t slot = handle_slot(h);
  if (slot >= index_of_slot.size()) index_of_slot.resize(size_t{slot} + 1, kNoIndex);
  assert(index_of_slot[slot] == kNoIndex && "slot reused before its object was erased");
  const uint32_t index = static_cast<uint32_t>(handle.size());
  index_of_slot[slot] = index;
  handle.push_back(h);
  model.push_back(m);
  transform.push_back(t);
  options.push_back(o);
  prev_level.push_back(0);
  was_visible.push_back(0);
  morph_from.push_back(0);
  morph_start.push_back(-1e300);
  for (auto* c : {&cx, &cy, &cz, &radius, &error_scale, &inv_priority}) c->push_back(0);
  row.push_back(0);
  min_level.push_back(0);
  never_cull.push_back(0);
  dirty.push_back(1);
  any_dirty = true;
  return index;
}

void ObjectStore::erase(uint32_t index) {
  assert(index < handle.size());
  index_of_slot[handle_slot(handle[index])] = kNoIndex;
  if (index + 1 < handle.size()) index_of_slot[handle_slot(handle.back())] = index;
  move_last_into(handle, index);
  move_last_into(model, index);
  move_last_into(transform, index);
  move_last_into(options, index);
  move_last_into(prev_level, index);
  move_last_into(was_visible, index);
  move_last_into(morph_from, index);
  move_last_into(morph_start, index);
  for (auto* c : {&cx, &cy, &cz, &radius, &error_scale, &inv_priority}) move_last_into(*c, index);
  move_last_into(row, index);
  move_last_into(min_level, index);
  move_last_into(never_cull, index);
  move_last_into(dirty, index);
}

void ObjectStore::mark_all_dirty() {
  std::fill(dirty.begin(), dirty.end(), uint8_t{1});
  any_dirty = !dirty.empty();
}

void ObjectStore::clear() {
  for (ObjectHandle h : handle) index_of_slot[handle_slot(h)] = kNoIndex;
  handle.clear(), model.clear(), transform.clear(), options.clear();
  prev_level.clear(), was_visible.clear(), morph_from.clear(), morph_start.clear();
  for (auto* c : {&cx, &cy, &cz, &radius, &error_scale, &inv_priority}) c->clear();
  row.clear(), min_level.clear(), never_cull.clear(), dirty.clear();
  any_dirty = false;
}

void ObjectStore::reset_temporal_state() {
  std::fill(prev_level.begin(), prev_level.end(), uint8_t{0});
  std::fill(was_visible.begin(), was_visible.end(), uint8_t{0});
  std::fill(morph_from.begin(), morph_from.end(), uint8_t{0});
  std::fill(morph_start.begin(), morph_start.end(), -1e300);
}

}  // namespace lod
