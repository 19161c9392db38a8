#include "app/plot_csv.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>

#include "sim/core/input_error.h"

namespace softtled {

const std::vector<double>* CsvTable::column(const std::string& name) const {
  for (std::size_t i = 0; i < names.size(); ++i)
    if (names[i] == name) return &cols[i];
  return nullptr;
}

CsvTable read_csv_table(const std::string& path) {
  std::ifstream f(path);
  if (!f) throw InputError(path + ": cannot read: " + std::strerror(errno));
  CsvTable t;
  std::string line;
  long lineno = 0;
  while (std::getline(f, line)) {
    ++lineno;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty() || line[0] == '#') continue;
    std::vector<std::string> cells;
    std::stringstream in(line);
    std::string cell;
    while (std::getline(in, cell, ',')) cells.push_back(cell);
    if (!line.empty() && line.back() == ',') cells.push_back("");
    if (t.names.empty()) {
      t.names = cells;
      t.cols.resize(cells.size());
      continue;
    }
    if (cells.size() != t.names.size())
      throw InputError(path + ":" + std::to_string(lineno) + ": " + std::to_string(cells.size()) + " values, the header has " +
                       std::to_string(t.names.size()));
    for (std::size_t c = 0; c < cells.size(); ++c) {
      const char* s = cells[c].c_str();
      char* end = nullptr;
      const double v = std::strtod(s, &end);
      if (end == s || *end != '\0')
        throw InputError(path + ":" + std::to_string(lineno) + ": column " + t.names[c] + ": '" + cells[c] + "' is not a number");
      t.cols[c].push_back(v);
    }
  }
  if (t.names.empty()) throw InputError(path + ": empty file (expected a header row: softtled run --csv)");
  return t;
}

std::vector<PlotPanel> run_plot_panels(const CsvTable& table, const std::string& title) {
  auto need = [&](const char* name) -> const std::vector<double>& {
    const std::vector<double>* c = table.column(name);
    if (!c) throw InputError(std::string("the CSV has no column '") + name + "' (expected softtled run --csv output)");
    return *c;
  };
  const std::vector<double>&t = need("t"), &cy = need("cy"), &ke = need("ke"), &se = need("se"), &pe = need("pe");
  if (t.empty()) throw InputError("the CSV has a header but no rows");
  std::vector<double> h(cy.size()), k(t.size()), s(t.size()), p(t.size()), sum(t.size());
  for (std::size_t i = 0; i < t.size(); ++i) {
    h[i] = cy[i] * 1e3;
    k[i] = ke[i] * 1e6, s[i] = se[i] * 1e6, p[i] = (pe[i] - pe[0]) * 1e6;
    sum[i] = k[i] + s[i] + p[i];
  }
  PlotPanel a;
  a.title = (title.empty() ? "" : title + ": ") + "centroid height cy [mm]";
  a.xlabel = "t [s]";
  a.series.push_back({"cy", t, h, Vec3{0.12f, 0.35f, 0.75f}});
  PlotPanel b;
  b.title = "energy [uJ]";
  b.xlabel = "t [s]";
  b.series.push_back({"kinetic ke", t, k, Vec3{0.85f, 0.25f, 0.20f}});
  b.series.push_back({"strain se", t, s, Vec3{0.15f, 0.60f, 0.25f}});
  b.series.push_back({"gravity pe - pe(0)", t, p, Vec3{0.20f, 0.40f, 0.85f}});
  b.series.push_back({"sum", t, sum, Vec3{0.25f, 0.25f, 0.28f}});
  return {a, b};
}

}  // namespace softtled
