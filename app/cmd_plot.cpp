// `softtled plot`: a run's CSV drawn into a PNG (plot_csv.h), on the CPU with render/'s
// plot rasteriser: no GL context, no Python.
#include <CLI/CLI.hpp>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>

#include "app/cli_support.h"
#include "app/commands.h"
#include "app/plot_csv.h"
#include "render/image.h"
#include "sim/io/output_file.h"

namespace softtled {

Command add_plot_command(CLI::App& app) {
  struct Opts {
    std::string csv, out = "plot.png", size = "900x700", title;
  };
  auto o = std::make_shared<Opts>();
  CLI::App* c = app.add_subcommand("plot", "draw a run's CSV (centroid height, energies) into a PNG");
  c->add_option("csv", o->csv, "CSV written by softtled run --csv")->required();
  c->add_option("--out", o->out, "PNG to write")->capture_default_str();
  c->add_option("--size", o->size, "image size WxH")->capture_default_str();
  c->add_option("--title", o->title, "prefix of the first panel's title (default: the CSV's file name)");
  return [o]() {
    int w = 0, h = 0;
    if (!parse_wxh_size(o->size, 200, 8192, w, h))
      throw InputError("--size '" + o->size + "': expected WxH between 200 and 8192, e.g. 900x700");
    check_output_file(o->out, "--out");
    check_streams_not_into(o->csv, "csv");
    check_distinct_paths({{o->csv, "csv"}, {o->out, "--out", true}});
    check_png_name(o->out, "--out");
    const CsvTable table = read_csv_table(o->csv);
    std::vector<PlotPanel> panels;
    try {
      panels = run_plot_panels(table, o->title.empty() ? std::filesystem::path(o->csv).filename().string() : o->title);
    } catch (const InputError& e) {  // named with the file, where the message does not already say it
      const std::string what = e.what();
      throw InputError(what.rfind(o->csv + ":", 0) == 0 ? what : o->csv + ": " + what);
    }
    const Image im = plot_panels(panels, w, h);
    // OUT.tmp renamed onto OUT when complete; a device or FIFO written in place; every
    // write checked (ResourceError naming OUT and the OS reason: exit 5).
    write_file_atomic(o->out, encode_png(im));
    std::printf("%s: %zu rows -> %s (%dx%d)\n", o->csv.c_str(), table.cols[0].size(), o->out.c_str(), w, h);
    return 0;
  };
}

}  // namespace softtled
