#pragma once
// Reading back what write_vtu / VtuSeries wrote: the numbers of one ASCII DataArray, and a
// file's text. Enough for write_vtu's own layout, not a general VTK reader.
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace softtled::test {

inline std::string read_text(const std::string& path) {
  std::ifstream f(path);
  std::stringstream buf;
  buf << f.rdbuf();
  return buf.str();
}

// The numbers of the first DataArray whose opening tag contains `marker`; empty if none.
inline std::vector<double> vtu_numbers(const std::string& xml, const std::string& marker) {
  const auto at = xml.find(marker);
  if (at == std::string::npos) return {};
  const auto start = xml.find('>', at + marker.size()) + 1, end = xml.find("</DataArray>", start);
  std::istringstream in(xml.substr(start, end - start));
  std::vector<double> v;
  double x;
  while (in >> x) v.push_back(x);
  return v;
}
inline std::vector<double> data_array(const std::string& xml, const std::string& name) {
  return vtu_numbers(xml, "Name=\"" + name + "\"");
}
// Point coordinates, x y z per point (the one DataArray inside <Points>, which has no Name).
inline std::vector<double> vtu_points(const std::string& xml) { return vtu_numbers(xml, "<Points>\n<DataArray"); }

}  // namespace softtled::test
