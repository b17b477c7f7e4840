// Status: what a boundary (file, config, asset) returns instead of throwing.
// The message names the file and the element that is wrong.
#pragma once
#include <string>
#include <utility>

namespace lod {

struct Status {
  bool ok = true;
  std::string message;  // empty when ok

  static Status success() { return {}; }
  static Status error(std::string msg) { return {false, std::move(msg)}; }
  explicit operator bool() const { return ok; }
};

}  // namespace lod
