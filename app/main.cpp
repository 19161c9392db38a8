// softtled: command-line entry. Sub-commands live in cmd_*.cpp; every user-facing input
// problem arrives here as an InputError and becomes a one-line message and exit code 2.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>
#include <map>
#include <string>

#include "app/commands.h"
#include "sim/mesh/surface_mesh.h"

int main(int argc, char** argv) {
  CLI::App app{"SoftTLED: real-time soft-body simulation (TLED, Neo-Hookean, plane contact)"};
  app.require_subcommand(1);
  std::map<std::string, softtled::Command> commands;
  commands["mesh"] = softtled::add_mesh_command(app);
  commands["run"] = softtled::add_run_command(app);
  commands["accuracy"] = softtled::add_accuracy_command(app);
  commands["bench"] = softtled::add_bench_command(app);
#ifdef SOFTTLED_HAVE_RENDER
  commands["render"] = softtled::add_render_command(app);
  commands["view"] = softtled::add_view_command(app);
#endif
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  try {
    for (auto* sub : app.get_subcommands()) return commands.at(sub->get_name())();
  } catch (const softtled::InputError& e) {
    std::fprintf(stderr, "softtled: error: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "softtled: internal error: %s\n", e.what());
    return 3;
  }
  return 1;
}
