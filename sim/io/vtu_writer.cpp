#include "sim/io/vtu_writer.h"

#include <sstream>

#include "sim/io/body_split.h"
#include "sim/io/output_file.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <regex>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "sim/fem/mesh_kinematics.h"
#include "sim/fem/von_mises.h"
#include "sim/mesh/surface_mesh.h"

namespace softtled {
void write_vtu(const std::string& path, const TetMesh& m, const HostState* s, double dt,
               const std::vector<NeoHookean<double>>& mats) {
  std::ostringstream o;
  const int n = m.nnode(), ne = m.ntet();
  o.precision(9);
  o << "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
    << "<UnstructuredGrid>\n<Piece NumberOfPoints=\"" << n << "\" NumberOfCells=\"" << ne << "\">\n";
  o << "<Points>\n<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n";
  // Positions with every digit of a double (17): a mesh written by mesh --vtu reads back
  // bit for bit (9 digits moved the nodes of a body 20 m out by 5e-12 m, its step and run
  // with them). The data arrays below keep 9.
  o.precision(17);
  for (int i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) o << m.X[3 * i + k] + (s ? s->u[k * n + i] : 0.0) << (k == 2 ? '\n' : ' ');
  o.precision(9);
  o << "</DataArray>\n</Points>\n<Cells>\n<DataArray type=\"Int32\" Name=\"connectivity\" format=\"ascii\">\n";
  for (int e = 0; e < ne; ++e)
    o << m.tet[4 * e] << ' ' << m.tet[4 * e + 1] << ' ' << m.tet[4 * e + 2] << ' ' << m.tet[4 * e + 3] << '\n';
  o << "</DataArray>\n<DataArray type=\"Int32\" Name=\"offsets\" format=\"ascii\">\n";
  for (int e = 0; e < ne; ++e) o << 4 * (e + 1) << '\n';
  o << "</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n";
  for (int e = 0; e < ne; ++e) o << "10\n";  // VTK_TETRA
  o << "</DataArray>\n</Cells>\n";
  if (s) {
    o << "<PointData Vectors=\"displacement\">\n<DataArray type=\"Float64\" Name=\"displacement\" NumberOfComponents=\"3\" format=\"ascii\">\n";
    for (int i = 0; i < n; ++i)
      for (int k = 0; k < 3; ++k) o << s->u[k * n + i] << (k == 2 ? '\n' : ' ');
    o << "</DataArray>\n<DataArray type=\"Float64\" Name=\"velocity\" NumberOfComponents=\"3\" format=\"ascii\">\n";
    for (int i = 0; i < n; ++i)
      for (int k = 0; k < 3; ++k) o << s->du[k * n + i] / dt << (k == 2 ? '\n' : ' ');
    o << "</DataArray>\n<DataArray type=\"UInt8\" Name=\"contact\" format=\"ascii\">\n";
    for (int i = 0; i < n; ++i) o << int(s->contact[i]) << '\n';
    o << "</DataArray>\n</PointData>\n";
  }
  o << "<CellData Scalars=\"von_mises\">\n<DataArray type=\"Float64\" Name=\"J\" format=\"ascii\">\n";
  std::vector<double> vm(ne);
  for (int e = 0; e < ne; ++e) {
    const Mat3<double> F = mesh_element_F(m, s ? &s->u : nullptr, e);
    const double J = volume_ratio(F);
    o << J << '\n';
    // Cauchy von Mises (von_mises.h, also the render map's) with the element's body's law.
    // A body with its own E ([body.material]): the stress scales with E at a fixed nu.
    const NeoHookean<double>& mat = mats.at(mats.size() == 1 ? 0 : std::size_t(m.tet_body.at(e)));
    vm[e] = von_mises_stress(mat, F) * (m.E_scale.empty() ? 1.0 : m.E_scale[e]);
  }
  o << "</DataArray>\n<DataArray type=\"Float64\" Name=\"von_mises\" format=\"ascii\">\n";
  for (double v : vm) o << v << '\n';
  if (!m.tet_body.empty()) {  // several bodies in one file (mesh --vtu): which is whose
    o << "</DataArray>\n<DataArray type=\"Int32\" Name=\"body\" format=\"ascii\">\n";
    for (int b : m.tet_body) o << b << '\n';
  }
  o << "</DataArray>\n</CellData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n";
  write_file_atomic(path, o.str());  // PATH.tmp, renamed when complete
}

VtuSeries::VtuSeries(std::string dir) : dir_(std::move(dir)) {
  std::error_code ec;
  std::filesystem::create_directories(dir_, ec);
  if (ec) throw InputError(dir_ + ": cannot create directory (" + ec.message() + ")");
  // The earlier index's frames, by the names this class writes: never a path (a hand-edited
  // index naming ../x.vtu) or another file.
  std::ifstream in(dir_ + "/series.pvd");
  const std::regex entry("file=\"(frame_[0-9]{5}(_b[0-9]+)?\\.vtu)\"");
  for (std::string line; std::getline(in, line);)
    for (std::sregex_iterator it(line.begin(), line.end(), entry), end; it != end; ++it) earlier_.push_back((*it)[1]);
  // A first frame staged beside an earlier one (add) by a run killed before it was renamed.
  const std::regex staged("frame_[0-9]{5}(_b[0-9]+)?\\.vtu\\.new");
  for (const auto& e : std::filesystem::directory_iterator(dir_, ec))
    if (std::regex_match(e.path().filename().string(), staged)) std::filesystem::remove(e.path(), ec);
}

void VtuSeries::add(double t, const TetMesh& m, const HostState& s, double dt,
                    const std::vector<NeoHookean<double>>& mats) {
  char name[64];
  Frame frame{t, {}};
  std::vector<std::string> names;
  for (int b = 0; b < m.nbody(); ++b) {  // one file per body
    if (m.nbody() == 1)
      std::snprintf(name, sizeof name, "frame_%05zu.vtu", frames_.size());
    else
      std::snprintf(name, sizeof name, "frame_%05zu_b%d.vtu", frames_.size(), b);
    names.push_back(name);
  }
  // A file of the first frame that bears the name of one of an earlier series' frames is
  // written beside it (".new") and renamed only once the new index is on disk, so that a
  // failure before then leaves the earlier series whole, its index naming only files that
  // exist. Such a name must be a regular file to be renamed onto: checked first.
  auto is_earlier = [&](const std::string& f) { return std::find(earlier_.begin(), earlier_.end(), f) != earlier_.end(); };
  for (const std::string& f : names) {
    std::error_code ec;
    const auto st = std::filesystem::symlink_status(dir_ + "/" + f, ec);
    if (is_earlier(f) && std::filesystem::exists(st) && !std::filesystem::is_regular_file(st))
      throw ResourceError(dir_ + "/" + f + ": an earlier series names it, but it is not a regular file; remove it");
  }
  auto staged = [&](const std::string& f) { return dir_ + "/" + f + (is_earlier(f) ? ".new" : ""); };
  std::vector<std::string> written;  // paths on disk, for the clean-up of a failed frame
  auto remove_written = [&] {
    for (const auto& f : written) std::remove(f.c_str());
  };
  try {
    for (int b = 0; b < m.nbody(); ++b) {
      const std::string path = staged(names[b]);
      if (m.nbody() == 1) {
        write_vtu(path, m, &s, dt, mats);
      } else {
        const HostState part = body_state(m, s, b);
        write_vtu(path, body_mesh(m, b), &part, dt, {mats.at(mats.size() == 1 ? 0 : std::size_t(b))});
      }
      written.push_back(path);
      frame.files.push_back(names[b]);
    }
  } catch (...) {
    remove_written();  // the directory keeps whole frames only
    throw;
  }
  // The index's entries are kept as text, one frame's appended at a time: formatting them
  // all again for every frame made a run of 10,000 frames take 67 s.
  {
    std::ostringstream o;
    o.precision(17);
    for (std::size_t p = 0; p < frame.files.size(); ++p) {
      o << "<DataSet timestep=\"" << frame.t << "\" ";
      if (frame.files.size() > 1) o << "part=\"" << p << "\" ";  // ParaView: the bodies of one time step
      o << "file=\"" << frame.files[p] << "\"/>\n";
    }
    entry_ends_.push_back(entries_.size());
    entries_ += o.str();
  }
  frames_.push_back(std::move(frame));
  auto index = [&] {  // of the frames kept
    return "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n<Collection>\n" + entries_ +
           "</Collection>\n</VTKFile>\n";
  };
  auto drop_last = [&] {
    frames_.pop_back();
    entries_.resize(entry_ends_.back());
    entry_ends_.pop_back();
  };
  try {
    write_file_atomic(dir_ + "/series.pvd", index());  // always a complete index of complete frames
  } catch (...) {
    // The index kept is the last one: the frame it does not list goes, so that the
    // directory holds exactly the frames series.pvd names.
    remove_written();
    drop_last();
    throw;
  }
  for (const std::string& f : frames_.back().files) {
    if (!is_earlier(f) || std::rename(staged(f).c_str(), (dir_ + "/" + f).c_str()) == 0) continue;
    // Not expected after the check above (same directory, a regular file): the frame goes
    // and the index is written again without it; the earlier frames stay, unlisted.
    const std::string why = std::strerror(errno);
    remove_written();
    drop_last();
    write_file_atomic(dir_ + "/series.pvd", index());
    throw ResourceError(dir_ + "/" + f + ": cannot rename the written frame into place: " + why);
  }
  // The new index is on disk: the earlier series' frames that this one has not rewritten go.
  for (const std::string& f : earlier_)
    if (std::find(frames_.back().files.begin(), frames_.back().files.end(), f) == frames_.back().files.end())
      std::remove((dir_ + "/" + f).c_str());
  earlier_.clear();
}

}  // namespace softtled
