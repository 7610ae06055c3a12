#include "graphs/nodes/decode_ahead.hpp"

#include "core/assert.hpp"

namespace orthoflow::graphs {

namespace {
constexpr auto POLL = std::chrono::microseconds(200);
}  // namespace

DecodeAhead::DecodeAhead(std::vector<std::filesystem::path> files, bool loop, std::size_t depth,
                         Decode decode)
    : files_(std::move(files)),
      loop_(loop),
      decode_(std::move(decode)),
      slots_(depth),
      free_(depth),
      ready_(depth) {
  OF_ENFORCE(decode_ != nullptr, "DecodeAhead: a decoding step is required");
  for (std::size_t k = 0; k < depth; ++k) (void)free_.try_push(static_cast<std::uint32_t>(k));
  thread_ = std::thread([this] { this->loop(); });
}

DecodeAhead::~DecodeAhead() {
  stop_.store(true);
  thread_.join();
}

void DecodeAhead::loop() noexcept {
  std::size_t next = 0;
  bool ended = false;
  while (!stop_.load()) {
    std::uint32_t k = 0;
    if (ended || !free_.try_pop(k)) {
      std::this_thread::sleep_for(POLL);
      continue;
    }
    Slot& slot = slots_[k];
    if (next == files_.size() && loop_) next = 0;
    if (next == files_.size()) {
      slot.end = true;
      ended = true;
    } else {
      try {
        slot.end = false;
        decode_(next++, slot);
      } catch (const std::exception& e) {  // std::bad_alloc: a frame error, not a dead thread
        slot.end = false;
        slot.ok = false;
        slot.error = formats::IoError{formats::IoError::Code::OPEN_FAILED,
                                      files_[next - 1].string() + ": " + e.what()};
      }
    }
    (void)ready_.try_push(k);  // never full: it holds at most the slots that left free_
  }
}

DecodeAhead::Slot* DecodeAhead::next(std::chrono::milliseconds timeout) noexcept {
  if (holding_) release();
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  std::uint32_t k = 0;
  while (!ready_.try_pop(k)) {
    if (std::chrono::steady_clock::now() >= deadline) return nullptr;
    std::this_thread::sleep_for(POLL);
  }
  held_ = k;
  holding_ = true;
  return &slots_[k];
}

void DecodeAhead::release() noexcept {
  if (!holding_) return;
  holding_ = false;
  (void)free_.try_push(held_);
}

}  // namespace orthoflow::graphs
