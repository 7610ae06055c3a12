#pragma once
/// @file
/// @brief LineWriter: text lines from the frame path to a file without blocking it. Lines go into a
/// fixed ring; a background thread writes them out. A line that does not fit is dropped and counted
/// (the frame path never waits for the disk).
#include <atomic>
#include <cstdio>
#include <memory>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "core/result.hpp"
#include "core/spsc_ring.hpp"

namespace orthoflow::graphs {

class LineWriter {
 public:
  /// @brief Opens (truncates) @p path; "-" writes to stdout. @p ring_bytes bounds the backlog.
  [[nodiscard]] static Result<std::unique_ptr<LineWriter>, std::string> open(
      const std::string& path, std::size_t ring_bytes = 4 << 20);
  ~LineWriter();  ///< writes what is queued, then closes
  LineWriter(const LineWriter&) = delete;
  LineWriter& operator=(const LineWriter&) = delete;
  /// @brief Queues @p line plus '\n'. Single producer. @return false if dropped (ring full).
  /// Lock-free.
  bool write(std::string_view line) noexcept;
  /// @brief Waits until everything queued is written and flushed (off the frame path).
  void flush() noexcept;
  [[nodiscard]] std::uint64_t dropped() const noexcept { return dropped_.load(); }
  /// @brief True if a write to the file failed (reported once the run ends).
  [[nodiscard]] bool failed() const noexcept { return failed_.load(); }

 private:
  LineWriter(std::FILE* file, bool owned, std::size_t ring_bytes);
  void loop() noexcept;
  bool drain() noexcept;
  std::FILE* file_;
  bool owned_;
  core::SpscRing<char> ring_;
  std::atomic<bool> stop_{false}, failed_{false};
  std::atomic<std::uint64_t> dropped_{0};
  std::thread thread_;
};

}  // namespace orthoflow::graphs
