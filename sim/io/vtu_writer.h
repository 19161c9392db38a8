#pragma once
// ParaView export: one .vtu (VTK unstructured grid, ASCII) per frame and a .pvd index.
// Point data: displacement, velocity, contact state; cell data: J and von Mises stress.
#include <string>
#include <vector>

#include "sim/fem/neo_hookean.h"
#include "sim/solver/solver.h"
#include "sim/mesh/tet_mesh.h"

namespace softtled {

// state may be null: the rest mesh alone. dt converts the increment du to a velocity.
void write_vtu(const std::string& path, const TetMesh& m, const HostState* state, double dt,
               const NeoHookean<double>& mat);

// Collects frames and keeps DIR/series.pvd up to date after each one.
class VtuSeries {
 public:
  explicit VtuSeries(std::string dir);
  void add(double t, const TetMesh& m, const HostState& s, double dt, const NeoHookean<double>& mat);

 private:
  std::string dir_;
  std::vector<std::pair<double, std::string>> frames_;
};

}  // namespace softtled
