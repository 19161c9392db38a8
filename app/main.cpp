// softtled: command-line entry. Sub-commands live in cmd_*.cpp. Every failure ends here as
// one "softtled: error: ..." line and an exit code (cli_support.h, README "Exit codes"):
// usage errors and InputErrors 2, resource problems 5, a stop by signal 130/143.
#include <CLI/CLI.hpp>
#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <csignal>
#include <filesystem>
#include <cstring>
#include <exception>
#include <map>
#include <new>
#include <string>

#include "app/cli_support.h"
#include "app/commands.h"
#include "sim/io/output_file.h"
#include "sim/mesh/surface_mesh.h"

#ifndef SOFTTLED_VERSION
#define SOFTTLED_VERSION "unknown"
#endif

int main(int argc, char** argv) {
  using namespace softtled;
  // One error line, at most ~2 KB: the messages quote the user's values (quoted() shortens
  // them where they are built), and this catches any that do not (a 3 MB key name). The
  // middle goes, not the end: the reason comes last ("PATH: ...: File name too long"), and
  // a path near PATH_MAX is longer than the whole budget.
  auto shortened = [](const std::string& m) {
    constexpr std::size_t kHead = 1000, kTail = 1000;
    if (m.size() <= kHead + kTail) return m;
    return m.substr(0, kHead) + " ... (" + std::to_string(m.size() - kHead - kTail) + " characters cut) ... " +
           m.substr(m.size() - kTail);
  };
  auto error = [&](const char* what) { std::fprintf(stderr, "softtled: error: %s\n", shortened(what).c_str()); };
  // Past a file-size limit (ulimit -f) a write fails with EFBIG, which the checked writers
  // report (exit 5, the CSV cut back to its last row) instead of SIGXFSZ killing the program
  // with half-written files.
  std::signal(SIGXFSZ, SIG_IGN);
  install_abrupt_exit_signals();  // SIGPIPE, SIGQUIT, ...: no temporary or ffmpeg outlives the program
  guard_stderr_of_files(true);
  // A standard stream started closed (`>&-`, `2>&-`) would let the first file opened take
  // its descriptor, and the summary or the log would be written into that CSV. Each closed
  // one is held by /dev/null opened read-only: its writes fail (EBADF) and are reported
  // as a write error (exit 5), as on a full disk.
  for (int fd = 0; fd <= 2; ++fd)
    if (::fcntl(fd, F_GETFD) < 0 && errno == EBADF) {
      const int held = ::open("/dev/null", O_RDONLY);
      if (held >= 0 && held != fd) ::close(held);  // (descriptors are taken lowest first)
    }
  CLI::App app{"SoftTLED: real-time soft-body simulation (TLED, Neo-Hookean, plane contact)\n"
               "Exit codes: 0 success, 2 bad input or usage, 3 internal error, 4 the watchdog stopped a diverging run,\n"
               "5 resource (out of memory, disk full or write error, no display/EGL), 129/130/143 stopped by\n"
               "SIGHUP/SIGINT/SIGTERM, 141 standard output's reader gone (SIGPIPE)."};
  app.require_subcommand(1);
  app.failure_message([shortened](const CLI::App*, const CLI::Error& e) {
    // CLI11 quotes the argument it refuses: shortened as above
    return "softtled: error: " + shortened(e.what()) + "\nRun with --help for more information.\n";
  });
  app.set_version_flag("--version", "softtled " SOFTTLED_VERSION);
  app.add_flag("-v,--verbose", g_verbose, "print notices (e.g. why backend auto chose the CPU)");
  std::map<std::string, Command> commands;
  commands["mesh"] = add_mesh_command(app);
  commands["run"] = add_run_command(app);
  commands["accuracy"] = add_accuracy_command(app);
  commands["bench"] = add_bench_command(app);
#ifdef SOFTTLED_HAVE_RENDER
  commands["render"] = add_render_command(app);
  commands["view"] = add_view_command(app);
  commands["plot"] = add_plot_command(app);
#endif
  // CLI11 reports a misspelt command only as "A subcommand is required": name it.
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "-v" || a == "--verbose") continue;
    if (a.empty() || a[0] == '-') break;  // --help, --version, or CLI11's own usage error
    if (!commands.count(a)) {
      std::string known;
      for (const auto& c : commands) known += (known.empty() ? "" : ", ") + c.first;
      std::fprintf(stderr, "softtled: error: unknown command %s (commands: %s)\nRun with --help for more information.\n",
                   quoted(a).c_str(), known.c_str());
      return kExitInput;
    }
    break;
  }
  // What went to standard output (the summary and tables, --help, --version) is output
  // too: a full disk or a closed pipe must not pass silently.
  // earlier: the errno of a write that already failed (CLI11 flushes --version's line itself).
  auto stdout_failed = [](int earlier = 0) {
    flush_stdout();
    if (!std::ferror(stdout)) return false;
    // A write into a stalled pipe interrupted by the stop signal (no SA_RESTART): the stop
    // is the outcome, with its exit code, not a write error.
    if (stop_requested() && (stdout_errno() ? stdout_errno() : earlier) == EINTR) return false;
    const int e = stdout_errno() ? stdout_errno() : earlier;
    std::fprintf(stderr, "softtled: error: standard output: write failed%s%s\n", e ? ": " : "", e ? std::strerror(e) : "");
    return true;
  };
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help and --version exit 0 (5 when their text could not be written); every usage
    // error (CLI11's 101..) is bad input.
    errno = 0;
    const int rc = app.exit(e);
    if (rc == 0 && stdout_failed(errno)) return kExitResource;
    return rc == 0 ? kExitOk : kExitInput;
  }
  auto stopped = [](const char* what) {
    const int sig = stop_signal();
    std::fprintf(stderr, "softtled: stopped by signal %d (%s)\n", sig, what);
    return exit_code_for_signal(sig);
  };
  try {
    for (auto* sub : app.get_subcommands()) {
      const int rc = commands.at(sub->get_name())();
      if (stdout_failed()) return kExitResource;
      // The log (mesh size, dt, warnings) is part of what a run reports: a success whose
      // log could not be written is not one. Nothing can be said about it on stderr itself.
      if (rc == kExitOk && std::ferror(stderr)) return kExitResource;
      return rc;
    }
  } catch (const InputError& e) {
    if (stop_requested()) return stopped(e.what());  // e.g. TetGen's child ended by the same Ctrl-C
    error(e.what());
    return kExitInput;
  } catch (const StoppedWhileWaiting& e) {  // a FIFO's wait for its reader, ended by Ctrl-C
    return stopped(e.what());
  } catch (const ResourceError& e) {
    error(e.what());
    return kExitResource;
  } catch (const std::filesystem::filesystem_error& e) {  // a path the OS refused (checks catch most before)
    error(e.what());
    return kExitResource;
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "softtled: error: out of memory (std::bad_alloc); use a coarser mesh or a smaller mesh.max_tets\n");
    return kExitResource;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "softtled: internal error: %s\n", e.what());
    return kExitInternal;
  }
  return 1;
}
