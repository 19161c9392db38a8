// libFuzzer target: parse_obj (sim/surface_io.h) on arbitrary bytes.
#include "fuzz_target.h"
#include "sim/mesh/surface_io.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return softtled::fuzz::run_one(data, size, [](const std::string& s) {
    softtled::fuzz::require_valid_surface(softtled::parse_obj(s, "fuzz.obj"));
  });
}
