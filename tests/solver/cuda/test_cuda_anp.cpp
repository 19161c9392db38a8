// T4ANP (average nodal pressure tets, sim/fem/anp.h) on the CUDA backend: the paper's torus
// drop with material.element = T4ANP follows the CPU backend's trajectory (float within
// float tolerance, double to rounding), is bitwise repeatable in every execution mode, and
// really is T4ANP (not the T4 step). Skipped with a message where no CUDA device is usable.
#include "cuda_test_helpers.h"

using namespace softtled;
using namespace softtled::test;

namespace {

Scene torus(const std::string& precision, const std::string& element = "T4ANP") {
  return load_scene(test::assets_dir() + "/scenes/torus_drop.toml",
                    {"solver.precision=" + precision, "material.element=" + element});
}

}  // namespace

TEST(CudaAnp, TorusDropMatchesCpuWithinFloatTolerance) {
  SKIP_WITHOUT_GPU();
  auto cpu_f = make_sim(torus("float"), "cpu");
  auto gpu_f = make_sim(torus("float"), "cuda");
  auto cpu_d = make_sim(torus("double"), "cpu");
  auto gpu_d = make_sim(torus("double"), "cuda");
  auto gpu_t4 = make_sim(torus("double", "T4"), "cuda");
  ASSERT_EQ(gpu_f->backend(), "cuda");
  ASSERT_EQ(gpu_d->params().element, kT4ANP);
  const double dt = cpu_f->time_step().dt;
  ASSERT_EQ(dt, gpu_d->time_step().dt);
  ASSERT_EQ(dt, gpu_t4->time_step().dt);
  // Free fall until ~0.02 s (no strain: both elements agree), impact and compression after.
  for (double t : {0.01, 0.025, 0.04, 0.06}) {
    const long target = std::lround(t / dt);
    for (Simulation* s : {cpu_f.get(), gpu_f.get(), cpu_d.get(), gpu_d.get(), gpu_t4.get()}) s->step(target - s->steps());
    const double gf_cf = max_diff(*gpu_f, *cpu_f);
    const double gf_cd = max_diff(*gpu_f, *cpu_d);
    const double cf_cd = max_diff(*cpu_f, *cpu_d);
    const double gd_cd = max_diff(*gpu_d, *cpu_d);
    const double anp_t4 = max_diff(*gpu_d, *gpu_t4);
    std::printf("T4ANP t = %.3f s: max |x| diff  gpu-f vs cpu-f %.3g m, gpu-f vs cpu-d %.3g m, cpu-f vs cpu-d %.3g m, "
                "gpu-d vs cpu-d %.3g m; T4ANP vs T4 (gpu-d) %.3g m; contacts %d\n",
                t, gf_cf, gf_cd, cf_cd, gd_cd, anp_t4, gpu_d->diagnostics().n_contact);
    EXPECT_LT(gf_cf, 5e-6) << "t = " << t;              // 5 um on a 20 mm body
    EXPECT_LT(gf_cd, 3 * cf_cd + 1e-6) << "t = " << t;  // as accurate as the CPU in float
    EXPECT_LT(gd_cd, 1e-9) << "t = " << t;              // double: rounding only (gather order)
    if (t > 0.03) EXPECT_GT(anp_t4, 1e-6) << "t = " << t << ": the CUDA step must run T4ANP, not T4";
  }
  EXPECT_GT(gpu_d->diagnostics().n_contact, 0) << "the torus should be on the floor by 0.06 s";
}

TEST(CudaAnp, AllExecutionModesAreBitwiseIdentical) {
  SKIP_WITHOUT_GPU();
  const long steps = 5000;  // past the first contact (~3600 steps); the nodal pressure uses the node stage's lanes
  expect_modes_bitwise_identical(torus("float"), steps, "T4ANP, ", [](cuda::ExecMode m, cuda::CudaSolverApi& api) {
    // T4ANP's fused and halo steps (two kernels each: pressures, then forces and nodes) really run.
    if (m == cuda::ExecMode::kFused || m == cuda::ExecMode::kMulti || m == cuda::ExecMode::kHalo)
      EXPECT_EQ(api.exec_mode(), m);
  });
}

TEST(CudaAnp, RayleighBetaAllExecutionModesAreBitwiseIdentical) {
  SKIP_WITHOUT_GPU();
  Scene s = torus("float");
  s.beta = 2e-6;  // the three T4ANP stages read u + (beta / dt) du
  expect_modes_bitwise_identical(s, 5000, "T4ANP, beta, ", [](cuda::ExecMode, cuda::CudaSolverApi&) {});
}

TEST(CudaAnp, SwitchingElementLiveRebuildsTheStep) {
  SKIP_WITHOUT_GPU();
  // T4 for 3000 steps, then T4ANP (the viewer's live edit): must match the CPU doing the same.
  auto cpu = make_sim(torus("double", "T4"), "cpu");
  auto gpu = make_sim(torus("double", "T4"), "cuda");
  for (Simulation* s : {cpu.get(), gpu.get()}) {
    s->step(3000);
    PhysicsParams p = s->params();
    p.element = kT4ANP;
    s->set_params(p);
    s->step(2500);
  }
  const double d = max_diff(*cpu, *gpu);
  std::printf("T4 -> T4ANP live switch: gpu-d vs cpu-d %.3g m\n", d);
  EXPECT_LT(d, 1e-9);
}

TEST(CudaAnp, StrainEnergyIsTheNodalOneAndMatchesCpu) {
  SKIP_WITHOUT_GPU();
  // T4ANP's energy (anp.h: deviatoric per element + kappa/2 (J_i - 1)^2 per node) on the
  // GPU (element and node terms, fixed-order sum) against the CPU's, on the same state in
  // contact; double, so only the summation order differs.
  auto cpu = make_sim(torus("double"), "cpu");
  auto gpu = make_sim(torus("double"), "cuda");
  cpu->step(4500);
  HostState st = cpu->state();
  gpu->set_state(st);
  const double ec = SolverAccess::of(*cpu).strain_energy(), eg = SolverAccess::of(*gpu).strain_energy();
  EXPECT_GT(ec, 0.0);
  EXPECT_NEAR(eg, ec, 1e-12 * ec);
  EXPECT_EQ(eg, SolverAccess::of(*gpu).strain_energy()) << "the reduction must be deterministic";
  // Not the element-wise T4 energy of the same state: the nodal volume term differs.
  PhysicsParams p = gpu->params();
  p.element = kT4;
  gpu->set_params(p);
  EXPECT_GT(std::abs(SolverAccess::of(*gpu).strain_energy() - eg), 1e-6 * ec);
}
