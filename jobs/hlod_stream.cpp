// HlodStream: select every model's cut, then page them all, once per frame.
#include "jobs/hlod_stream.h"

#include <algorithm>
#include <cfloat>
#include <cassert>
#include <chrono>
#include <thread>
#include <utility>

namespace lod {

std::vector<HlodStream::Model> HlodStream::models_of(std::vector<HlodTree> trees) {
  std::vector<Model> models(trees.size());
  uint32_t first = 0;
  for (size_t m = 0; m < trees.size(); ++m) {
    models[m].tree = std::move(trees[m]);
    models[m].first = first;
    first += uint32_t(models[m].tree.nodes.size());
    prepare_hlod_cut(models[m].cut, models[m].scratch, models[m].tree);
  }
  return models;
}

std::vector<uint64_t> HlodStream::bytes_of(const std::vector<Model>& models) {
  std::vector<uint64_t> bytes;
  for (const Model& m : models) {
    const std::vector<uint64_t> b = node_bytes_of(m.tree);
    bytes.insert(bytes.end(), b.begin(), b.end());
  }
  return bytes;
}

Status HlodStream::load_node(uint32_t node, HlodPayload& out) const {
  const uint32_t m = model_of_[node];
  return load_(m, node - models_[m].first, out);
}

HlodStream::HlodStream(std::vector<HlodTree> trees, const StreamPagerConfig& config, ModelNodeLoader load)
    : models_(models_of(std::move(trees))),
      model_of_([this] {
        std::vector<uint32_t> of;
        for (uint32_t m = 0; m < models_.size(); ++m) of.insert(of.end(), models_[m].tree.nodes.size(), m);
        return of;
      }()),
      load_(std::move(load)),
      pager_(bytes_of(models_), config,
             [this](uint32_t node, HlodPayload& out) { return load_node(node, out); }) {
  wanted_.reserve(model_of_.size());
  in_use_.reserve(model_of_.size());
}

HlodStream::HlodStream(HlodTree tree, const StreamPagerConfig& config, NodeLoader load)
    : HlodStream(
          [&] {
            std::vector<HlodTree> one;
            one.push_back(std::move(tree));
            return one;
          }(),
          config,
          [load = std::move(load)](uint32_t, uint32_t node, HlodPayload& out) { return load(node, out); }) {}

std::span<const uint8_t> HlodStream::residency(uint32_t model) const {
  return pager_.residency().subspan(models_[model].first, models_[model].tree.nodes.size());
}

void HlodStream::frame(uint64_t frame, const HlodView& view, std::span<const HlodModelInput> inputs) {
  assert(inputs.size() == models_.size());
  wanted_.clear();
  in_use_.clear();
  for (uint32_t m = 0; m < models_.size(); ++m) {
    Model& model = models_[m];
    select_hlod_cut(model.cut, model.scratch, model.tree, residency(m), inputs[m].transform, view,
                    inputs[m].params);
    for (const HlodRequest& r : model.cut.requests)
      wanted_.push_back({r.node + model.first, r.deficit, r.distance});
    for (const uint32_t k : model.cut.kept) in_use_.push_back(k + model.first);
  }
  // One priority order across models (each cut's requests are already in it).
  if (models_.size() > 1) std::sort(wanted_.begin(), wanted_.end(), request_before);
  update_ = &pager_.update(frame + frame_offset_, wanted_, in_use_);
  keep_failures(*update_);
}

void HlodStream::keep_failures(const StreamUpdate& update) {
  for (const StreamFailure& f : update.failures) {
    const uint32_t m = model_of_[f.node];
    failures_.push_back({m, f.node - models_[m].first, f.why});
  }
}

bool HlodStream::load_roots(double timeout_s) {
  std::vector<HlodRequest> roots;
  std::vector<uint32_t> keep;
  for (const Model& m : models_) {
    roots.push_back({m.first, FLT_MAX, 0});
    keep.push_back(m.first);
  }
  const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  for (;;) {
    const StreamUpdate& u = pager_.update(++frame_offset_, roots, keep);
    keep_failures(u);
    if (!u.failures.empty()) return false;
    const bool all = std::all_of(keep.begin(), keep.end(), [&](uint32_t n) { return pager_.residency()[n] != 0; });
    if (all) return true;
    if (std::chrono::steady_clock::now() > until) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
}

const HlodCut& HlodStream::frame(uint64_t frame_index, const Transform& transform, const HlodView& view,
                                 const HlodSelectParams& params) {
  const HlodModelInput input{transform, params};
  frame(frame_index, view, std::span<const HlodModelInput>(&input, 1));
  return models_[0].cut;
}

HlodStreamFigures HlodStream::figures() const {
  HlodStreamFigures f;
  for (const Model& m : models_) {
    f.hlod_nodes_drawn += uint32_t(m.cut.drawn.size());
    f.hlod_triangles += m.cut.triangles;
    f.holes += m.cut.holes;
    f.wanted += uint32_t(m.cut.requests.size());
  }
  const StreamCounters& c = pager_.counters();
  f.resident_bytes = pager_.resident_bytes();
  f.stream_requests = c.requests;
  f.stream_loads = c.loads;
  f.stream_failures = c.failures;
  f.stream_evictions = c.evictions;
  return f;
}

}  // namespace lod
