// CommitQueue: staging under one lock, batches swapped out under another.
#include "jobs/commit_queue.h"

#include <cmath>

#include "runtime/object_controls.h"

namespace lod {

bool transform_valid(const Transform& t) {
  float q2 = 0;
  for (float v : t.position)
    if (!std::isfinite(v)) return false;
  for (float v : t.rotation) {
    if (!std::isfinite(v)) return false;
    q2 += v * v;
  }
  return std::isfinite(t.scale) && t.scale > 0 && q2 > 1e-20f && std::isfinite(q2);
}

ObjectHandle CommitQueue::create(uint32_t model, uint32_t model_count, const Transform& t, const ObjectOptions& o) {
  if (model >= model_count || !transform_valid(t) || !options_valid(o)) return 0;
  std::lock_guard lock(stage_mutex_);
  const ObjectHandle h = handles_.allocate();
  ObjectCommand& c = staged_.emplace_back();
  c.handle = h;
  c.kind = CommandKind::create;
  c.model = model;
  c.transform = t;
  if (o.lod_bias != 0 || o.min_level != 0 || o.max_level != 255 || o.priority != 1 || o.forced_level >= 0 ||
      o.never_cull) {
    ObjectCommand& oc = staged_.emplace_back();
    oc.handle = h;
    oc.kind = CommandKind::options;
    oc.options = o;
  }
  return h;
}

bool CommitQueue::destroy(ObjectHandle h) {
  std::lock_guard lock(stage_mutex_);
  if (!handles_.release(h)) return false;
  ObjectCommand& c = staged_.emplace_back();
  c.handle = h;
  c.kind = CommandKind::destroy;
  return true;
}

bool CommitQueue::set_transform(ObjectHandle h, const Transform& t) {
  if (!transform_valid(t)) return false;
  std::lock_guard lock(stage_mutex_);
  if (!handles_.live(h)) return false;
  ObjectCommand& c = staged_.emplace_back();
  c.handle = h;
  c.kind = CommandKind::transform;
  c.transform = t;
  return true;
}

bool CommitQueue::set_options(ObjectHandle h, const ObjectOptions& o) {
  if (!options_valid(o)) return false;
  std::lock_guard lock(stage_mutex_);
  if (!handles_.live(h)) return false;
  ObjectCommand& c = staged_.emplace_back();
  c.handle = h;
  c.kind = CommandKind::options;
  c.options = o;
  return true;
}

size_t CommitQueue::set_transforms(std::span<const ObjectHandle> h, std::span<const Transform> t) {
  const size_t n = std::min(h.size(), t.size());
  size_t accepted = 0;
  std::lock_guard lock(stage_mutex_);
  for (size_t i = 0; i < n; ++i) {
    if (!handles_.live(h[i]) || !transform_valid(t[i])) continue;
    ObjectCommand& c = staged_.emplace_back();
    c.handle = h[i];
    c.kind = CommandKind::transform;
    c.transform = t[i];
    ++accepted;
  }
  return accepted;
}

bool CommitQueue::live(ObjectHandle h) const {
  std::lock_guard lock(stage_mutex_);
  return handles_.live(h);
}

uint64_t CommitQueue::live_count() const {
  std::lock_guard lock(stage_mutex_);
  return handles_.live_count();
}

uint64_t CommitQueue::slots() const {
  std::lock_guard lock(stage_mutex_);
  return handles_.slots();
}

uint64_t CommitQueue::commits() const {
  std::lock_guard lock(stage_mutex_);
  return commits_;
}

bool CommitQueue::commit(uint64_t tick, uint64_t* last) {
  std::lock_guard stage(stage_mutex_);
  if (commits_ > 0 && tick < last_tick_) {
    if (last) *last = last_tick_;
    return false;
  }
  std::lock_guard pending(pending_mutex_);
  ++commits_;
  last_tick_ = tick;
  Batch& b = pending_.emplace_back();
  b.tick = tick;
  b.commands.swap(staged_);
  if (!spare_.empty()) {  // a recycled buffer keeps its capacity for the next batch
    staged_.swap(spare_.back());
    spare_.pop_back();
  } else {
    buffers_.fetch_add(1, std::memory_order_relaxed);  // the new staging buffer grows from empty
  }
  return true;
}

void CommitQueue::take(std::vector<Batch>& out) {
  std::lock_guard lock(pending_mutex_);
  out.swap(pending_);
}

void CommitQueue::recycle(std::vector<Batch>& used) {
  for (Batch& b : used) b.commands.clear();
  std::lock_guard lock(pending_mutex_);
  for (Batch& b : used) spare_.push_back(std::move(b.commands));
  used.clear();
}

}  // namespace lod
