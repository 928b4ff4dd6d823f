#pragma once
// The fuzzed entry points, shared by the libFuzzer targets (fuzz_*.cpp, clang, ASan+UBSan)
// and the regression runner that `make test` runs over fuzz/corpus and fuzz/regression.
// Each takes arbitrary bytes; the engine's own Error is the expected outcome for bad
// input, anything else (a crash, a sanitizer report, another exception) is a finding.
#include <cstddef>
#include <cstdint>

namespace relief_snake::fuzz {

/// Byte 0 picks the format (bits 0-1: OBJ, PLY, OFF, STL) and bit 2 allow_partial; the
/// rest is the file's bytes, read by read_mesh_bytes and built by Mesh::from_soup.
void mesh_intake(const std::uint8_t* data, std::size_t size);

/// A small height-field mesh (3..12 by 3..12 vertices, heights from the bytes), then
/// 2..6 picks and the main options from the bytes, then segment() capped at a few
/// iterations per phase.
void segment_small(const std::uint8_t* data, std::size_t size);

}  // namespace relief_snake::fuzz
