#include "viewer/morph_buffers.h"

#include <algorithm>

namespace lod::viewer {

MorphBuffers::~MorphBuffers() {
  if (vbo_) glDeleteBuffers(1, &vbo_);
}

void MorphBuffers::init(std::span<const LodChain> chains) {
  streams_ = MorphStreams(chains);
  glGenBuffers(1, &vbo_);
}

int64_t MorphBuffers::stream(uint32_t model, uint32_t fine, uint32_t coarse) {
  const int64_t first = streams_.offset_of(model, fine, coarse);
  const std::vector<float>& v = streams_.vertices();
  if (first < 0 || v.size() == uploaded_) return first;
  glBindBuffer(GL_ARRAY_BUFFER, vbo_);
  if (v.size() > capacity_) {
    capacity_ = std::max(v.size(), 2 * capacity_);
    glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(capacity_ * sizeof(float)), nullptr, GL_STATIC_DRAW);
    uploaded_ = 0;
  }
  glBufferSubData(GL_ARRAY_BUFFER, GLintptr(uploaded_ * sizeof(float)),
                  GLsizeiptr((v.size() - uploaded_) * sizeof(float)), v.data() + uploaded_);
  uploaded_ = v.size();
  return first;
}

}  // namespace lod::viewer
