// libFuzzer target: parse_scene (sim/scene.h). The input is the TOML text; each line that
// starts with "#@set " also becomes a --set override (the rest of the line, "key=value"),
// so one input exercises both the file and the override path and stays valid TOML.
#include <sstream>
#include <vector>

#include "fuzz_target.h"
#include "sim/scene.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return softtled::fuzz::run_one(data, size, [](const std::string& text) {
    std::vector<std::string> overrides;
    std::istringstream in(text);
    const std::string tag = "#@set ";
    for (std::string line; std::getline(in, line);)
      if (line.compare(0, tag.size(), tag) == 0) overrides.push_back(line.substr(tag.size()));
    softtled::parse_scene(text, "fuzz.toml", overrides);
  });
}
