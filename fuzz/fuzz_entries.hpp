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

/// segment() on small meshes: byte 0 picks one of six fixed 10 x 10 height fields (a sharp,
/// a blended and a ring-shaped disk, a step to the boundary, a disk on a tilted wavy background,
/// a flat field; built once) or a 3..8 by 3..8 field with heights from the bytes; then 2..7
/// picks, flags (closed, side, foot snap, holes, refit, auto h, extras), planarity options, h,
/// W_int, 1..5 iterations per phase, a cancel point, and band or hole picks.
void segment_small(const std::uint8_t* data, std::size_t size);

}  // namespace relief_snake::fuzz
