#include "batch_command.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <system_error>

#include "relief_snake/error.hpp"

// Set by CMake: the interpreter the build found and the folder that holds relief_snake_batch/.
#ifndef RELIEF_SNAKE_BATCH_PYTHON
#define RELIEF_SNAKE_BATCH_PYTHON "python3"
#endif
#ifndef RELIEF_SNAKE_BATCH_DIR
#define RELIEF_SNAKE_BATCH_DIR ""
#endif

namespace relief_snake::cli {

const char* kBatchUsage =
    "batch: run every scan of a manifest (docs/batch.md), each as its own segment/detect process;\n"
    "  finished entries are skipped on a rerun. Needs Python 3 (Dask and tqdm optional).\n"
    "  relief-snake batch MANIFEST.json --out DIR [--jobs N] [--timeout S] [--dask local:N|tcp://HOST:PORT]\n"
    "                     [--force] [--no-progress]      (relief-snake batch --help: every option)\n"
    "  exit codes: 0 all ok, 3 some doubtful, 1 some failed, crashed or timed out, 2 usage or manifest error\n"
    "  environment: RELIEF_SNAKE_PYTHON (the interpreter), RELIEF_SNAKE_BATCH_PATH (the folder holding\n"
    "  relief_snake_batch/)\n";

namespace {

std::string env_or(const char* name, const std::string& fallback) {
  const char* value = std::getenv(name);
  return value && *value ? std::string(value) : fallback;
}

}  // namespace

int run_batch(const std::vector<std::string>& args) {
  namespace fs = std::filesystem;
  const std::string python = env_or("RELIEF_SNAKE_PYTHON", RELIEF_SNAKE_BATCH_PYTHON);
  const std::string runner_dir = env_or("RELIEF_SNAKE_BATCH_PATH", RELIEF_SNAKE_BATCH_DIR);
  std::error_code ec;
  if (runner_dir.empty() || !fs::is_regular_file(fs::path(runner_dir) / "relief_snake_batch" / "__main__.py", ec))
    throw Error("the batch runner relief_snake_batch is not in '" + runner_dir +
                "'; set RELIEF_SNAKE_BATCH_PATH to the folder that holds relief_snake_batch/ (the repository's "
                "batch/ folder)");

  // The runner starts this same executable for every entry.
  std::string self = fs::read_symlink("/proc/self/exe", ec).string();
  if (ec) self = "relief-snake";

  const char* old_path = std::getenv("PYTHONPATH");
  const std::string python_path = runner_dir + (old_path && *old_path ? std::string(":") + old_path : "");
  if (::setenv("PYTHONPATH", python_path.c_str(), 1) != 0) throw Error("cannot set PYTHONPATH for the batch runner");

  std::vector<std::string> command = {python, "-m", "relief_snake_batch", "--cli", self};
  command.insert(command.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& part : command) argv.push_back(part.data());
  argv.push_back(nullptr);
  std::cout.flush();
  std::cerr.flush();
  std::fflush(nullptr);
  ::execvp(argv[0], argv.data());
  const int error = errno;
  throw Error("batch needs Python 3: cannot start '" + python + "' (" + std::strerror(error) +
              "); install python3 or set RELIEF_SNAKE_PYTHON to an interpreter");
}

}  // namespace relief_snake::cli
