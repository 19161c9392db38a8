#pragma once
// Sub-commands of the softtled executable; each registers its options on the CLI11 app
// and returns the function main() runs when it is chosen.
#include <functional>
#include <string>

namespace CLI {
class App;
}

namespace softtled {
using Command = std::function<int()>;
Command add_mesh_command(CLI::App& app);
Command add_run_command(CLI::App& app);
Command add_accuracy_command(CLI::App& app);  // cmd_accuracy.cpp
Command add_bench_command(CLI::App& app);  // cmd_bench.cpp
Command add_render_command(CLI::App& app);  // cmd_render.cpp (needs render/)
Command add_view_command(CLI::App& app);    // cmd_view.cpp (needs render/)
Command add_plot_command(CLI::App& app);    // cmd_plot.cpp (render/'s CPU plot and PNG code)
// The scene `view` and `accuracy` take without --scene (cmd_accuracy.cpp).
std::string default_scene();
}  // namespace softtled
