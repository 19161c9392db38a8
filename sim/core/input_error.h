#pragma once
// Thrown for every user-facing input problem (bad file, bad mesh, bad scene key); the
// message names the problem, main() prints it and exits with a non-zero code.
#include <stdexcept>

namespace softtled {

struct InputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

}  // namespace softtled
