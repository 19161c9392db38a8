#pragma once
// CUDA-OpenGL interop for one GL buffer (compiled only with SOFTTLED_CUDA; no CUDA
// headers here so GL code can include it). After cudaGraphicsGLRegisterBuffer(...,
// WriteDiscard), map() returns a device pointer to the GL buffer's storage for this frame;
// unmap() hands it back to GL (cuda-samples `particles`). When registration fails, the
// object keeps a cudaMalloc'd staging buffer instead and download() copies it to the host.
#include <cstddef>
#include <string>

#include "render/gl.h"

namespace softtled {

class CudaGlBuffer {
 public:
  CudaGlBuffer(GLuint gl_buffer, std::size_t bytes);
  ~CudaGlBuffer();
  CudaGlBuffer(const CudaGlBuffer&) = delete;
  CudaGlBuffer& operator=(const CudaGlBuffer&) = delete;

  bool interop() const { return resource_ != nullptr; }
  const std::string& why_not() const { return why_not_; }  // registration error, if any
  float* map();     // device pointer: the GL buffer (interop) or the staging buffer
  void unmap();     // interop: unmap; staging: nothing
  void download(float* host);  // staging only: device -> host

 private:
  void* resource_ = nullptr;  // cudaGraphicsResource_t
  float* staging_ = nullptr;
  std::size_t bytes_ = 0;
  std::string why_not_;
};

}  // namespace softtled
