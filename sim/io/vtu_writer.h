#pragma once
// ParaView export: one .vtu (VTK unstructured grid, ASCII) per frame, or per body and frame
// for a mesh of several bodies, and a .pvd index.
// Point data: displacement, velocity, contact state; cell data: J and von Mises stress
// (scaled by the mesh's E_scale where a body has its own E), and for a mesh of several
// bodies written as one file (mesh --vtu) the body of each element.
#include <string>
#include <vector>

#include "sim/fem/neo_hookean.h"
#include "sim/solver/solver.h"
#include "sim/mesh/tet_mesh.h"

namespace softtled {

// state may be null: the rest mesh alone. dt converts the increment du to a velocity.
// mats: the material of every body (m.tet_body), or one for all. Written atomically
// (PATH.tmp, then renamed); write errors are ResourceErrors.
void write_vtu(const std::string& path, const TetMesh& m, const HostState* state, double dt,
               const std::vector<NeoHookean<double>>& mats);

// Collects frames and keeps DIR/series.pvd up to date after each one. A one-body mesh gives
// DIR/frame_NNNNN.vtu per frame; a mesh of several bodies one file per body,
// DIR/frame_NNNNN_bK.vtu (that body's nodes and elements alone, renumbered from 0), listed
// in the .pvd with part="K" and the frame's time step. Every file is
// written to NAME.tmp and renamed when complete (output_file.h), so after any stop the
// directory holds whole frames and a .pvd that lists exactly those; write errors are
// ResourceErrors naming the file. A directory that holds an earlier series: the frames its
// series.pvd lists (names of the frame_NNNNN[_bK].vtu form only) are removed once the new
// series' first frame and index are written, so a shorter run leaves no stale frames and a
// run that fails before its first frame leaves the earlier series whole.
class VtuSeries {
 public:
  explicit VtuSeries(std::string dir);
  // mats: the material of every body (Simulation::materials), or one for all.
  void add(double t, const TetMesh& m, const HostState& s, double dt, const std::vector<NeoHookean<double>>& mats);
  std::size_t size() const { return frames_.size(); }
  const std::string& dir() const { return dir_; }

 private:
  std::string dir_;
  struct Frame {
    double t;
    std::vector<std::string> files;  // one, or one per body in body order
  };
  std::vector<Frame> frames_;
  std::string entries_;                 // the index's DataSet lines of frames_
  std::vector<std::size_t> entry_ends_;  // entries_'s length before each frame's lines
  std::vector<std::string> earlier_;  // the frames an earlier series.pvd in dir_ listed
};

}  // namespace softtled
