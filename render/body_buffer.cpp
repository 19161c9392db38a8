#include "render/body_buffer.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "render/cuda_gl_buffer.h"

namespace softtled {

#ifndef SOFTTLED_RENDER_CUDA_INTEROP
// Without CUDA the interop object is never created, but unique_ptr still needs its destructor.
CudaGlBuffer::~CudaGlBuffer() = default;
#endif

BodyVertexBuffer::BodyVertexBuffer(int nvert, const std::vector<int>& tri) : nvert_(nvert), nindex_(int(tri.size())) {
  glGenVertexArrays(1, &vao_);
  glBindVertexArray(vao_);
  glGenBuffers(1, &vbo_);
  glBindBuffer(GL_ARRAY_BUFFER, vbo_);
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(sizeof(float)) * kBodyFloatsPerVertex * nvert_, nullptr, GL_DYNAMIC_DRAW);
  const GLsizei stride = sizeof(float) * kBodyFloatsPerVertex;
  glEnableVertexAttribArray(0);  // position [m]
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, stride, reinterpret_cast<void*>(0));
  glEnableVertexAttribArray(1);  // normal
  glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, stride, reinterpret_cast<void*>(3 * sizeof(float)));
  glEnableVertexAttribArray(2);  // the colour scalar: |u| [m] or von Mises [Pa]
  glVertexAttribPointer(2, 1, GL_FLOAT, GL_FALSE, stride, reinterpret_cast<void*>(kBodyScalarSlot * sizeof(float)));
  glEnableVertexAttribArray(3);  // contact state 0 free / 1 stick / 2 slide
  glVertexAttribPointer(3, 1, GL_FLOAT, GL_FALSE, stride, reinterpret_cast<void*>(7 * sizeof(float)));
  glGenBuffers(1, &ibo_);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, ibo_);
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(sizeof(int)) * nindex_, tri.data(), GL_STATIC_DRAW);
  glBindVertexArray(0);
  check_gl("creating the body vertex buffer");
}

BodyVertexBuffer::~BodyVertexBuffer() {
  cuda_.reset();  // unregister before the GL buffer goes
  glDeleteBuffers(1, &ibo_);
  glDeleteBuffers(1, &vbo_);
  glDeleteVertexArrays(1, &vao_);
}

float* BodyVertexBuffer::map(bool on_device) {
  const std::size_t nfloat = std::size_t(kBodyFloatsPerVertex) * nvert_;
  mapped_on_device_ = on_device;
  if (on_device) {
#ifdef SOFTTLED_RENDER_CUDA_INTEROP
    if (!cuda_) cuda_ = std::make_unique<CudaGlBuffer>(vbo_, nfloat * sizeof(float));
    return cuda_->map();
#else
    throw std::runtime_error("the vertices are written on the device, but this build has no CUDA-GL interop");
#endif
  }
  host_.resize(nfloat);
  return host_.data();
}

void BodyVertexBuffer::unmap() {
  const std::size_t nfloat = std::size_t(kBodyFloatsPerVertex) * nvert_;
  if (mapped_on_device_) {
#ifdef SOFTTLED_RENDER_CUDA_INTEROP
    cuda_->unmap();
    if (cuda_->interop()) {
      path_ = "interop";
      return;
    }
    host_.resize(nfloat);
    cuda_->download(host_.data());
    path_ = "staging";
#endif
  } else {
    path_ = "host";
  }
  glBindBuffer(GL_ARRAY_BUFFER, vbo_);
  glBufferSubData(GL_ARRAY_BUFFER, 0, GLsizeiptr(nfloat * sizeof(float)), host_.data());
  glBindBuffer(GL_ARRAY_BUFFER, 0);
}

float BodyVertexBuffer::scalar_max() const {
  if (path_.empty()) return 0.f;  // never written
  const std::size_t nfloat = std::size_t(kBodyFloatsPerVertex) * nvert_;
  std::vector<float> back;
  const float* v = host_.data();  // the host and staging paths keep what they uploaded
  if (path_ == "interop") {
    back.resize(nfloat);
    glBindBuffer(GL_ARRAY_BUFFER, vbo_);
    glGetBufferSubData(GL_ARRAY_BUFFER, 0, GLsizeiptr(nfloat * sizeof(float)), back.data());
    glBindBuffer(GL_ARRAY_BUFFER, 0);
    v = back.data();
  }
  float m = 0.f;
  for (int i = 0; i < nvert_; ++i) {
    const float s = v[std::size_t(kBodyFloatsPerVertex) * i + kBodyScalarSlot];
    if (std::isfinite(s)) m = std::max(m, s);
  }
  return m;
}

void BodyVertexBuffer::draw() const {
  glBindVertexArray(vao_);
  glDrawElements(GL_TRIANGLES, nindex_, GL_UNSIGNED_INT, nullptr);
  glBindVertexArray(0);
}

}  // namespace softtled
