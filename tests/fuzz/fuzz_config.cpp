// libFuzzer target: the YAML configuration reader on arbitrary text. An InputError is the expected
// answer to a bad file; anything else escaping -- another exception, a crash, a sanitizer report --
// is a bug.
#include <cstddef>
#include <cstdint>
#include <string>

#include "bundletrack/config/config_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    bundletrack::parseConfig(std::string(reinterpret_cast<const char*>(data), size), "fuzz-input.yaml");
  } catch (const bundletrack::InputError&) {
  }
  return 0;
}
