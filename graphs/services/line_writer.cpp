#include "graphs/services/line_writer.hpp"

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>

namespace orthoflow::graphs {

namespace {
constexpr auto POLL = std::chrono::milliseconds(5);
}

Result<std::unique_ptr<LineWriter>, std::string> LineWriter::open(const std::string& path,
                                                                  std::size_t ring_bytes) {
  if (path == "-") return std::unique_ptr<LineWriter>(new LineWriter(stdout, false, ring_bytes));
  std::FILE* file = std::fopen(path.c_str(), "w");
  if (file == nullptr)
    return err("cannot open '" + path + "' for writing: " + std::strerror(errno));
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
  // Room for the line and its newline is checked first (the consumer only frees room), so both go
  // in or neither does.
  if (ring_.capacity() - ring_.size() < line.size() + 1 ||
      !ring_.try_push_all({line.data(), line.size()}) || !ring_.try_push('\n')) {
    dropped_.fetch_add(1, std::memory_order_relaxed);
    return false;
  }
  return true;
}

// Writes out everything queued so far; true if there was something.
bool LineWriter::drain() noexcept {
  const auto [first, second] = ring_.readable();
  if (first.empty()) return false;
  bool ok = std::fwrite(first.data(), 1, first.size(), file_) == first.size();
  if (!second.empty())
    ok = ok && std::fwrite(second.data(), 1, second.size(), file_) == second.size();
  if (!ok) failed_.store(true);
  ring_.release(first.size() + second.size());
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
  while (ring_.size() != 0) std::this_thread::sleep_for(POLL);
  if (std::fflush(file_) != 0) failed_.store(true);
}

}  // namespace orthoflow::graphs
