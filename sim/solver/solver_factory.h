#pragma once
// Picks the backend by name: "cpu", "cuda" or "auto" (CUDA when a device is present).
#include <memory>
#include <string>

#include "sim/solver/solver.h"

namespace softtled {

// InputError for an unknown backend, or "cuda" where this build has no CUDA backend or no
// device is usable; cheap, so callers ask it before meshing or creating outputs.
void check_backend_available(const std::string& backend);

// Throws InputError for an unknown or unavailable backend (check_backend_available). `note` receives a one-line
// message when "auto" falls back to the CPU.
std::unique_ptr<Solver> make_solver(const std::string& backend, const TetMesh& mesh, double rho,
                                    const std::vector<std::uint8_t>& flags, Precision prec,
                                    std::string* note = nullptr);

}  // namespace softtled
