// WorkerPool: every item once, worker indices in range, exceptions rethrown, nested runs safe.
#include <gtest/gtest.h>

#include <atomic>
#include <stdexcept>
#include <thread>
#include <vector>

#include "../../native/src/worker_pool.hpp"

using relief_snake::WorkerPool;

TEST(WorkerPool, RunsEveryItemOnceWithWorkerIndicesInRange) {
  WorkerPool pool(3);
  std::vector<std::atomic<int>> hits(1000);
  std::atomic<bool> bad_worker{false};
  pool.run(1000, [&](int item, int worker) {
    hits[item]++;
    if (worker < 0 || worker >= pool.size()) bad_worker = true;
  });
  for (const auto& h : hits) EXPECT_EQ(h.load(), 1);
  EXPECT_FALSE(bad_worker);
}

TEST(WorkerPool, RethrowsTheFirstException) {
  WorkerPool pool(2);
  EXPECT_THROW(pool.run(100, [](int item, int) {
                 if (item == 37) throw std::runtime_error("item 37");
               }),
               std::runtime_error);
  // Still usable afterwards.
  std::atomic<int> sum{0};
  pool.run(10, [&](int item, int) { sum += item; });
  EXPECT_EQ(sum.load(), 45);
}

TEST(WorkerPool, NestedRunsFinishSeriallyOnTheCallersWorker) {
  WorkerPool pool(3);
  std::vector<std::atomic<int>> inner_hits(40 * 25);
  std::atomic<bool> foreign_worker{false};
  pool.run(40, [&](int outer, int worker) {
    const std::thread::id me = std::this_thread::get_id();
    pool.run(25, [&](int inner, int inner_worker) {
      inner_hits[outer * 25 + inner]++;
      // Serial on the same thread, under the outer task's worker index (its scratch).
      if (inner_worker != worker || std::this_thread::get_id() != me) foreign_worker = true;
    });
  });
  for (const auto& h : inner_hits) EXPECT_EQ(h.load(), 1);
  EXPECT_FALSE(foreign_worker);
}
