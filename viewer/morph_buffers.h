// MorphBuffers: the GL side of MorphStreams. One vertex buffer holds every composed target
// stream made so far; a stream is uploaded the first time a blended draw needs it (the
// buffer grows by doubling, re-uploading what it held).
#pragma once
#include <cstdint>
#include <span>

#include <epoxy/gl.h>

#include "viewer/morph_streams.h"

namespace lod::viewer {

class MorphBuffers {
 public:
  MorphBuffers() = default;
  ~MorphBuffers();
  MorphBuffers(const MorphBuffers&) = delete;
  MorphBuffers& operator=(const MorphBuffers&) = delete;

  void init(std::span<const LodChain> chains);
  // First vertex of the pair's stream in buffer(), made and uploaded on first use; -1 when
  // the model cannot blend.
  int64_t stream(uint32_t model, uint32_t fine, uint32_t coarse);

  GLuint buffer() const { return vbo_; }
  size_t stream_count() const { return streams_.stream_count(); }
  size_t bytes() const { return streams_.vertices().size() * sizeof(float); }

 private:
  MorphStreams streams_;
  GLuint vbo_ = 0;
  size_t uploaded_ = 0;  // floats on the GPU
  size_t capacity_ = 0;  // floats the buffer can hold
};

}  // namespace lod::viewer
