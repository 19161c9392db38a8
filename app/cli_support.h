#pragma once
// What the sub-commands share: the exit codes, numeric validators for CLI11 options (the
// range shows in --help), SIGINT/SIGTERM/SIGHUP as a stop request, the backend choice and the
// bounds on a run's step count.
#include <CLI/CLI.hpp>
#include <chrono>
#include <memory>
#include <string>

#include <vector>

#include "sim/io/output_file.h"
#include "sim/scene/simulation.h"

namespace softtled {

// README, "Exit codes".
enum ExitCode {
  kExitOk = 0,
  kExitInput = 2,      // bad input or usage: the message names the file, key or flag
  kExitInternal = 3,   // a bug
  kExitDiverged = 4,   // the watchdog stopped a diverging run
  kExitResource = 5,   // the machine: out of memory, disk full or write error, no display / EGL
  kExitSighup = 129,   // stopped by SIGHUP (128 + 1), as for SIGTERM
  kExitSigint = 130,   // stopped by SIGINT (128 + 2) after writing what it had
  kExitSigterm = 143,  // stopped by SIGTERM (128 + 15)
};

// -v on the top-level command.
extern bool g_verbose;

// A finite number in [lo, hi] (NaN and infinities refused); shown in --help as "in [lo, hi]".
CLI::Validator finite_range(double lo, double hi);
// An integer option's range, shown in --help (CLI11 refuses values that overflow the type).
CLI::Validator int_range(long lo, long hi);


// SIGINT, SIGTERM and SIGHUP (a closed terminal) set a flag that long loops poll (stop_requested) to finish the current
// step, write what they have and return; a second signal ends the program at once.
void install_stop_signals();
int stop_signal();  // 0, SIGINT, SIGTERM or SIGHUP
inline bool stop_requested() { return stop_signal() != 0; }
int exit_code_for_signal(int sig);
// The signals whose default action ends the program at once, not a stop (SIGPIPE: standard
// output's reader gone; SIGQUIT, SIGALRM, SIGUSR1/2, SIGXCPU): the temporaries being written
// are removed and ffmpeg's process group killed first (abrupt_exit.h), then the program dies
// of the same signal (141 for SIGPIPE, as before). A signal ignored at start stays ignored.
void install_abrupt_exit_signals();

// A JSON string literal of s (RFC 8259): quote, backslash and control characters escaped,
// a byte that is not part of well-formed UTF-8 replaced by U+FFFD, so a scene path with a
// newline or a Latin-1 byte still gives valid JSON.
std::string json_string(const std::string& s);

// Flushes standard output and remembers the reason of its first failed write,
// which a later fflush no longer reports: progress printed by long
// commands is flushed here, not line-buffered, so "No space left on device" survives to
// the exit message.
void flush_stdout();
int stdout_errno();  // 0 while every write succeeded or its reason is unknown

// "auto" becomes "cuda" when a CUDA device is usable (every stage runs on both backends),
// else "cpu"; the reason is printed only with -v. Asking for "cuda" where there is none is
// an InputError at once (check_backend_available), before any meshing or output.
std::string resolve_backend(const std::string& requested);

// The Simulation of a scene on a backend (resolve_backend). InputErrors from meshing that
// do not name the scene file yet ("mesh too large ...", "TetGen ... crashed") get it.
std::unique_ptr<Simulation> make_simulation(const Scene& s, const std::string& backend);

// Steps to cover `duration` at `dt` (rounded), refused with a message naming the keys when
// it overflows, exceeds kMaxRunSteps, or is 0 for a positive duration. A frame time
// (frame_time: render's --at) may round to step 0: that frame is the start, as --at 0 is
// (1e-6 s at a 11 us step was refused as a run too short to take a step).
constexpr double kMaxRunSteps = 1e11;  // 1e11 steps: more than a day at 1 us/step
long checked_step_count(double duration, double dt, const std::string& what, bool frame_time = false);

// The decimals the CSV and messages print times with: enough that consecutive output
// times dt apart differ (3 significant digits of dt), at least 6.
int time_decimals(double dt);

// The long-run warning of run and render, once: after 2 s of stepping, where what is left up
// to t_end would take more than 5 minutes of wall time at the rate so far (render's frames
// far ahead ran for hours with no word, where run warned). check() is called with the
// simulated time now, from the stop checks and between outputs.
class LongRunWarning {
 public:
  LongRunWarning(const char* what, double t_end);
  void check(double t_now);

 private:
  const char* what_;
  double t_end_;  // from t = 0
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
  bool warned_ = false, tty_;
};

}  // namespace softtled
