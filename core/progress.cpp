#include "core/progress.h"

#include <unistd.h>

#include <cstdio>

namespace nebula {

Progress::Progress(std::string label, uint64_t total, bool enabled)
    : label_(std::move(label)),
      total_(total == 0 ? 1 : total),
      enabled_(enabled),
      tty_(isatty(STDERR_FILENO) != 0),
      start_(std::chrono::steady_clock::now()) {
  if (enabled_) thread_ = std::thread([this] { loop(); });
}

Progress::~Progress() { finish(); }

void Progress::finish() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (stop_) return;
    stop_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) {
    thread_.join();
    draw(true);
  }
}

void Progress::loop() {
  // Redraw often on a terminal, rarely in a log file.
  const auto period = tty_ ? std::chrono::milliseconds(200) : std::chrono::milliseconds(5000);
  std::unique_lock<std::mutex> lock(mutex_);
  while (!wake_.wait_for(lock, period, [this] { return stop_; })) draw(false);
}

void Progress::draw(bool final_line) {
  const double elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  if (!final_line && elapsed < 1.0) return;  // short work draws nothing
  const uint64_t done = done_.load(std::memory_order_relaxed);
  const double fraction = done >= total_ ? 1.0 : static_cast<double>(done) / total_;
  const double eta = fraction > 0 ? elapsed * (1 - fraction) / fraction : 0;
  constexpr int kWidth = 30;
  const int filled = static_cast<int>(fraction * kWidth);
  char bar[kWidth + 1];
  for (int i = 0; i < kWidth; ++i) bar[i] = i < filled ? '#' : '.';
  bar[kWidth] = 0;
  if (final_line && !tty_ && elapsed < 1.0) return;
  std::fprintf(stderr, "%s%s [%s] %5.1f%%  %.1fs elapsed, %.1fs left%s", tty_ ? "\r" : "",
               label_.c_str(), bar, 100 * fraction, elapsed, eta,
               tty_ ? (final_line ? "\n" : "") : "\n");
  std::fflush(stderr);
}

}  // namespace nebula
