#include "worker_pool.hpp"

namespace relief_snake {
namespace {
// The worker index of the task this thread is running (-1 outside any task). A run() from inside
// a task (nested parallelism, as libigl's parallel_for allows) then runs its items serially on
// this thread under the same index, so per-worker scratch stays owned by one thread.
thread_local int tls_worker = -1;

struct InTask {
  int saved;
  explicit InTask(int worker) : saved(tls_worker) { tls_worker = worker; }
  ~InTask() { tls_worker = saved; }
};
}  // namespace

WorkerPool::WorkerPool(int threads) {
  if (threads <= 0) threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  for (int w = 1; w < threads; ++w) threads_.emplace_back([this, w] { worker_main(w); });
}

WorkerPool::~WorkerPool() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  for (std::thread& t : threads_) t.join();
}

void WorkerPool::work(int worker) {
  for (int item = next_.fetch_add(1); item < count_; item = next_.fetch_add(1)) {
    try {
      const InTask in_task(worker);
      (*task_)(item, worker);
    } catch (...) {
      std::lock_guard<std::mutex> lock(mutex_);
      if (!error_) error_ = std::current_exception();
      next_.store(count_);  // skip the rest
    }
  }
}

void WorkerPool::worker_main(int worker) {
  std::uint64_t seen = 0;
  for (;;) {
    {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait(lock, [&] { return stop_ || generation_ != seen; });
      if (stop_) return;
      seen = generation_;
    }
    work(worker);
    std::lock_guard<std::mutex> lock(mutex_);
    if (--busy_ == 0) done_.notify_one();
  }
}

void WorkerPool::run(int count, const std::function<void(int, int)>& task) {
  if (count <= 0) return;
  if (tls_worker >= 0) {  // nested: inside one of this (or another) pool's tasks
    for (int item = 0; item < count; ++item) task(item, tls_worker);
    return;
  }
  if (threads_.empty() || count == 1) {
    const InTask in_task(0);
    for (int item = 0; item < count; ++item) task(item, 0);
    return;
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    task_ = &task;
    count_ = count;
    next_.store(0);
    busy_ = static_cast<int>(threads_.size());
    error_ = nullptr;
    ++generation_;
  }
  wake_.notify_all();
  work(0);
  std::unique_lock<std::mutex> lock(mutex_);
  done_.wait(lock, [&] { return busy_ == 0; });
  task_ = nullptr;
  if (error_) std::rethrow_exception(error_);
}

}  // namespace relief_snake
