// lod run --validate for HLOD models: every frame's drawn cut (Frame::hlod_drawn / hlod_opened)
// is a cut of its tree and opens no crack (runtime/hlod_cut_check, against the model's own open
// edges), no wanted node is a hole, and the resident bytes stay within the stream budget.
// The check reads every node of the .hlod files itself, once, independent of the pager.
#pragma once
#include <string>
#include <vector>

#include "jobs/hlod_models.h"
#include "runtime/frame.h"
#include "runtime/hlod_cut_check.h"

namespace lod::cli {

class HlodCheck {
 public:
  // Reads every node of every model (a node that cannot be read stays empty).
  void load(const HlodModels& models);
  // False with `why` at the first fault of `f`.
  bool check(const Frame& f, std::string* why) const;

 private:
  struct Model {
    const HlodTree* tree = nullptr;
    std::vector<HlodPayload> payloads;
    std::vector<const HlodPayload*> pointers;
    HlodCutReference reference;
  };
  bool check_cut(const Frame& f, uint32_t m, std::string* why) const;
  std::vector<Model> models_;
};

}  // namespace lod::cli
