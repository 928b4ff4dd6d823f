#pragma once
// relief-snake batch: hands the command line to the Python batch runner (batch/relief_snake_batch,
// docs/batch.md), which runs each manifest entry as its own relief-snake process.
#include <string>
#include <vector>

namespace relief_snake::cli {

/// Usage of the batch command, for relief-snake --help.
extern const char* kBatchUsage;

/// relief-snake batch MANIFEST.json --out DIR [...]: replaces this process with
///   $RELIEF_SNAKE_PYTHON -m relief_snake_batch --cli <this executable> ARGS...
/// with the runner's folder ($RELIEF_SNAKE_BATCH_PATH, else the one CMake recorded) first on
/// PYTHONPATH. Returns only when that cannot start: throws relief_snake::Error (exit 1) naming what is
/// missing and what to set.
int run_batch(const std::vector<std::string>& args);

}  // namespace relief_snake::cli
