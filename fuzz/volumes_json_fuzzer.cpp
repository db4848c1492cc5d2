// libFuzzer target over the VOLUMES.json parser (src/io/volumes_json.cpp, fogcl::parse_volumes_file): the
// text `fogcl apply --volumes` reads. The contract under test: any input either gives volumes and
// lights that pass fogcl::validate and survive a round trip through volumes_to_json unchanged, or throws
// fogcl::Error with one line; no crash (nesting 100 000 deep included), no other exception, no
// sanitizer report. Built with clang (-fsanitize=fuzzer,address,undefined) by `make fuzz`, which
// runs it on the demo's volume files (fuzz/make_seeds writes them) with fuzz/volumes_json.dict.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "fogcl/error.h"
#include "fogcl/volumes_json.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const fogcl::VolumesFile file = fogcl::parse_volumes_file(text, "fuzz.json");
    for (std::size_t i = 0; i < file.volumes.size(); ++i) fogcl::validate(file.volumes[i], i);
    for (std::size_t i = 0; i < file.lights.size(); ++i) fogcl::validate(file.lights[i], i);
    const std::string written = fogcl::volumes_to_json(file);
    if (fogcl::volumes_to_json(fogcl::parse_volumes_file(written, "written.json")) != written)
      __builtin_trap();  // what the parser accepted does not read back as the same volumes and lights
  } catch (const fogcl::Error& e) {
    if (std::strchr(e.what(), '\n') != nullptr) __builtin_trap();  // errors are one line
  }
  return 0;
}
