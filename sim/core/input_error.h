#pragma once
// Thrown for every user-facing input problem (bad file, bad mesh, bad scene key); the
// message names the problem, main() prints it and exits with a non-zero code.
#include <cctype>
#include <stdexcept>
#include <string>

namespace softtled {

struct InputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// The length of the well-formed UTF-8 sequence of a non-ASCII character at s[i] (2-4
// bytes, no overlong forms or surrogates), or 0.
inline std::size_t utf8_length(const std::string& s, std::size_t i) {
  const auto b = [&](std::size_t k) { return i + k < s.size() ? static_cast<unsigned char>(s[i + k]) : 0u; };
  const auto cont = [&](std::size_t k) { return (b(k) & 0xC0u) == 0x80u; };
  const unsigned c = b(0);
  if (c >= 0xC2 && c <= 0xDF) return cont(1) ? 2 : 0;
  if (c >= 0xE0 && c <= 0xEF) {
    const unsigned lo = c == 0xE0 ? 0xA0 : 0x80, hi = c == 0xED ? 0x9F : 0xBF;
    return b(1) >= lo && b(1) <= hi && cont(2) ? 3 : 0;
  }
  if (c >= 0xF0 && c <= 0xF4) {
    const unsigned lo = c == 0xF0 ? 0x90 : 0x80, hi = c == 0xF4 ? 0x8F : 0xBF;
    return b(1) >= lo && b(1) <= hi && cont(2) && cont(3) ? 4 : 0;
  }
  return 0;
}

// A value of the user's, quoted for a message: at most 60 bytes shown (then "...", and its
// length), control characters and bytes that are not UTF-8 as '?' (UTF-8 text as it is:
// units = "мм" read as '????'). A 3 MB value made a 3 MB message line.
inline std::string quoted(const std::string& v) {
  constexpr std::size_t kShown = 60;
  std::string s = "'";
  std::size_t i = 0;
  while (i < v.size() && i < kShown) {
    const unsigned char c = static_cast<unsigned char>(v[i]);
    const std::size_t n = c < 0x80 ? 1 : utf8_length(v, i);
    if (n > 1 && i + n <= kShown) {
      s += v.substr(i, n);
      i += n;
    } else {
      s += n == 1 && std::isprint(c) ? char(c) : '?';
      i += n > 1 ? n : 1;
    }
  }
  if (v.size() <= kShown) return s + "'";
  return s + "...' (" + std::to_string(v.size()) + " characters)";
}

}  // namespace softtled
