// CPU time per explicit step on the paper's torus (Google Benchmark), at 1 and 2 threads.
#include <benchmark/benchmark.h>
#include <omp.h>

#include "sim/scene/scene.h"
#include "sim/scene/simulation.h"

using namespace softtled;

static void BM_TorusStep(benchmark::State& state) {
  const bool f32 = state.range(1) == 1;
  Scene s = parse_scene("", "bench", {std::string("solver.precision=") + (f32 ? "float" : "double")});
  omp_set_num_threads(int(state.range(0)));
  Simulation sim(s);
  sim.step(100);
  for (auto _ : state) sim.step(1);
  state.counters["tets"] = sim.mesh().ntet();
  state.counters["us_per_step"] = benchmark::Counter(double(state.iterations()) * 1e-6,
                                                      benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_TorusStep)->ArgsProduct({{1, 2}, {0, 1}})->ArgNames({"threads", "float"})->Unit(benchmark::kMicrosecond);
BENCHMARK_MAIN();
