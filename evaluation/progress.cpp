#include "evaluation/progress.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <utility>

namespace orthoflow::evaluation {

namespace {

constexpr double REDRAW_SECONDS =
    0.1;  // ~10 Hz: fast enough to look live, cheap on a slow terminal
constexpr std::size_t BAR_WIDTH = 20;

double steady_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// Fraction done in [0, 1]; an empty job (total 0) counts as complete.
double fraction(std::size_t done, std::size_t total) {
  return total == 0 ? 1.0 : static_cast<double>(done) / static_cast<double>(total);
}

// Completed 10 % steps, 0..10 (plain mode prints one line per step).
std::size_t tenths(std::size_t done, std::size_t total) {
  return total == 0 ? 0 : static_cast<std::size_t>(std::floor(10.0 * fraction(done, total)));
}

}  // namespace

Progress::Progress(std::string label, std::size_t total, std::FILE* out, bool terminal)
    : Progress(std::move(label), total, out, terminal, steady_seconds) {}

Progress::Progress(std::string label, std::size_t total, std::FILE* out, bool terminal,
                   Clock now_seconds)
    : label_(std::move(label)),
      total_(total),
      out_(out),
      terminal_(terminal),
      now_(std::move(now_seconds)),
      start_(now_()) {
  if (terminal_) {
    const std::lock_guard lock(draw_mutex_);
    draw(0, start_, false);  // show the label at once: the first step may take a while
  }
}

Progress::~Progress() { finish(); }

void Progress::advance(std::size_t n) {
  std::size_t before = done_.load(std::memory_order_relaxed);
  std::size_t after = 0;
  do {  // clamp at total without overflow: a step past the end counts as the end
    after = total_ - before < n ? total_ : before + n;
  } while (!done_.compare_exchange_weak(before, after, std::memory_order_relaxed));
  if (!terminal_) {
    if (tenths(before, total_) == tenths(after, total_))
      return;  // no 10 % boundary crossed: nothing to print
    const std::lock_guard lock(draw_mutex_);
    const std::size_t now_done = done_.load(std::memory_order_relaxed);
    const std::size_t tenth = tenths(now_done, total_);
    if (finished_ || tenth <= printed_tenth_ || tenth >= 10) return;  // 100 % is finish()'s line
    printed_tenth_ = tenth;
    draw(now_done, now_(), false);
    return;
  }
  const std::unique_lock lock(draw_mutex_, std::try_to_lock);
  if (!lock.owns_lock() || finished_) return;  // another thread is drawing: skip rather than wait
  const double now = now_();
  if (now - last_draw_ < REDRAW_SECONDS) return;
  draw(done_.load(std::memory_order_relaxed), now, false);
}

void Progress::finish() {
  const std::lock_guard lock(draw_mutex_);
  if (finished_) return;
  finished_ = true;
  draw(done_.load(std::memory_order_relaxed), now_(), true);
}

bool Progress::is_terminal(std::FILE* out) noexcept {
  return out != nullptr && ::isatty(::fileno(out)) == 1;
}

std::string Progress::format_duration(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0) return "--";
  const auto total = static_cast<long long>(std::llround(std::min(seconds, 1e12)));
  const long long h = total / 3600, m = (total / 60) % 60, s = total % 60;
  char buf[48];
  if (h > 0) {
    std::snprintf(buf, sizeof buf, "%lld:%02lld:%02lld", h, m, s);
  } else {
    std::snprintf(buf, sizeof buf, "%lld:%02lld", m, s);
  }
  return buf;
}

std::string Progress::line(std::size_t done, double now, bool final_line) const {
  const double frac = fraction(done, total_), elapsed = std::max(0.0, now - start_);
  std::string text = label_ + ' ';
  if (terminal_) {
    const auto filled = static_cast<std::size_t>(std::floor(frac * static_cast<double>(BAR_WIDTH)));
    text += '[' + std::string(filled, '#') + std::string(BAR_WIDTH - filled, '.') + "] ";
  }
  char counts[96];
  std::snprintf(counts, sizeof counts, "%zu/%zu %3d%%  elapsed ", done, total_,
                static_cast<int>(std::floor(100.0 * frac)));
  text += counts + format_duration(elapsed);
  if (final_line) return text;
  // ETA from the mean rate so far (thesis-style runs have steps of similar cost): elapsed *
  // remaining / done.
  const double eta =
      done == 0 ? -1.0 : elapsed * static_cast<double>(total_ - done) / static_cast<double>(done);
  return text + "  ETA " + format_duration(eta);
}

void Progress::draw(std::size_t done, double now, bool final_line) {
  std::string text = line(done, now, final_line);
  last_draw_ = now;
  if (terminal_) {
    const std::size_t width = text.size();
    if (width < last_width_)
      text.append(last_width_ - width, ' ');  // blank what a longer line left behind
    last_width_ = width;
    std::fputc('\r', out_);
  }
  std::fputs(text.c_str(), out_);
  if (!terminal_ || final_line) std::fputc('\n', out_);
  std::fflush(out_);
}

}  // namespace orthoflow::evaluation
