#pragma once
/// @file
/// @brief A progress indicator for long offline loops (evaluation runs, dataset description).
/// On a terminal: one line redrawn with '\r', at most ~10 times a second:
/// `label [########............] 42/100  42%  elapsed 0:12  ETA 0:17`.
/// Elsewhere (a log file, CI): plain lines without '\r' or escape codes, at most one per 10 % step,
/// and the final one.
#include <atomic>
#include <cstddef>
#include <cstdio>
#include <functional>
#include <mutex>
#include <string>

namespace orthoflow::evaluation {

/// @brief Counts finished steps out of a known total and reports them on a FILE stream.
/// @note advance() is thread-safe: the count is an atomic, drawing happens under a mutex and is
/// skipped (not queued) while another thread draws, so workers never wait on the terminal. finish()
/// is called once, after the workers are done. Output depends on the clock only through the elapsed
/// and ETA fields and, on a terminal, the 0.1 s throttle.
class Progress {
 public:
  /// @brief Seconds on a monotonic clock; injectable so tests are deterministic.
  using Clock = std::function<double()>;

  /// @brief Reports on @p out with std::chrono::steady_clock.
  /// @pre @p out stays open until finish() or destruction. @p terminal: redraw one line (e.g.
  /// isatty(fileno(out))).
  Progress(std::string label, std::size_t total, std::FILE* out, bool terminal);
  /// @brief Same, with the time source @p now_seconds; it is only called under the drawing mutex,
  /// so it need not be thread-safe.
  Progress(std::string label, std::size_t total, std::FILE* out, bool terminal, Clock now_seconds);
  /// @brief Calls finish() if it was not called, so a terminal line always ends with a newline.
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  /// @brief Adds @p n finished steps (the count stops at total) and redraws if due.
  void advance(std::size_t n = 1);
  /// @brief Writes the final line ("label 100/100 100%  elapsed 1:02" for a finished run). Later
  /// calls do nothing.
  void finish();
  /// @brief Steps counted so far, <= total.
  [[nodiscard]] std::size_t done() const noexcept { return done_.load(std::memory_order_relaxed); }

  /// @brief True if @p out is a terminal (isatty of its descriptor).
  [[nodiscard]] static bool is_terminal(std::FILE* out) noexcept;
  /// @brief "m:ss", or "h:mm:ss" from one hour on; negative or non-finite seconds give "--".
  [[nodiscard]] static std::string format_duration(double seconds);

 private:
  [[nodiscard]] std::string line(std::size_t done, double now, bool final_line) const;
  void draw(std::size_t done, double now, bool final_line);

  std::string label_;
  std::size_t total_;
  std::FILE* out_;
  bool terminal_;
  Clock now_;
  double start_;
  std::atomic<std::size_t> done_{0};
  std::mutex draw_mutex_;
  double last_draw_ = -1e300;  // guarded by draw_mutex_
  std::size_t printed_tenth_ =
      0;  // guarded by draw_mutex_: 10 % steps already printed (plain mode)
  std::size_t last_width_ =
      0;  // guarded by draw_mutex_: length of the terminal line, to blank leftovers
  bool finished_ = false;  // guarded by draw_mutex_
};

}  // namespace orthoflow::evaluation
