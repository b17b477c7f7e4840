// HandleTable: which object handles are live. A slot's generation grows each time its object
// is destroyed, so an old handle never names the slot's next object. Freed slots are reused
// last-in first-out, so a churn of creates and destroys keeps the table at its peak size.
#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

#include "lodkit/types.hpp"

namespace lod {

class HandleTable {
 public:
  ObjectHandle allocate();
  bool live(ObjectHandle h) const {
    const uint32_t slot = static_cast<uint32_t>(h);
    return h != 0 && slot < generation_.size() && live_[slot] && generation_[slot] == static_cast<uint32_t>(h >> 32);
  }
  bool release(ObjectHandle h);  // false when not live
  uint64_t live_count() const { return live_count_; }
  size_t slots() const { return generation_.size(); }

 private:
  std::vector<uint32_t> generation_;  // per slot, never 0
  std::vector<uint8_t> live_;
  std::vector<uint32_t> free_;
  uint64_t live_count_ = 0;
};

}  // namespace lod
