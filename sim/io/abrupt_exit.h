#pragma once
// What must not outlive the program when it ends at once (a second Ctrl-C, or a signal
// such as SIGPIPE or SIGQUIT, re-raises the signal with its default action): temporaries being written (an atomic output's
// PATH.tmp, a video's PATH.tmp, ffmpeg's log) and child process groups (ffmpeg, which runs
// in its own group so that the first Ctrl-C reaches softtled only). The table is fixed
// size and lock-free, so a signal handler can walk it (remove_on_abrupt_exit only calls
// unlink and kill, both async-signal-safe). A full table is not an error: the entry is
// then simply not cleaned up.
#include <sys/types.h>

#include <string>

namespace softtled {

// Slot handles; -1: not tracked (table full or path too long).
int track_abrupt_exit_file(const std::string& path);
void untrack_abrupt_exit_file(int slot);
int track_abrupt_exit_group(pid_t pgid);
void untrack_abrupt_exit_group(int slot);
// From a signal handler: SIGKILL to each tracked process group, then unlink each file (in
// the process that tracked them only: nothing in a forked child).
void remove_on_abrupt_exit();

}  // namespace softtled
