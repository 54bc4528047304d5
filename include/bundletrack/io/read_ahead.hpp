#pragma once

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <utility>
#include <variant>

namespace bundletrack::io {

/// Reads items 0 .. count-1 in order on one background thread, at most `capacity` ahead of the
/// consumer, so that decoding the next frames overlaps tracking this one (the tracker's own API
/// stays synchronous). next() hands them out in order; an item whose reading threw rethrows
/// there, in the consumer's thread, and reading goes on with the next index.
/// `read(i, backlog)` reads item i; `backlog` says whether, as it starts, the consumer has an
/// item waiting already: then it will not wait for this one soon, and the reader may do more of
/// the consumer's work on it (preprocess a frame, io::frameAhead); without, the consumer is
/// waiting for the reader, and that work is better left to the consumer.
template <typename T>
class ReadAhead {
 public:
  ReadAhead(std::size_t count, std::function<T(std::size_t, bool)> read, std::size_t capacity = 4)
      : count_(count), capacity_(capacity < 1 ? 1 : capacity), read_(std::move(read)),
        worker_([this](std::stop_token stop) { run(stop); }) {}

  ReadAhead(const ReadAhead&) = delete;
  ReadAhead& operator=(const ReadAhead&) = delete;

  ~ReadAhead() {
    {
      std::lock_guard lock(mutex_);  // so that the worker cannot miss the stop between its test and its wait
      worker_.request_stop();
    }
    changed_.notify_all();
  }  // the jthread joins

  /// The next item; call it at most `count` times.
  T next() {
    std::unique_lock lock(mutex_);
    changed_.wait(lock, [&] { return !ready_.empty(); });
    Slot slot = std::move(ready_.front());
    ready_.pop_front();
    lock.unlock();
    changed_.notify_all();
    if (auto* error = std::get_if<std::exception_ptr>(&slot)) std::rethrow_exception(*error);
    return std::move(std::get<T>(slot));
  }

 private:
  using Slot = std::variant<T, std::exception_ptr>;

  void run(const std::stop_token& stop) {
    for (std::size_t i = 0; i < count_; ++i) {
      bool backlog = false;
      {
        std::unique_lock lock(mutex_);
        changed_.wait(lock, [&] { return stop.stop_requested() || ready_.size() < capacity_; });
        if (stop.stop_requested()) return;
        backlog = !ready_.empty();
      }
      Slot slot = [&]() -> Slot {
        try {
          return read_(i, backlog);
        } catch (...) {
          return std::current_exception();
        }
      }();
      {
        std::lock_guard lock(mutex_);
        ready_.push_back(std::move(slot));
      }
      changed_.notify_all();
    }
  }

  std::size_t count_, capacity_;
  std::function<T(std::size_t, bool)> read_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<Slot> ready_;
  std::jthread worker_;  // last: starts after, and joins before, the members it uses
};

}  // namespace bundletrack::io
