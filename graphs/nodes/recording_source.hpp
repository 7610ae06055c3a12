#pragma once
/// @file
/// @brief (internal) The base of the sources that replay a recording from files (replay_source,
/// tum_source): RecordingSource decodes the files ahead on a thread (DecodeAhead) and emits them at
/// the recorded pace (RecordedPace) or unpaced; a file that does not decode is an error frame.
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string_view>
#include <thread>
#include <vector>

#include "graphs/nodes/decode_ahead.hpp"
#include "graphs/nodes/frame_source.hpp"

namespace orthoflow::graphs {

/// Each frame waits until its time since the first frame; a pause of more than a second in the
/// recording is cut to one second, and a schedule that goes back (a loop starting over) restarts
/// the clock.
class RecordedPace {
 public:
  using Clock = std::chrono::steady_clock;
  static constexpr std::int64_t MAX_GAP_NS = 1'000'000'000;

  /// Sleeps until @p schedule_ns (the frame's recorded time since the first frame) has come.
  void wait(std::int64_t schedule_ns) noexcept {
    const auto now = Clock::now();
    if (!started_ || schedule_ns < last_schedule_ns_) {
      started_ = true;
      origin_ = now - std::chrono::nanoseconds(schedule_ns);
    } else if (schedule_ns - last_schedule_ns_ > MAX_GAP_NS) {
      origin_ -= std::chrono::nanoseconds(schedule_ns - last_schedule_ns_ - MAX_GAP_NS);
    }
    last_schedule_ns_ = schedule_ns;
    std::this_thread::sleep_until(origin_ + std::chrono::nanoseconds(schedule_ns));
  }

 private:
  bool started_ = false;
  std::int64_t last_schedule_ns_ = 0;
  Clock::time_point origin_{};
};

/// A recording's files, decoded ahead and emitted in order; the derived source decodes one file.
class RecordingSource : public FrameSource {
 public:
  static constexpr std::chrono::milliseconds DECODE_TIMEOUT{5000};

  /// @p timeout_text: the frame error's detail when no file decoded within DECODE_TIMEOUT.
  RecordingSource(std::size_t capacity, const engine::NodeContext& context, bool paced,
                  std::string_view timeout_text)
      : FrameSource(capacity, context), paced_(paced), timeout_text_(timeout_text) {}

  engine::SourceStatus produce(engine::Message& out) noexcept override {
    DecodeAhead::Slot* slot = decoder_->next(DECODE_TIMEOUT);
    if (slot != nullptr && slot->end) return engine::SourceStatus::END;
    if (slot != nullptr && slot->ok && paced_) pace_.wait(slot->schedule_ns);
    if (!take_block(out)) return engine::SourceStatus::FRAME;
    if (slot == nullptr || !slot->ok) {
      emit_decode_failure(out, slot, timeout_text_);
      return engine::SourceStatus::FRAME;
    }
    kernels::PointCloud& cloud = slot->cloud;
    cloud.info.frame_id = frames_++;
    cloud.info.host_stamp_ns = std::chrono::steady_clock::now().time_since_epoch().count();
    emit_cloud(out, cloud);
    decoder_->release();
    return engine::SourceStatus::FRAME;
  }

 protected:
  /// Starts decoding @p files, three ahead (the last step of the derived constructor).
  void start_decoding(std::vector<std::filesystem::path> files, bool loop,
                      DecodeAhead::Decode decode) {
    decoder_ = std::make_unique<DecodeAhead>(std::move(files), loop, 3, std::move(decode));
  }
  /// Stops the decoder thread (first in the derived destructor: its decode uses derived members).
  void stop_decoding() noexcept { decoder_.reset(); }

 private:
  bool paced_;
  std::string_view timeout_text_;
  RecordedPace pace_;
  std::uint64_t frames_ = 0;
  std::unique_ptr<DecodeAhead> decoder_;
};

}  // namespace orthoflow::graphs
