#pragma once
// The tet readers' shared cursor over a file held in memory (tet_io_*.cpp only): text
// tokens with line numbers for messages, strict numbers (trailing garbage is an error),
// integers in a range, and bounds-checked little-endian binary reads (Gmsh binary).
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>

#include "sim/core/input_error.h"

namespace softtled::tet_io {

class Cursor {
 public:
  // [begin, end) of data; comment: a character that starts a comment to the end of the line
  // ('\0': none).
  Cursor(const std::string& data, const std::string& name, std::size_t begin = 0, std::size_t end = std::string::npos,
         char comment = '\0')
      : d_(data), name_(name), pos_(begin), end_(end == std::string::npos ? data.size() : end), comment_(comment) {}

  // "NAME:LINE" (the line of the last token read, or of the cursor).
  std::string at() const { return name_ + ":" + std::to_string(line_); }
  [[noreturn]] void fail(const std::string& what) const { throw InputError(at() + ": " + what); }

  // Skips white space and comments; false at the end.
  bool more() {
    while (pos_ < end_) {
      const char c = d_[pos_];
      if (c == '\n') {
        ++line_;
        ++pos_;
      } else if (c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v') {
        ++pos_;
      } else if (comment_ && c == comment_) {
        while (pos_ < end_ && d_[pos_] != '\n') ++pos_;
      } else {
        return true;
      }
    }
    return false;
  }
  // The next token without taking it ("" at the end).
  std::string_view peek() {
    if (!more()) return {};
    std::size_t j = pos_;
    while (j < end_ && !space(d_[j]) && !(comment_ && d_[j] == comment_)) ++j;
    return std::string_view(d_.data() + pos_, j - pos_);
  }
  std::string_view token(const char* what = "data") {
    const std::string_view t = peek();
    if (t.empty()) fail(std::string("file ends early (truncated?): expected ") + what);
    pos_ += t.size();
    return t;
  }
  // Whether the next token is on the current line (only white space before it).
  bool on_this_line() const {
    for (std::size_t j = pos_; j < end_; ++j) {
      if (d_[j] == '\n' || (comment_ && d_[j] == comment_)) return false;
      if (!space(d_[j])) return true;
    }
    return false;
  }
  // Whether only white space and comments are left (a short last line is a truncated file).
  bool at_end() const {
    Cursor rest = *this;
    return !rest.more();
  }
  // For formats of one entry a line, a line short of a number (on_this_line() false): read
  // on, the next line's first number was taken and the message named the next line.
  [[noreturn]] void fail_short_line(const std::string& what) const {
    fail(at_end() ? "file ends early (truncated?): " + what : what);
  }
  // Moves past the end of the current line.
  void skip_line() {
    while (pos_ < end_ && d_[pos_] != '\n') ++pos_;
    if (pos_ < end_) ++pos_, ++line_;
  }
  double number(const char* what) {
    std::string_view t = token(what);
    const std::string_view orig = t;
    if (!t.empty() && t[0] == '+') t.remove_prefix(1);
    double v = 0;
    const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
    // Out of range (1e999, 1e-999): strtod's infinity or tiny value; the caller checks finiteness.
    if (r.ec == std::errc::result_out_of_range && r.ptr == t.data() + t.size()) return std::strtod(std::string(t).c_str(), nullptr);
    if (r.ec != std::errc() || r.ptr != t.data() + t.size() || t.empty())
      fail(std::string(what) + ": " + quoted(std::string(orig)) + " is not a number");  // (a NUL byte cut the message)
    return v;
  }
  long long integer(long long lo, long long hi, const std::string& what) {
    std::string_view t = token(what.c_str());
    const std::string_view orig = t;
    if (!t.empty() && t[0] == '+') t.remove_prefix(1);
    long long v = 0;
    const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
    if (r.ec != std::errc() || r.ptr != t.data() + t.size() || t.empty() || v < lo || v > hi)
      fail(what + ": " + quoted(std::string(orig)) + " is not an integer in " + std::to_string(lo) + ".." +
           std::to_string(hi));
    return v;
  }
  // Expects the token `word` next.
  void expect(std::string_view word) {
    const std::string_view t = peek();
    if (t != word) fail("expected '" + std::string(word) + "', found " + quoted(std::string(t)));
    pos_ += t.size();
  }

  // Binary: n bytes at the cursor, copied into out (little-endian host assumed: checked by
  // the callers' endianness markers).
  template <class T>
  T binary(const char* what) {
    T v;
    if (end_ - pos_ < sizeof(T)) fail(std::string("file ends early (truncated?) in binary data: expected ") + what);
    std::memcpy(&v, d_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    return v;
  }
  std::size_t left() const { return end_ - pos_; }
  std::size_t pos() const { return pos_; }
  void seek(std::size_t p, int newlines_passed) {
    pos_ = p;
    line_ += newlines_passed;
  }
  const std::string& data() const { return d_; }
  const std::string& name() const { return name_; }

  static bool space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v'; }

 private:
  const std::string& d_;
  const std::string& name_;
  std::size_t pos_, end_;
  char comment_;
  int line_ = 1;
};

// Refuses a declared count above the cap or above what the bytes left can hold (each entry
// needs at least min_bytes), before anything is allocated for it.
inline void check_count(const Cursor& c, long long n, long long cap, std::size_t min_bytes, const std::string& what) {
  if (n < 0) c.fail(what + " " + std::to_string(n) + " is negative");
  if (n > cap) c.fail(what + " " + std::to_string(n) + " is above the limit of " + std::to_string(cap));
  if (min_bytes > 0 && std::uint64_t(n) > c.left() / min_bytes + 1)
    c.fail(what + " " + std::to_string(n) + " cannot fit in the " + std::to_string(c.left()) + " bytes left (truncated file?)");
}

}  // namespace softtled::tet_io
