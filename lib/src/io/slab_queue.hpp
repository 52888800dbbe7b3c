// Internal: the hand-over of slabs between the baking thread and the HDF5 writer thread
// (write_hdf5_slabbed).
#pragma once

#include <array>
#include <condition_variable>
#include <deque>
#include <mutex>

#include "hairlut/tables/tables.hpp"

namespace hairlut::detail {

// Hands the slabs of slabbed tables from the baking thread to the writing thread: two buffers,
// one baked while the other is written (so at most two slabs are in memory).
class SlabQueue {
 public:
  struct Item {
    Table* values = nullptr;
    std::size_t row0 = 0, rows = 0;
  };
  SlabQueue() {
    for (Table& b : buffers_) empty_.push_back(&b);
  }
  // Baking side: a buffer to fill, or nullptr once the writer has stopped.
  Table* take_empty() {
    std::unique_lock lock(mutex_);
    changed_.wait(lock, [&] { return closed_ || !empty_.empty(); });
    if (closed_) return nullptr;
    Table* b = empty_.front();
    empty_.pop_front();
    return b;
  }
  void put_full(const Item& item) {
    std::lock_guard lock(mutex_);
    full_.push_back(item);
    changed_.notify_all();
  }
  // Writing side: the next baked slab, or false once the baker has stopped.
  bool take_full(Item& item) {
    std::unique_lock lock(mutex_);
    changed_.wait(lock, [&] { return closed_ || !full_.empty(); });
    if (full_.empty()) return false;
    item = full_.front();
    full_.pop_front();
    return true;
  }
  void put_empty(Table* b) {
    std::lock_guard lock(mutex_);
    empty_.push_back(b);
    changed_.notify_all();
  }
  // Either side stops the other (error or cancellation); the writer still drains baked slabs
  // only when it was not closed.
  void close() {
    std::lock_guard lock(mutex_);
    closed_ = true;
    full_.clear();
    changed_.notify_all();
  }

 private:
  std::mutex mutex_;
  std::condition_variable changed_;
  bool closed_ = false;
  std::array<Table, 2> buffers_;
  std::deque<Table*> empty_;
  std::deque<Item> full_;
};

}  // namespace hairlut::detail
