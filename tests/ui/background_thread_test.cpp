// The web view's threads run at nice 19 (ui/background_thread.hpp): the helper lowers only the
// calling thread, and every thread a running server starts (civetweb's master and workers, the
// event stream) is lowered, while the thread that started it keeps its priority.
#include "ui/background_thread.hpp"

#include <gtest/gtest.h>
#include <sys/resource.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <thread>

#include "ui/ui_server.hpp"

namespace orthoflow::ui {
namespace {

// The thread ids of this process, from /proc/self/task.
std::set<long> thread_ids() {
  std::set<long> ids;
  for (const auto& entry : std::filesystem::directory_iterator("/proc/self/task"))
    ids.insert(std::strtol(entry.path().filename().c_str(), nullptr, 10));
  return ids;
}

// Field 19 of /proc/self/task/TID/stat: the thread's nice value (after the parenthesised name).
int nice_of(long tid) {
  std::ifstream in("/proc/self/task/" + std::to_string(tid) + "/stat");
  std::string stat((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::istringstream fields(stat.substr(stat.rfind(')') + 2));
  std::string field;
  for (int k = 3; k <= 19 && fields >> field; ++k) {}
  return std::stoi(field);
}

class NoBackend : public UiBackend {
 public:
  UiSnapshot snapshot() const override { return {}; }
  UiAnswer submit(const UiAction&, int) override { return {}; }
  std::string camera_png() override { return {}; }
};

TEST(BackgroundThread, LowersOnlyTheCallingThread) {
  const int before = this_thread_nice();
  int inside = 0;
  bool ok = false;
  std::thread([&] {
    ok = make_this_thread_background();
    inside = this_thread_nice();
  }).join();
  EXPECT_TRUE(ok);
  EXPECT_EQ(inside, 19);
  EXPECT_EQ(this_thread_nice(), before);
}

TEST(BackgroundThread, EveryServerThreadRunsAtNiceNineteen) {
  const int mine = this_thread_nice();
  ASSERT_LT(mine, 19) << "the test process already runs at nice 19: nothing to tell apart";
  const std::set<long> before = thread_ids();
  NoBackend backend;
  auto server = UiServer::start(UiServerConfig{}, backend);
  ASSERT_TRUE(server) << server.error();
  // civetweb starts its workers asynchronously; each lowers itself first thing.
  std::set<long> started;
  for (int wait = 0; wait < 200; ++wait) {
    started.clear();
    bool all_lowered = true;
    for (const long tid : thread_ids()) {
      if (before.count(tid) != 0) continue;
      started.insert(tid);
      all_lowered = all_lowered && nice_of(tid) == 19;
    }
    if (started.size() >= 3 && all_lowered) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ASSERT_GE(started.size(), 3U);  // the event stream, civetweb's master and its workers
  for (const long tid : started) EXPECT_EQ(nice_of(tid), 19) << "thread " << tid;
  EXPECT_EQ(this_thread_nice(), mine);
}

}  // namespace
}  // namespace orthoflow::ui
