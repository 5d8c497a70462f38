#pragma once
// The hand-off between pipeline stages (tracking -> local mapping -> loop closing): a FIFO that a
// worker thread drains, or that the caller drains in lock-step (deterministic) mode. It also
// knows whether the worker is busy with an item, so tracking can wait for mapping to go idle.

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <mutex>
#include <optional>

namespace sbaslam {

template <class T>
class WorkQueue {
 public:
  void push(T item) {
    push(std::move(item), [] {});
  }

  // `with_item` runs under the queue's lock, so the worker cannot take the item before it ran.
  template <class WithItem>
  void push(T item, WithItem&& with_item) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      items_.push_back(std::move(item));
      with_item();
    }
    item_cv_.notify_one();
  }

  // For the worker: blocks for the next item and marks the worker busy until finish_item();
  // after close(), returns what is left, then nullopt.
  std::optional<T> wait_and_take() {
    std::unique_lock<std::mutex> lock(mutex_);
    item_cv_.wait(lock, [this] { return closed_ || !items_.empty(); });
    if (items_.empty()) return std::nullopt;
    busy_ = true;
    return pop_front();
  }

  void finish_item() {
    std::lock_guard<std::mutex> lock(mutex_);
    busy_ = false;
    if (items_.empty()) idle_cv_.notify_all();
  }

  // For lock-step mode: the next item without waiting.
  std::optional<T> try_take() {
    std::lock_guard<std::mutex> lock(mutex_);
    if (items_.empty()) return std::nullopt;
    return pop_front();
  }

  // Blocks until nothing is queued or being worked on, or the queue is closed.
  void wait_until_idle() {
    std::unique_lock<std::mutex> lock(mutex_);
    idle_cv_.wait(lock, [this] { return closed_ || (items_.empty() && !busy_); });
  }

  bool idle() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return items_.empty() && !busy_;
  }

  std::size_t size() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return items_.size();
  }

  // Wakes the worker to drain what is left and return; reopen() before the next worker.
  void close() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      closed_ = true;
    }
    item_cv_.notify_all();
    idle_cv_.notify_all();
  }

  void reopen() {
    std::lock_guard<std::mutex> lock(mutex_);
    closed_ = false;
  }

 private:
  T pop_front() {
    T item = std::move(items_.front());
    items_.pop_front();
    return item;
  }

  mutable std::mutex mutex_;
  std::condition_variable item_cv_;
  std::condition_variable idle_cv_;
  std::deque<T> items_;
  bool busy_ = false;
  bool closed_ = false;
};

}  // namespace sbaslam
