#pragma once
// A number for messages in the fewest %g digits (6 at least) that read back as it: a range
// message never shows a value just past its limit rounded onto it ("1e+06 is out of range
// [-1e+06, 1e+06]", "20.0000001 ... got 20").
#include <cstdio>
#include <cstdlib>
#include <string>

namespace softtled {

inline std::string exact_number(double v) {
  char buf[40];
  for (int digits = 6; digits <= 17; ++digits) {
    std::snprintf(buf, sizeof buf, "%.*g", digits, v);
    if (std::strtod(buf, nullptr) == v) break;
  }
  return buf;
}

}  // namespace softtled
