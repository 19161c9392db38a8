#pragma once
// A process-wide stop request, for the work no Simulation stop check reaches: TetGen in its
// child process, an output FIFO's wait for its reader, the stable step's eigenvalue
// iteration at the start of a run. Process-wide, as the signal it stands for: the mesher is
// called from scene loading, tet-file and obstacle checks, none of which should carry a
// stop flag through. The CLI sets it (install_stop_signals: SIGINT, SIGTERM, SIGHUP), so one
// Ctrl-C is answered at once; unset (the default, and in Python), nothing is asked.
namespace softtled {

inline bool (*&stop_request_check_slot())() {
  static bool (*check)() = nullptr;
  return check;
}
inline void set_stop_request_check(bool (*check)()) { stop_request_check_slot() = check; }
inline bool stop_request_pending() {
  bool (*check)() = stop_request_check_slot();
  return check && check();
}

}  // namespace softtled
