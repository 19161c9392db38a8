#pragma once
// `softtled plot`: a run's CSV (`softtled run --csv`) as a figure. Two panels: the
// centroid height cy against time (the paper's Fig. 4 style: the drop, the bounces, the
// rest height) and the energies ke, se and pe - pe(0) with their sum (pe relative to the
// first row, so all share one axis and the sum shows what damping and contact took).
#include <string>
#include <vector>

#include "render/plot.h"

namespace softtled {

struct CsvTable {
  std::vector<std::string> names;          // header
  std::vector<std::vector<double>> cols;   // one vector per column, one value per row
  const std::vector<double>* column(const std::string& name) const;  // nullptr when absent
};

// A numeric CSV with a header row; InputError naming the file, line and column otherwise.
CsvTable read_csv_table(const std::string& path);

// The figure's panels from a run's table; InputError naming a missing column (t, cy, ke,
// se, pe) or a table without rows. Units: t [s], cy [mm], energies [uJ].
std::vector<PlotPanel> run_plot_panels(const CsvTable& table, const std::string& title = "");

}  // namespace softtled
