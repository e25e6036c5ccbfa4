// A first-in first-out buffer of at most `limit` elements that drops the oldest beyond it: the worker's
// input queues, the path and the diagnostics window. Its storage grows to the most it has held and is then
// reused, so a steady stream allocates nothing (std::deque allocates and frees blocks as it moves along).
// ROS-free; not thread-safe.
#pragma once

#include <algorithm>
#include <cstddef>
#include <limits>
#include <utility>
#include <vector>

namespace hglasm_odometry {

template <typename T>
class RingBuffer {
 public:
  /// `limit` >= 1 (0 is taken as 1).
  explicit RingBuffer(std::size_t limit = std::numeric_limits<std::size_t>::max())
      : limit_(std::max<std::size_t>(limit, 1)) {}

  std::size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  bool full() const { return size_ >= limit_; }
  std::size_t limit() const { return limit_; }
  /// Elements it can hold before its storage grows again.
  std::size_t capacity() const { return storage_.size(); }

  /// The i-th oldest element (i < size()).
  T& operator[](std::size_t i) { return storage_[slot(i)]; }
  const T& operator[](std::size_t i) const { return storage_[slot(i)]; }
  T& front() { return storage_[head_]; }
  const T& front() const { return storage_[head_]; }
  T& back() { return (*this)[size_ - 1]; }
  const T& back() const { return (*this)[size_ - 1]; }

  /// Appends `value`, dropping the oldest element first when full: true if one was dropped.
  bool push_back(T value) {
    const bool drop = full();
    if (drop) pop_front();
    makeRoom();
    storage_[slot(size_)] = std::move(value);
    ++size_;
    return drop;
  }

  /// Puts `value` before the oldest element; false, and nothing changed, when full.
  bool push_front(T value) {
    if (full()) return false;
    makeRoom();
    head_ = (head_ + storage_.size() - 1) % storage_.size();
    storage_[head_] = std::move(value);
    ++size_;
    return true;
  }

  /// Removes the oldest element (!empty()); what it held is released now, not when its slot is reused.
  void pop_front() {
    storage_[head_] = T();
    head_ = (head_ + 1) % storage_.size();
    --size_;
  }

  /// Removes every element and keeps the storage.
  void clear() {
    while (!empty()) pop_front();
    head_ = 0;
  }

  /// Exchanges the elements with `other`'s; each keeps its limit (each must hold no more than the
  /// other's limit). Constant time: how a consumer takes everything queued without copying or allocating.
  void swapElements(RingBuffer& other) {
    storage_.swap(other.storage_);
    std::swap(head_, other.head_);
    std::swap(size_, other.size_);
  }

 private:
  std::size_t slot(std::size_t i) const { return (head_ + i) % storage_.size(); }

  /// Grows the storage (doubling, up to the limit) when every slot is taken, oldest element first.
  void makeRoom() {
    if (size_ < storage_.size()) return;
    const std::size_t capacity = std::min(limit_, std::max<std::size_t>(8, 2 * storage_.size()));
    std::vector<T> grown(capacity);
    for (std::size_t i = 0; i < size_; ++i) grown[i] = std::move((*this)[i]);
    storage_.swap(grown);
    head_ = 0;
  }

  std::vector<T> storage_;
  std::size_t head_ = 0;
  std::size_t size_ = 0;
  std::size_t limit_;
};

}  // namespace hglasm_odometry
