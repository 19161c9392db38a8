#include "sim/solver/solver_factory.h"

#include "sim/mesh/surface_mesh.h"
#if defined(SOFTTLED_HAVE_CUDA)
#include "sim/solver/cuda/cuda_solver.h"
#include "sim/solver/cuda/device_info.h"
#endif

namespace softtled {

void check_backend_available(const std::string& backend) {
  if (backend == "cpu" || backend == "auto") return;
  if (backend != "cuda") throw InputError("unknown backend '" + backend + "' (use cpu, cuda or auto)");
#if defined(SOFTTLED_HAVE_CUDA)
  std::string why;
  if (cuda::device_count(&why) <= 0) throw InputError("backend 'cuda': " + why);
#else
  throw InputError("backend 'cuda': this build has no CUDA backend (configure with -DSOFTTLED_CUDA=ON)");
#endif
}

std::unique_ptr<Solver> make_solver(const std::string& backend, const TetMesh& mesh, double rho,
                                    const std::vector<std::uint8_t>& flags, Precision prec,
                                    std::string* note) {
  check_backend_available(backend);
  if (backend == "cpu") return make_cpu_solver(mesh, rho, flags, prec);
#if defined(SOFTTLED_HAVE_CUDA)
  if (backend == "cuda") return make_cuda_solver(mesh, rho, flags, prec);
  std::string why;
  if (cuda::device_count(&why) > 0) return make_cuda_solver(mesh, rho, flags, prec);
  if (note) *note = "backend auto: " + why + "; running on the CPU";
#else
  if (note) *note = "backend auto: no CUDA backend in this build; running on the CPU";
#endif
  return make_cpu_solver(mesh, rho, flags, prec);  // auto without a usable device
}

}  // namespace softtled
