// libFuzzer target: parse_msh (Gmsh .msh 2.2 / 4.1, ASCII and binary) on arbitrary bytes, then
// import_tet_soup (sim/mesh/tet_io.h); an accepted mesh must pass require_valid_tet_mesh.
#include "fuzz_tet.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return softtled::fuzz::run_tet(data, size, [](const std::string& s) { return softtled::parse_msh(s, "fuzz.msh", 100000); });
}
