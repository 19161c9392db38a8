#pragma once
// `softtled plot`: a run's CSV (`softtled run --csv`) as a figure. Two panels: the
// centroid height cy against time (the paper's Fig. 4 style: the drop, the bounces, the
// rest height) and the energies ke, se and pe - pe(0) with their sum (pe relative to the
// first row, so all share one axis and the sum shows what damping and contact took).
#include <cstdint>
#include <string>
#include <vector>

#include "render/plot.h"

namespace softtled {

struct CsvTable {
  std::vector<std::string> names;          // header
  std::vector<std::vector<double>> cols;   // one vector per column, one value per row
  // Per column, the message for its first cell that is not a number (below), "" if none:
  // raised only where the column is used, so `run`'s min_gap of "inf" (no contact pair)
  // does not stop a plot of the other columns.
  std::vector<std::string> bad;
  // The column's values; nullptr when absent; InputError naming its first bad cell.
  const std::vector<double>* column(const std::string& name) const;
};

// Largest CSV `softtled plot` reads.
constexpr std::uint64_t kMaxPlotCsvBytes = 256ull << 20;
// Largest magnitude of a value (beyond it axis ranges and unit scaling overflow).
constexpr double kMaxPlotValue = 1e30;

// A numeric CSV with a header row, read with read_input_file (a regular file of at most
// max_bytes: a directory, device or FIFO is refused, never read). Numbers are decimal
// (-1.5, 2e-3; no hex, inf, nan), finite and at most kMaxPlotValue in magnitude; a UTF-8
// byte order mark before the header is skipped; a NUL byte is refused. InputError naming
// the file, line and column otherwise (for a bad number: when its column is read).
CsvTable read_csv_table(const std::string& path, std::uint64_t max_bytes = kMaxPlotCsvBytes);
// The same on text in memory; `name` stands for the file in messages.
CsvTable parse_csv_table(const std::string& text, const std::string& name);

// "WxH" with both sides decimal integers in [lo, hi]; false otherwise (no wrap-around).
bool parse_wxh_size(const std::string& s, int lo, int hi, int& w, int& h);

// The figure's panels from a run's table; InputError naming a missing column (t, cy, ke,
// se, pe) or a table without rows. Units: t [s], cy [mm], energies [uJ].
std::vector<PlotPanel> run_plot_panels(const CsvTable& table, const std::string& title = "");

}  // namespace softtled
