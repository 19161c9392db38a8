#include "render/cuda_gl_buffer.h"

// gl.h (GLEW) before cuda_gl_interop.h, which includes GL/gl.h.
#include <cuda_gl_interop.h>
#include <cuda_runtime.h>

#include <stdexcept>
#include <string>

namespace softtled {
namespace {
void check(cudaError_t e, const char* what) {
  if (e != cudaSuccess) throw std::runtime_error(std::string(what) + ": " + cudaGetErrorString(e));
}
}  // namespace

CudaGlBuffer::CudaGlBuffer(GLuint gl_buffer, std::size_t bytes) : bytes_(bytes) {
  cudaGraphicsResource_t r = nullptr;
  const cudaError_t e = cudaGraphicsGLRegisterBuffer(&r, gl_buffer, cudaGraphicsRegisterFlagsWriteDiscard);
  if (e == cudaSuccess) {
    resource_ = r;
    return;
  }
  (void)cudaGetLastError();  // clear the sticky-free error so later CUDA calls do not report it
  why_not_ = cudaGetErrorString(e);
  check(cudaMalloc(&staging_, bytes), "cudaMalloc (render staging buffer)");
}

CudaGlBuffer::~CudaGlBuffer() {
  if (resource_) cudaGraphicsUnregisterResource(static_cast<cudaGraphicsResource_t>(resource_));
  if (staging_) cudaFree(staging_);
}

float* CudaGlBuffer::map() {
  if (!resource_) return staging_;
  auto r = static_cast<cudaGraphicsResource_t>(resource_);
  check(cudaGraphicsMapResources(1, &r, 0), "cudaGraphicsMapResources");
  void* p = nullptr;
  std::size_t n = 0;
  check(cudaGraphicsResourceGetMappedPointer(&p, &n, r), "cudaGraphicsResourceGetMappedPointer");
  if (n < bytes_) throw std::runtime_error("mapped GL buffer is smaller than the render vertices");
  return static_cast<float*>(p);
}

void CudaGlBuffer::unmap() {
  if (!resource_) return;
  auto r = static_cast<cudaGraphicsResource_t>(resource_);
  check(cudaGraphicsUnmapResources(1, &r, 0), "cudaGraphicsUnmapResources");
}

void CudaGlBuffer::download(float* host) {
  check(cudaMemcpy(host, staging_, bytes_, cudaMemcpyDeviceToHost), "cudaMemcpy (render staging buffer)");
}

}  // namespace softtled
