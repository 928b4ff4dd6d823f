#pragma once
// relief-snake extract, and segment's --extract DIR (extract_command.cpp).
#include <functional>
#include <string>
#include <vector>

namespace relief_snake::cli {

/// Usage of the extract command, for relief-snake --help.
extern const char* kExtractUsage;

/// relief-snake extract MESH RESULT.json --out DIR [--pixel-size S] [--flatten auto|plane|conformal]
/// [--step-height H] [--quiet]. Returns the exit code (2 for usage errors, printed here);
/// throws relief_snake::Error for bad input (exit 1 in main).
int run_extract(const std::vector<std::string>& args);

/// segment with --extract DIR [--pixel-size S] [--flatten M]: runs `segment` on the other arguments
/// (with --out DIR/result.json unless --out is given), then extracts from its result.
int run_segment_with_extract(const std::vector<std::string>& args,
                             const std::function<int(const std::vector<std::string>&)>& segment);

}  // namespace relief_snake::cli
