#pragma once
// Output files that are either complete or absent, and checks of output paths made before
// any work starts (a run that fails on its last output must not have truncated the first).
//
// Every write, flush and close is checked: a full disk or an I/O error is a ResourceError
// naming the file and the OS reason ("out.csv: write failed: No space left on device").
#include <cstdio>
#include <stdexcept>
#include <string>

namespace softtled {

// A problem of the machine, not of the input: out of memory, disk full, write errors, no
// display or EGL device. The CLI exits with its own code for these (README, "Exit codes").
struct ResourceError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

class OutputFile {
 public:
  // kDirect writes PATH in place ("-" is standard output). kAtomic writes PATH.tmp and
  // renames it onto PATH in close(), so PATH never holds a partial file (an existing
  // device or FIFO is written in place).
  enum Mode { kDirect, kAtomic };
  OutputFile(std::string path, Mode mode = kDirect);
  ~OutputFile();  // without close(): a kAtomic temporary is removed
  OutputFile(const OutputFile&) = delete;
  OutputFile& operator=(const OutputFile&) = delete;

  void write(const std::string& s) { write(s.data(), s.size()); }
  void write(const char* data, std::size_t n);
  void flush();  // to the OS; checked
  void close();  // flush, close (checked), then the rename for kAtomic
  bool is_stdout() const { return f_ == stdout; }
  const std::string& path() const { return path_; }

 private:
  [[noreturn]] void fail(const char* what);
  std::string path_, tmp_;
  std::FILE* f_ = nullptr;
};

// Writes a whole file atomically (OutputFile kAtomic).
void write_file_atomic(const std::string& path, const std::string& content);

// InputError (naming `what`, e.g. "--csv", the path and the OS reason) unless a file can be
// created or overwritten at path: not a directory, its directory exists and is writable,
// an existing file is writable. "-" (standard output) passes when allow_stdout.
void check_output_file(const std::string& path, const std::string& what, bool allow_stdout = false);
// InputError unless path is a writable directory or can be created as one (its nearest
// existing ancestor is a writable directory).
void check_output_dir(const std::string& path, const std::string& what);

}  // namespace softtled
