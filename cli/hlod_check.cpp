// lod run --validate on HLOD models: cut shape, cracks, holes, the byte budget.
#include "cli/hlod_check.h"

#include "runtime/hlod_asset.h"

namespace lod::cli {

void HlodCheck::load(const HlodModels& h) {
  models_.clear();
  models_.resize(h.trees.size());
  for (size_t m = 0; m < h.trees.size(); ++m) {
    Model& model = models_[m];
    model.tree = &h.trees[m];
    model.payloads.resize(model.tree->nodes.size());
    // A node that cannot be read stays without geometry: the pager cannot load it either, so
    // the frames must never draw it (if one did, its edges would count as gaps).
    for (size_t n = 0; n < model.payloads.size(); ++n) {
      const bool read = read_hlod_node(h.files[m], model.tree->nodes[n], model.payloads[n]).ok;
      model.pointers.push_back(read ? &model.payloads[n] : nullptr);
    }
    model.reference = hlod_cut_reference(*model.tree, model.pointers);
  }
}

bool HlodCheck::check_cut(const Frame& f, uint32_t m, std::string* why) const {
  const Model& model = models_[m];
  std::vector<int8_t> cut(model.tree->nodes.size(), kHlodCutOutside);
  bool any = false;
  for (const HlodDrawFrame& d : f.hlod_drawn)
    if (d.model == m && d.node < cut.size()) cut[d.node] = int8_t(d.layer), any = true;
  for (const HlodOpenedFrame& o : f.hlod_opened)
    if (o.model == m && o.node < cut.size()) cut[o.node] = kHlodCutOpened, any = true;
  // Nothing of it: the root is outside the frustum (a missing root is a hole, checked before).
  if (!any) return true;
  const std::string name = "hlod model " + std::to_string(m) + " (" + model.tree->name + "): ";
  std::string message;
  if (!validate_hlod_cut(*model.tree, cut, &message)) {
    *why = name + "not a cut: " + message;
    return false;
  }
  const size_t gaps = count_cut_gaps(*model.tree, model.pointers, cut, model.reference);
  if (gaps != 0) {
    *why = name + std::to_string(gaps) + " edges of the drawn cut open a crack";
    return false;
  }
  return true;
}

bool HlodCheck::check(const Frame& f, std::string* why) const {
  if (models_.empty()) return true;
  if (f.holes != 0) {
    *why = std::to_string(f.holes) + " hlod holes (wanted nodes with no drawn ancestor)";
    return false;
  }
  if (f.resident_bytes > f.stream_budget) {
    *why = "resident bytes " + std::to_string(f.resident_bytes) + " exceed the stream budget " +
           std::to_string(f.stream_budget);
    return false;
  }
  if (f.hlod_nodes_drawn != f.hlod_drawn.size()) {
    *why = "hlod_nodes_drawn does not match the drawn list";
    return false;
  }
  for (uint32_t m = 0; m < models_.size(); ++m)
    if (!check_cut(f, m, why)) return false;
  return true;
}

}  // namespace lod::cli
