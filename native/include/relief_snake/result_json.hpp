#pragma once
// One result format: the JSON the CLI writes and the dict the Python module returns are
// the same document (docs/result-format.md), made here from a Result.
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "relief_snake/mesh.hpp"
#include "relief_snake/segment.hpp"

namespace relief_snake {

/// What the front end adds to a Result: where the mesh came from and how long things took.
struct ResultContext {
  std::string mesh_path;              ///< file name, or empty for arrays
  std::vector<std::int64_t> picks;    ///< as given (input vertex indices)
  double load_seconds = 0;            ///< mesh intake
  double segment_seconds = 0;         ///< the engine
};

/// What intake made of the mesh (input counts, merges, refusals, sizes, one-line summary).
nlohmann::json mesh_report_json(const Mesh& mesh, const std::string& path = "");

/// The result document. options: the options the segmentation was called with.
nlohmann::json to_json(const Result& result, const Options& options, const Mesh& mesh, const ResultContext& context);

}  // namespace relief_snake
