#pragma once
/// @file
/// @brief DecodeAhead: a file sources' decode-ahead. A background thread reads and decodes a list
/// of files in order into a few slots, so that reading a file (about 8 ms for a binary_compressed
/// 640x480 PCD) runs beside the graph instead of on its critical path; the source takes the next
/// decoded file and gives the slot back. The decoder thread allocates (the readers do); the frame
/// path only copies out of a slot. The decoding step is the source's: PCD files for pcd_source
/// (read_pcd_into, graphs/nodes/source_nodes.hpp), fakenect depth records for replay_source
/// (graphs/nodes/replay_source.cpp).
#include <atomic>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <thread>
#include <vector>

#include "core/spsc_ring.hpp"
#include "formats/io_error.hpp"
#include "kernels/point_cloud.hpp"

namespace orthoflow::graphs {

class DecodeAhead {
 public:
  /// @brief One decoded file: its cloud, or why it could not be read; @p end after the last file
  /// (never with loop).
  struct Slot {
    kernels::PointCloud cloud;
    bool ok = false;
    formats::IoError error{};
    bool end = false;
    std::int64_t schedule_ns = 0;  ///< when the file is due, for a paced replay (0 = unpaced)
  };
  /// @brief Decodes file @p index of the list into @p slot (sets ok / error / cloud). Runs on the
  /// decoder thread; may allocate and block; must not throw.
  using Decode = std::function<void(std::size_t index, Slot& slot)>;
  /// @brief Starts decoding @p files (in this order, again from the first with @p loop) into
  /// @p depth slots. @pre !files.empty(), depth >= 1.
  /// @p decode turns file @p index into a slot. @pre decode is not empty.
  DecodeAhead(std::vector<std::filesystem::path> files, bool loop, std::size_t depth,
              Decode decode);
  ~DecodeAhead();  ///< stops the thread (a file being read is finished first)
  DecodeAhead(const DecodeAhead&) = delete;
  DecodeAhead& operator=(const DecodeAhead&) = delete;

  /// @brief The next decoded file, waiting at most @p timeout for it (nullptr: not ready in time).
  /// Single consumer. Until release(), the slot is the caller's. Never allocates.
  [[nodiscard]] Slot* next(std::chrono::milliseconds timeout) noexcept;
  /// @brief Gives the slot of the last next() back to the decoder.
  void release() noexcept;

 private:
  void loop() noexcept;
  std::vector<std::filesystem::path> files_;
  bool loop_;
  Decode decode_;
  std::vector<Slot> slots_;
  core::SpscRing<std::uint32_t> free_, ready_;  // slot indices: to the decoder, to the source
  std::uint32_t held_ = 0;
  bool holding_ = false;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace orthoflow::graphs
