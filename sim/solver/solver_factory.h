#pragma once
// Picks the backend by name: "cpu", "cuda" or "auto" (CUDA when a device is present).
#include <memory>
#include <string>

#include "sim/solver/solver.h"

namespace softtled {

// Throws InputError for an unknown or unavailable backend. `note` receives a one-line
// message when "auto" falls back to the CPU.
std::unique_ptr<Solver> make_solver(const std::string& backend, const TetMesh& mesh, double rho,
                                    const std::vector<std::uint8_t>& flags, Precision prec,
                                    std::string* note = nullptr);

}  // namespace softtled
