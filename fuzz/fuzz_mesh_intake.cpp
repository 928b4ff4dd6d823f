// libFuzzer target: mesh intake from bytes (fuzz_entries.hpp).
#include "fuzz_entries.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  relief_snake::fuzz::mesh_intake(data, size);
  return 0;
}
