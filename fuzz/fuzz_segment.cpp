// libFuzzer target: segment() on small meshes with picks and options from the bytes (fuzz_entries.hpp).
#include "fuzz_entries.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  relief_snake::fuzz::segment_small(data, size);
  return 0;
}
