#include "solver_factory.h"

#include "surface_mesh.h"

namespace softtled {

std::unique_ptr<Solver> make_solver(const std::string& backend, const TetMesh& mesh, double rho,
                                    const std::vector<std::uint8_t>& flags, Precision prec,
                                    std::string* note) {
  if (backend == "cpu") return make_cpu_solver(mesh, rho, flags, prec);
  if (backend == "auto") {
    if (note) *note = "no CUDA backend in this build: running on the CPU";
    return make_cpu_solver(mesh, rho, flags, prec);
  }
  if (backend == "cuda") throw InputError("backend 'cuda': this build has no CUDA backend");
  throw InputError("unknown backend '" + backend + "' (use cpu, cuda or auto)");
}

}  // namespace softtled
