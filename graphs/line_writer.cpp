#include "graphs/line_writer.hpp"

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>

namespace orthoflow::graphs {

namespace {
constexpr auto POLL = std::chrono::milliseconds(5);
}

Result<std::unique_ptr<LineWriter>, std::string> LineWriter::open(const std::string& path, std::size_t ring_bytes) {
  if (path == "-") return std::unique_ptr<LineWriter>(new LineWriter(stdout, false, ring_bytes));
  std::FILE* file = std::fopen(path.c_str(), "w");
  if (file == nullptr) return err("cannot open '" + path + "' for writing: " + std::strerror(errno));
  return std::unique_ptr<LineWriter>(new LineWriter(file, true, ring_bytes));
}

LineWriter::LineWriter(std::FILE* file, bool owned, std::size_t ring_bytes)
    : file_(file), owned_(owned), ring_(ring_bytes) {
  thread_ = std::thread([this] { loop(); });
}

LineWriter::~LineWriter() {
  stop_.store(true);
  thread_.join();
  if (std::fflush(file_) != 0) failed_.store(true);
  if (owned_) std::fclose(file_);
}

bool LineWriter::write(std::string_view line) noexcept {
  const std::size_t head = head_.load(std::memory_order_relaxed);
  const std::size_t used = head - tail_.load(std::memory_order_acquire);
  if (used + line.size() + 1 > ring_.size()) {
    dropped_.fetch_add(1, std::memory_order_relaxed);
    return false;
  }
  for (std::size_t i = 0; i < line.size(); ++i) ring_[(head + i) % ring_.size()] = line[i];
  ring_[(head + line.size()) % ring_.size()] = '\n';
  head_.store(head + line.size() + 1, std::memory_order_release);
  return true;
}

// Writes out everything queued so far; true if there was something.
bool LineWriter::drain() noexcept {
  const std::size_t tail = tail_.load(std::memory_order_relaxed);
  const std::size_t head = head_.load(std::memory_order_acquire);
  if (head == tail) return false;
  const std::size_t start = tail % ring_.size();
  const std::size_t first = std::min(head - tail, ring_.size() - start);
  bool ok = std::fwrite(ring_.data() + start, 1, first, file_) == first;
  if (head - tail > first) ok = ok && std::fwrite(ring_.data(), 1, head - tail - first, file_) == head - tail - first;
  if (!ok) failed_.store(true);
  tail_.store(head, std::memory_order_release);
  return true;
}

void LineWriter::loop() noexcept {
  while (true) {
    const bool stopping = stop_.load();
    if (!drain()) {
      if (stopping) return;
      std::this_thread::sleep_for(POLL);
    }
  }
}

void LineWriter::flush() noexcept {
  while (tail_.load() != head_.load()) std::this_thread::sleep_for(POLL);
  if (std::fflush(file_) != 0) failed_.store(true);
}

}  // namespace orthoflow::graphs
