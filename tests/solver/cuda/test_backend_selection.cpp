// Backend choice: "auto" uses CUDA where a device is usable and otherwise runs on the CPU
// with a one-line note; "cuda" without a device (or without the backend) is an InputError.
#include <gtest/gtest.h>

#include "sim/solver/solver_factory.h"
#include "sim/mesh/surface_mesh.h"
#include "sim/mesh/tet_mesh.h"
#if defined(SOFTTLED_HAVE_CUDA)
#include "sim/solver/cuda/cuda_solver.h"
#include "sim/solver/cuda/device_info.h"
#endif

using namespace softtled;

namespace {
TetMesh one_tet() {
  return make_tet_mesh({0, 0, 0, 1e-3, 0, 0, 0, 1e-3, 0, 0, 0, 1e-3}, {0, 1, 2, 3});
}
bool have_device() {
#if defined(SOFTTLED_HAVE_CUDA)
  return cuda::device_count() > 0;
#else
  return false;
#endif
}
}  // namespace

TEST(BackendSelection, AutoPicksCudaWhenPresentElseCpuWithNote) {
  const TetMesh m = one_tet();
  std::string note;
  auto s = make_solver("auto", m, 1000, std::vector<std::uint8_t>(4, 0), Precision::kFloat, &note);
  if (have_device()) {
    EXPECT_EQ(s->backend(), "cuda");
    EXPECT_TRUE(note.empty()) << note;
  } else {
    EXPECT_EQ(s->backend().rfind("cpu", 0), 0u) << s->backend();
    EXPECT_FALSE(note.empty());
    EXPECT_EQ(note.find('\n'), std::string::npos) << "one line: " << note;
  }
}

TEST(BackendSelection, CudaWithoutDeviceIsAnInputError) {
  if (have_device()) GTEST_SKIP() << "a CUDA device is present: nothing to refuse";
  const TetMesh m = one_tet();
  try {
    make_solver("cuda", m, 1000, std::vector<std::uint8_t>(4, 0), Precision::kFloat);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("cuda"), std::string::npos) << e.what();
  }
}

TEST(BackendSelection, UnknownBackendIsAnInputError) {
  const TetMesh m = one_tet();
  EXPECT_THROW(make_solver("opencl", m, 1000, std::vector<std::uint8_t>(4, 0), Precision::kFloat), InputError);
}

#if defined(SOFTTLED_HAVE_CUDA)
TEST(BackendSelection, CudaModesAreTheProductStepsAndTheGraphFallback) {
  // fused, halo and graph-pdl (what auto picks), graph (graph-pdl without PDL) and the opt-in
  // multi; the removed bench-only modes are input errors, not silently something else.
  for (cuda::ExecMode m : {cuda::ExecMode::kAuto, cuda::ExecMode::kFused, cuda::ExecMode::kGraphPdl, cuda::ExecMode::kGraph,
                           cuda::ExecMode::kMulti, cuda::ExecMode::kHalo})
    EXPECT_EQ(cuda::parse_exec_mode(cuda::exec_mode_name(m)), m);
  EXPECT_THROW(cuda::parse_exec_mode("plain"), InputError);
  EXPECT_THROW(cuda::parse_exec_mode("persistent"), InputError);
}
#endif
