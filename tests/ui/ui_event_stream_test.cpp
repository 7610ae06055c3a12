// EventStream (ui/ui_event_stream.hpp) without sockets: each client gets documents at the rate it
// chose, never above the cap; a full stream refuses a client; a removed client gets nothing more.
#include "ui/ui_event_stream.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <atomic>
#include <chrono>
#include <map>
#include <mutex>
#include <thread>

namespace orthoflow::ui {
namespace {

class CountingBackend : public UiBackend {
 public:
  UiSnapshot snapshot() const override {
    UiSnapshot s;
    s.frame_id = ++snapshots;
    return s;
  }
  UiAnswer submit(const UiAction&, int) override { return {}; }
  void want_camera() override { ++camera_wanted; }
  mutable std::atomic<std::uint64_t> snapshots{0};
  std::atomic<std::uint64_t> camera_wanted{0};
};

struct Received {
  std::mutex lock;
  std::map<void*, int> count;
  std::string last;
};

TEST(EventStream, EachClientAtItsRateCappedAtTheFrameRate) {
  CountingBackend backend;
  Received got;
  int slow = 0, fast = 0, broken = 0;
  EventStream stream(backend, /*max_hz=*/20.0, /*max_clients=*/3,
                     [&](void* client, std::string_view text) {
                       std::lock_guard<std::mutex> guard(got.lock);
                       ++got.count[client];
                       got.last = std::string(text);
                       return client != &broken;
                     });
  EXPECT_DOUBLE_EQ(stream.clamp(1000.0), 20.0);
  EXPECT_DOUBLE_EQ(stream.clamp(5.0), 5.0);
  ASSERT_TRUE(stream.add(&slow, 4.0));
  ASSERT_TRUE(stream.add(&fast, 1000.0));  // asks for more than the frames give
  ASSERT_TRUE(stream.add(&broken, 20.0));
  EXPECT_FALSE(stream.add(&slow, 1.0));  // full
  std::this_thread::sleep_for(std::chrono::milliseconds(1000));
  stream.remove(&fast);
  std::map<void*, int> after_remove;
  {
    std::lock_guard<std::mutex> guard(got.lock);
    after_remove = got.count;
    EXPECT_EQ(nlohmann::json::parse(got.last)["objects"].size(), 0U);  // a whole state document
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  std::lock_guard<std::mutex> guard(got.lock);
  // 1 s: at most 1 + rate documents (the first goes out at once); at least one.
  EXPECT_GE(after_remove[&slow], 1);
  EXPECT_LE(after_remove[&slow], 5 + 1);
  EXPECT_GE(after_remove[&fast], 1);
  EXPECT_LE(after_remove[&fast], 21 + 1);
  EXPECT_GT(after_remove[&fast], after_remove[&slow]);
  EXPECT_EQ(got.count[&fast], after_remove[&fast]);  // removed: nothing more
  EXPECT_EQ(got.count[&broken], 1);                  // a failed write is not retried
  EXPECT_EQ(stream.clients(), 2U);
}

// A client that shows the camera keeps the backend drawing images: want_camera() before each of
// its documents; a client without the camera asks for none.
TEST(EventStream, OnlyCameraClientsKeepTheCameraWanted) {
  CountingBackend backend;
  std::atomic<int> written{0};
  int plain = 0, viewer = 0;
  EventStream stream(backend, 20.0, 2, [&](void*, std::string_view) {
    ++written;
    return true;
  });
  ASSERT_TRUE(stream.add(&plain, 20.0));
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  EXPECT_GT(written.load(), 0);
  EXPECT_EQ(backend.camera_wanted.load(), 0U);
  ASSERT_TRUE(stream.add(&viewer, 10.0, /*camera=*/true));
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  EXPECT_GE(backend.camera_wanted.load(), 1U);
  stream.remove(&viewer);
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  const std::uint64_t after = backend.camera_wanted.load();
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  EXPECT_EQ(backend.camera_wanted.load(), after);  // only the plain client is left
}

}  // namespace
}  // namespace orthoflow::ui
