// libFuzzer target: parse_tetgen (TetGen .node / .ele) on arbitrary bytes, then
// import_tet_soup (sim/mesh/tet_io.h); an accepted mesh must pass require_valid_tet_mesh.
// The input is the .node text, a NUL byte, then the .ele text (no NUL: an empty .ele).
#include "fuzz_tet.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return softtled::fuzz::run_tet(data, size, [](const std::string& s) {
    const std::size_t z = s.find('\0');
    const std::string node = s.substr(0, z), ele = z == std::string::npos ? "" : s.substr(z + 1);
    return softtled::parse_tetgen(node, ele, "fuzz", 100000);
  });
}
