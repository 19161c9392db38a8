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

// A value of the user's, quoted for a message: at most 60 characters shown (then "...",
// and its length), anything unprintable as '?'. A 3 MB value made a 3 MB message line.
inline std::string quoted(const std::string& v) {
  constexpr std::size_t kShown = 60;
  std::string s = "'" + v.substr(0, kShown);
  for (std::size_t i = 1; i < s.size(); ++i)
    if (!std::isprint(static_cast<unsigned char>(s[i]))) s[i] = '?';
  if (v.size() <= kShown) return s + "'";
  return s + "...' (" + std::to_string(v.size()) + " characters)";
}

}  // namespace softtled
