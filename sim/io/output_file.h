#pragma once
// Output files that are either complete or absent, and checks of output paths made before
// any work starts (a run that fails on its last output must not have truncated the first).
//
// Every write, flush and close is checked: a full disk or an I/O error is a ResourceError
// naming the file and the OS reason ("out.csv: write failed: No space left on device").
// A kDirect regular file that fails is cut back to its size at the last successful
// flush(): a writer that flushes after each record (run --csv) never leaves a partial one.
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace softtled {

// A problem of the machine, not of the input: out of memory, disk full, write errors, no
// display or EGL device. The CLI exits with its own code for these (README, "Exit codes").
struct ResourceError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// A wait on an output's reader ended by the process-wide stop request
// (sim/core/stop_request.h): a FIFO's reader not opening it, or a pipe's or FIFO's reader
// not reading (the write blocked until the stop signal interrupted it). The command was
// stopped, not short of a resource.
struct StoppedWhileWaiting : ResourceError {
  using ResourceError::ResourceError;
};

// How long an output FIFO waits for its reader to open it [s] (OutputFile). The stop
// request is polled while that wait lasts: true ends it at once with StoppedWhileWaiting,
// which the CLI reports as the signal's stop.
constexpr int kFifoReaderWaitS = 5;

class OutputFile {
 public:
  // kDirect writes PATH in place ("-" is standard output). kAtomic writes PATH.tmp and
  // renames it onto PATH in close(), so PATH never holds a partial file (an existing
  // device or FIFO is written in place). The replaced file's permissions carry over, and a
  // symlink at PATH stays one (its target is replaced). A PATH.tmp that is not a regular
  // file (a directory, FIFO or symlink) is never written through: ResourceError.
  //
  // Written with write(2), not stdio: a write blocked on a reader that does not read (a
  // pipe, a FIFO) returns EINTR when a stop signal arrives (install_stop_signals sets no
  // SA_RESTART), and is then given up with StoppedWhileWaiting where a stop was requested
  // (stdio's fwrite drops its buffer on EINTR, so it could not be retried otherwise).
  enum Mode { kDirect, kAtomic };
  OutputFile(std::string path, Mode mode = kDirect);
  ~OutputFile();  // without close(): what was not flush()ed is dropped, a kAtomic temporary removed
  OutputFile(const OutputFile&) = delete;
  OutputFile& operator=(const OutputFile&) = delete;

  void write(const std::string& s) { write(s.data(), s.size()); }
  void write(const char* data, std::size_t n);
  void flush();  // to the OS; checked
  void close();  // finish(), then commit()
  void finish();  // flush and close (checked); a kAtomic temporary is complete but not renamed yet
  void commit();  // kAtomic: renames the temporary onto PATH (a symlink's target: the link stays)
  bool is_stdout() const { return stdout_; }
  const std::string& path() const { return path_; }

 private:
  [[noreturn]] void fail(const char* what, bool stopped = false);
  void write_all(const char* data, std::size_t n);  // to fd_, every byte
  void open_temporary(int mode);  // kAtomic: target_ and tmp_ set, fd_ open on tmp_; mode < 0: a new file
  void drop_temporary(bool remove);  // forget tmp_ (renamed, or removed when remove)
  int abrupt_slot_ = -1;             // tmp_ in abrupt_exit.h's table
  std::string path_, tmp_, target_;
  std::string buf_;  // written, not yet handed to the OS
  int fd_ = -1;
  bool stdout_ = false;   // "-": fd_ is standard output's, never closed here
  bool regular_ = false;  // kDirect onto a regular file: cut back on failure
  long long written_ = 0, flushed_ = 0;  // bytes handed to write(), and at the last good flush
};

// The file an atomic write replaces: PATH, or the regular file a symlink at PATH names (the
// link stays a link); its temporary is that name + ".tmp".
std::string atomic_target(const std::string& path);

// Writes a whole file atomically (OutputFile kAtomic).
void write_file_atomic(const std::string& path, const std::string& content);
// Writes files that belong together (a TetGen .node/.ele pair): every PATH.tmp first, and
// only when all are complete renamed onto their paths, so a failure keeps the old set.
void write_files_atomic(const std::vector<std::pair<std::string, std::string>>& files);

// InputError when path holds a NUL byte (a Python string may): the OS would take the part
// before it, another file. what: the flag or call, or empty for an input path.
void check_no_nul(const std::string& path, const std::string& what);

// The CLI turns this on at start: before refusing because a standard stream goes to a file
// the command reads or writes, standard error is moved off that file where it holds
// something, so the refusal is not appended to it (output_file.cpp, keep_stderr_out_of).
// Off, as in the Python module and the tests, standard error is left where it is.
void guard_stderr_of_files(bool on);
// Refuses (InputError) an input the command reads that standard output or standard error
// already goes to (2>> scene.toml), before anything is read or printed: a warning of the
// scene reader would be appended to the scene itself.
void check_streams_not_into(const std::string& path, const std::string& what);

// InputError (naming `what`, e.g. "--csv", the path and the OS reason) unless a file can be
// created or overwritten at path: not a directory, its directory exists and is writable,
// an existing file is writable. "-" (standard output) passes when allow_stdout. An
// existing regular file also needs a writable directory (write_file_atomic writes PATH.tmp
// there) unless in_place (OutputFile kDirect); then PATH.tmp must fit the directory's name
// length and PATH_MAX, and not be anything but a regular file.
// A PNG the command creates or replaces is named for what it holds: unless path is a
// device or FIFO (written in place, whatever its name), it must end in .png (any case).
// Throws InputError "WHAT PATH: ..." (plot's --out, the Python module's render_png, which
// wrote a PNG named x.jpg).
void check_png_name(const std::string& path, const std::string& what);

void check_output_file(const std::string& path, const std::string& what, bool allow_stdout = false,
                       bool in_place = false);

// A path a command reads or writes, for check_distinct_paths: `what` names it in messages
// ("--csv", "--scene", "body.file"); a directory output (run --vtu) owns the files it
// writes there (series.pvd, frame_*.vtu).
struct PathUse {
  std::string path, what;
  bool output = false;
  bool output_dir = false;
  bool in_place = false;  // an output written where it is (a CSV), not through PATH.tmp
};
// InputError naming both flags when an output, or the PATH.tmp it is written to first, is
// the same file as an input or as another output (same device and inode, or the same
// absolute path once symlinks are resolved, a dangling one's too, for a file not there
// yet), or when a file a directory output writes (series.pvd, frame_*.vtu) is one: by the
// other path's name or resolved path, and by device and inode for those names already in
// the directory. "-", empty paths and existing non-regular files (/dev/null, /dev/full,
// FIFOs) are not compared.
void check_distinct_paths(const std::vector<PathUse>& paths);
// InputError unless path is a writable directory or can be created as one (its nearest
// existing ancestor is a writable directory).
void check_output_dir(const std::string& path, const std::string& what);
// check_output_dir for a VTU series' directory (vtu_writer.h), and none of the names the
// series writes there (series.pvd, frame_*.vtu, their .tmp and .new) is taken by anything
// but a regular file: a directory named series.pvd failed the run after meshing (exit 5),
// and a symlink there had the series write through it (onto the scene it named). The
// longest of those paths must fit PATH_MAX.
void check_series_dir(const std::string& path, const std::string& what);

}  // namespace softtled
