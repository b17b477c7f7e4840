// Captures what OpenMesh says on omerr()/omout()/omlog() while the calling thread reads a
// mesh, without touching std::cout/cerr/clog: a host's logging on other threads is never
// redirected or lost.
#pragma once
#include <string>

namespace lod::detail {

// While an OpenMeshLogCapture lives, every character the *constructing thread* writes to
// OpenMesh's three log streams lands in text() instead of the terminal (nothing, for a stream
// that is disabled, as it would have printed nothing); other threads' writes
// to those streams go where they always went. Captures nest on one thread (the inner one
// gets the text until it ends). OpenMesh's readers that write to std::cerr
// directly (a few PLY/OFF conversion warnings) are not caught: doing so would need the
// process-wide swap this class exists to avoid. Writing to one OpenMesh stream from several
// threads at once is as safe as OpenMesh makes it (its buffer locks; the std::ostream's
// formatting state is shared), with or without a capture.
class OpenMeshLogCapture {
 public:
  OpenMeshLogCapture();
  ~OpenMeshLogCapture();
  OpenMeshLogCapture(const OpenMeshLogCapture&) = delete;
  OpenMeshLogCapture& operator=(const OpenMeshLogCapture&) = delete;

  // What was said so far, on one line: whitespace runs collapsed, trimmed, at most ~300 characters.
  std::string text() const;

 private:
  std::string raw_;
  std::string* previous_ = nullptr;
};

}  // namespace lod::detail
