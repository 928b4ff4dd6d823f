#pragma once
// relief-snake detect, and segment with several --picks groups (multi_command.cpp).
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "relief_snake/mesh.hpp"
#include "relief_snake/segment.hpp"

namespace relief_snake::cli {

/// Usage of the detect command, for relief-snake --help.
extern const char* kDetectUsage;

/// Loads a mesh (the CLI's loader: --allow-partial, warnings); sets the load time.
using MeshLoader = std::function<Mesh(const std::string& path, double* load_seconds)>;

/// relief-snake detect MESH [--region-vertices FILE] [--min-area A] [--out FILE] [...]. Returns the
/// exit code (0: written and every candidate converged or none found; 3: written, some candidate
/// doubtful or failed); throws UsageError-like std::invalid_argument for usage errors (exit 2) and
/// relief_snake::Error for bad input (exit 1).
int run_detect(const std::vector<std::string>& args, const MeshLoader& load);

/// segment with two or more groups: one snake each on one Segmenter, written as the
/// "relief-snake-results/1" document. Returns 0 when every relief converged, else 3.
int run_segment_groups(const Mesh& mesh, const std::vector<std::vector<std::int64_t>>& groups, const Options& options,
                       const std::string& mesh_path, const std::string& out_path, double load_seconds, bool quiet);

/// Writes text to path through a temporary name renamed when complete (stdout when path is empty).
void write_document(const std::string& text, const std::string& path);

}  // namespace relief_snake::cli
