#pragma once
// Environment variables the solvers read (SOFTTLED_CPU_SIMD, SOFTTLED_CUDA_*): a value set
// but not understood is an InputError naming the variable, never a silent default (a
// probe's SOFTTLED_CPU_SIMD=off kept the SIMD path; atoi read SOFTTLED_CUDA_GRAPH_STEPS=1e9
// as one step). Unset or empty: the default.
#include <cctype>
#include <cerrno>
#include <cstdlib>
#include <optional>
#include <string>

#include "sim/core/input_error.h"

namespace softtled {

inline std::optional<std::string> env_setting(const char* name) {
  const char* v = std::getenv(name);
  if (!v || !*v) return std::nullopt;
  return std::string(v);
}

// A whole number in [lo, hi] (decimal digits after an optional sign).
inline int env_int(const char* name, int fallback, int lo, int hi) {
  const std::optional<std::string> v = env_setting(name);
  if (!v) return fallback;
  errno = 0;
  char* end = nullptr;
  const long n = std::strtol(v->c_str(), &end, 10);
  if (errno != 0 || end == v->c_str() || *end != '\0' || std::isspace(static_cast<unsigned char>((*v)[0])) || n < lo ||
      n > hi)
    throw InputError(std::string(name) + "=" + quoted(*v) + ": expected a whole number in [" + std::to_string(lo) +
                     ", " + std::to_string(hi) + "]");
  return int(n);
}

// "0" or "1".
inline bool env_switch(const char* name, bool fallback) {
  const std::optional<std::string> v = env_setting(name);
  if (!v) return fallback;
  if (*v != "0" && *v != "1") throw InputError(std::string(name) + "=" + quoted(*v) + ": expected 0 or 1");
  return *v == "1";
}

}  // namespace softtled
