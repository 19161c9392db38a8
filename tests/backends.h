#pragma once
// Physics-fact tests on every backend present (as Warp registers each test per device):
//   class TorusDrop : public test::OnEachBackend {};
//   TEST_P(TorusDrop, Lands) { Simulation sim(scene, backend()); ... }
//   SOFTTLED_ON_EACH_BACKEND(TorusDrop);
// The CUDA instance skips, saying why, where the build has no CUDA backend or the machine
// no usable device.
#include <gtest/gtest.h>

#include <string>

#if defined(SOFTTLED_HAVE_CUDA)
#include "sim/solver/cuda/device_info.h"
#endif

namespace softtled::test {

// Empty when `backend` can run here, else the reason it cannot.
inline std::string backend_unavailable(const std::string& backend) {
  if (backend != "cuda") return "";
#if defined(SOFTTLED_HAVE_CUDA)
  std::string why;
  return cuda::device_count(&why) > 0 ? "" : why;
#else
  return "this build has no CUDA backend (configure with -DSOFTTLED_CUDA=ON)";
#endif
}

class OnEachBackend : public ::testing::TestWithParam<std::string> {
 protected:
  void SetUp() override {
    const std::string why = backend_unavailable(GetParam());
    if (!why.empty()) GTEST_SKIP() << GetParam() << " backend: " << why;
  }
  const std::string& backend() const { return GetParam(); }
};

}  // namespace softtled::test

#define SOFTTLED_ON_EACH_BACKEND(Fixture)                                                       \
  INSTANTIATE_TEST_SUITE_P(Backends, Fixture, ::testing::Values(std::string("cpu"), std::string("cuda")), \
                           [](const ::testing::TestParamInfo<std::string>& info) { return info.param; })
