#pragma once
// A small persistent pool of worker threads for data-parallel loops (internal).
// The engine's hot loops are short (tens to thousands of items of ~50 us each),
// so threads are kept alive between calls instead of being spawned per loop.
#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace relief_snake {

class WorkerPool {
 public:
  /// threads: total workers including the calling thread; <= 0 means one per
  /// hardware thread. 1 runs everything on the caller.
  explicit WorkerPool(int threads);
  ~WorkerPool();
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

  /// Number of workers (the caller is worker 0).
  int size() const { return static_cast<int>(threads_.size()) + 1; }
  /// Calls task(item, worker) for every item in [0, count), spread over the
  /// workers, and returns when all are done. Rethrows the first exception.
  /// Call from one thread at a time. A call from inside a task (nested) runs its items
  /// serially on that thread, with that task's worker index.
  void run(int count, const std::function<void(int item, int worker)>& task);

 private:
  void work(int worker);
  void worker_main(int worker);

  std::vector<std::thread> threads_;
  std::mutex mutex_;
  std::condition_variable wake_, done_;
  const std::function<void(int, int)>* task_ = nullptr;
  int count_ = 0;
  std::atomic<int> next_{0};
  int busy_ = 0;
  std::uint64_t generation_ = 0;
  bool stop_ = false;
  std::exception_ptr error_;
};

}  // namespace relief_snake
