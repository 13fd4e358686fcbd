#pragma once
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <string>
#include <thread>

namespace nebula {

// A progress bar on stderr for long work, drawn by its own thread so workers
// only bump an atomic counter. On a terminal it redraws in place; elsewhere
// (CI logs) it prints a line every few seconds. Silent when disabled.
class Progress {
 public:
  Progress(std::string label, uint64_t total, bool enabled = true);
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  void add(uint64_t done) { done_.fetch_add(done, std::memory_order_relaxed); }
  void finish();

 private:
  void draw(bool final_line);
  void loop();

  std::string label_;
  uint64_t total_;
  bool enabled_;
  bool tty_;
  std::atomic<uint64_t> done_{0};
  std::chrono::steady_clock::time_point start_;
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stop_ = false;
  std::thread thread_;
};

}  // namespace nebula
