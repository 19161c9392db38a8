#pragma once
// RAII owner of one device allocation (the views in body_view.h only borrow pointers).
// Move-only; frees in the destructor. Copies to and from host vectors are synchronous
// unless a stream is given.
#include <cuda_runtime_api.h>

#include <cstddef>
#include <utility>
#include <vector>

#include "sim/solver/cuda/cuda_check.h"

namespace softtled::cuda {

template <class T>
class DeviceBuffer {
 public:
  DeviceBuffer() = default;
  explicit DeviceBuffer(std::size_t n) { resize(n); }
  explicit DeviceBuffer(const std::vector<T>& host) { upload(host); }
  DeviceBuffer(const DeviceBuffer&) = delete;
  DeviceBuffer& operator=(const DeviceBuffer&) = delete;
  DeviceBuffer(DeviceBuffer&& o) noexcept : ptr_(std::exchange(o.ptr_, nullptr)), n_(std::exchange(o.n_, 0)) {}
  DeviceBuffer& operator=(DeviceBuffer&& o) noexcept {
    if (this != &o) {
      release();
      ptr_ = std::exchange(o.ptr_, nullptr);
      n_ = std::exchange(o.n_, 0);
    }
    return *this;
  }
  ~DeviceBuffer() { release(); }

  // Discards the contents when the size changes.
  void resize(std::size_t n) {
    if (n == n_) return;
    release();
    if (n > 0) SOFTTLED_CUDA_CHECK(cudaMalloc(reinterpret_cast<void**>(&ptr_), n * sizeof(T)));
    n_ = n;
  }
  void upload(const std::vector<T>& host) {
    resize(host.size());
    if (n_) SOFTTLED_CUDA_CHECK(cudaMemcpy(ptr_, host.data(), n_ * sizeof(T), cudaMemcpyHostToDevice));
  }
  void download(std::vector<T>& host) const {
    host.resize(n_);
    if (n_) SOFTTLED_CUDA_CHECK(cudaMemcpy(host.data(), ptr_, n_ * sizeof(T), cudaMemcpyDeviceToHost));
  }
  void fill_zero() {
    if (n_) SOFTTLED_CUDA_CHECK(cudaMemset(ptr_, 0, n_ * sizeof(T)));
  }

  T* data() { return ptr_; }
  const T* data() const { return ptr_; }
  std::size_t size() const { return n_; }
  std::size_t bytes() const { return n_ * sizeof(T); }
  bool empty() const { return n_ == 0; }

 private:
  void release() noexcept {
    if (ptr_) cudaFree(ptr_);  // an error here cannot be reported from a destructor
    ptr_ = nullptr;
    n_ = 0;
  }
  T* ptr_ = nullptr;
  std::size_t n_ = 0;
};

// Page-locked host memory for small device-to-host results: an async copy into it is a
// plain DMA, where pageable memory goes through a staging copy and a wait.
template <class T>
class PinnedBuffer {
 public:
  explicit PinnedBuffer(std::size_t n) : n_(n) {
    SOFTTLED_CUDA_CHECK(cudaMallocHost(reinterpret_cast<void**>(&ptr_), n * sizeof(T)));
  }
  PinnedBuffer(const PinnedBuffer&) = delete;
  PinnedBuffer& operator=(const PinnedBuffer&) = delete;
  ~PinnedBuffer() { cudaFreeHost(ptr_); }
  T* data() { return ptr_; }
  T& operator[](std::size_t i) { return ptr_[i]; }
  std::size_t bytes() const { return n_ * sizeof(T); }

 private:
  T* ptr_ = nullptr;
  std::size_t n_ = 0;
};

}  // namespace softtled::cuda
