#pragma once
// Shared body of the libFuzzer targets: a loader must either return or throw InputError.
// Any other exception escapes LLVMFuzzerTestOneInput and libFuzzer reports it as a crash
// ("deadly signal" from std::terminate), like an ASan or UBSan report or a timeout.
#include <cstddef>
#include <cstdint>
#include <string>

#include "sim/surface_mesh.h"

namespace softtled::fuzz {

template <class Parse>
int run_one(const std::uint8_t* data, std::size_t size, Parse parse) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    parse(text);
  } catch (const InputError&) {
    // the expected outcome for bad input
  }
  return 0;
}

}  // namespace softtled::fuzz
