// Progress (evaluation/progress.hpp): plain lines per 10 % step, the terminal line with '\r' and
// its ETA under an injected clock, total 0, clamping past the total, and exact counting from 4
// threads.
#include "evaluation/progress.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace orthoflow::evaluation {
namespace {

// An in-memory FILE* whose contents can be read back.
class Capture {
 public:
  Capture() : file_(open_memstream(&data_, &size_)) {}
  ~Capture() {
    std::fclose(file_);
    std::free(data_);
  }
  Capture(const Capture&) = delete;
  Capture& operator=(const Capture&) = delete;
  [[nodiscard]] std::FILE* file() const { return file_; }
  [[nodiscard]] std::string text() {
    std::fflush(file_);
    return std::string(data_, size_);
  }

 private:
  char* data_ = nullptr;
  std::size_t size_ = 0;
  std::FILE* file_;
};

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);) lines.push_back(l);
  return lines;
}

TEST(Progress, PlainOutputHasOneLinePerTenPercentAndTheFinalOne) {
  Capture cap;
  double t = 0.0;
  {
    Progress p("fold", 20, cap.file(), false, [&] { return t; });
    for (int i = 0; i < 20; ++i) {
      t += 0.5;  // 0.5 s per step: elapsed = done / 2, ETA = remaining / 2
      p.advance();
    }
    p.finish();
    p.finish();  // idempotent
  }
  const std::string text = cap.text();
  EXPECT_EQ(text.find('\r'), std::string::npos);
  EXPECT_EQ(text.find('\x1b'), std::string::npos);
  const std::vector<std::string> expected{
      "fold 2/20  10%  elapsed 0:01  ETA 0:09",  "fold 4/20  20%  elapsed 0:02  ETA 0:08",
      "fold 6/20  30%  elapsed 0:03  ETA 0:07",  "fold 8/20  40%  elapsed 0:04  ETA 0:06",
      "fold 10/20  50%  elapsed 0:05  ETA 0:05", "fold 12/20  60%  elapsed 0:06  ETA 0:04",
      "fold 14/20  70%  elapsed 0:07  ETA 0:03", "fold 16/20  80%  elapsed 0:08  ETA 0:02",
      "fold 18/20  90%  elapsed 0:09  ETA 0:01", "fold 20/20 100%  elapsed 0:10"};
  EXPECT_EQ(lines_of(text), expected);
}

TEST(Progress, PlainOutputSkipsTenthsCrossedInOneStep) {
  Capture cap;
  double t = 0.0;
  Progress p("runs", 10, cap.file(), false, [&] { return t; });
  t = 1.0;
  p.advance(5);  // 0 -> 50 %: one line, not five
  t = 2.0;
  p.advance(5);  // 100 % is left to finish()
  p.finish();
  const std::vector<std::string> expected{"runs 5/10  50%  elapsed 0:01  ETA 0:01",
                                          "runs 10/10 100%  elapsed 0:02"};
  EXPECT_EQ(lines_of(cap.text()), expected);
}

TEST(Progress, TerminalRedrawsOneLineWithCarriageReturnAndEta) {
  Capture cap;
  double t = 0.0;
  Progress p("teach", 10, cap.file(), true, [&] { return t; });
  EXPECT_EQ(cap.text(), "\rteach [....................] 0/10   0%  elapsed 0:00  ETA --");
  t = 2.0;
  p.advance();  // mean rate 0.5 step/s, 9 steps left: ETA 18 s
  EXPECT_NE(cap.text().find("\rteach [##..................] 1/10  10%  elapsed 0:02  ETA 0:18"),
            std::string::npos);
  t = 2.05;
  const std::size_t before = cap.text().size();
  p.advance();  // within 0.1 s of the last draw: throttled
  EXPECT_EQ(cap.text().size(), before);
  t = 8.0;
  p.advance(2);  // 4 done in 8 s: 6 left take 12 s
  EXPECT_NE(cap.text().find("4/10  40%  elapsed 0:08  ETA 0:12"), std::string::npos);
  t = 3725.0;
  p.advance(6);
  p.finish();
  const std::string text = cap.text();
  EXPECT_EQ(text.back(), '\n');
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 1);
  const std::string final_line = "\rteach [####################] 10/10 100%  elapsed 1:02:05";
  const std::size_t at = text.rfind(final_line);
  ASSERT_NE(at, std::string::npos) << text;
  // The final line is shorter than the one it overwrites: blanks up to the old width, then the
  // newline.
  EXPECT_EQ(text.find_first_not_of(' ', at + final_line.size()), text.size() - 1);
  EXPECT_EQ(text.find('\x1b'), std::string::npos);
}

TEST(Progress, TerminalBlanksLeftoversOfALongerLine) {
  Capture cap;
  double t = 0.0;
  Progress p("x", 2, cap.file(), true, [&] { return t; });
  p.advance();  // same instant: throttled, nothing new
  t = 1.0;
  p.finish();  // "x [...] 1/2  50%  elapsed 0:01" is shorter than the line with "ETA --": padded
               // with blanks
  const std::string text = cap.text();
  const std::size_t second = text.rfind('\r');
  ASSERT_NE(second, 0u);
  EXPECT_EQ(text.size() - second - 2, second - 1);  // both lines equally wide (minus '\r' and '\n')
}

TEST(Progress, ZeroTotalDoesNotDivideByZero) {
  Capture cap;
  double t = 0.0;
  {
    Progress plain("none", 0, cap.file(), false, [&] { return t; });
    plain.advance(3);
    EXPECT_EQ(plain.done(), 0u);
  }  // the destructor writes the final line
  Progress term("none", 0, cap.file(), true, [&] { return t; });
  term.advance();
  term.finish();
  const std::string text = cap.text();
  EXPECT_NE(text.find("none 0/0 100%  elapsed 0:00\n"), std::string::npos);
  EXPECT_NE(text.find("[####################] 0/0 100%"), std::string::npos);
  EXPECT_EQ(text.find("nan"), std::string::npos);
  EXPECT_EQ(text.find("inf"), std::string::npos);
}

TEST(Progress, AdvancePastTotalClamps) {
  Capture cap;
  Progress p("clamp", 5, cap.file(), false, [] { return 0.0; });
  p.advance(3);
  p.advance(static_cast<std::size_t>(-1));  // would overflow an unchecked sum
  EXPECT_EQ(p.done(), 5u);
  p.advance();
  EXPECT_EQ(p.done(), 5u);
  p.finish();
  EXPECT_NE(cap.text().find("clamp 5/5 100%"), std::string::npos);
}

TEST(Progress, ConcurrentAdvanceCountsExactly) {
  Capture plain_cap, term_cap;
  constexpr std::size_t PER_THREAD = 5000;
  Progress plain("mt", 4 * PER_THREAD, plain_cap.file(), false);
  Progress term("mt", 4 * PER_THREAD + 7, term_cap.file(),
                true);  // real steady clock, redraws throttled
  std::vector<std::thread> workers;
  for (int w = 0; w < 4; ++w) {
    workers.emplace_back([&] {
      for (std::size_t i = 0; i < PER_THREAD; ++i) plain.advance(), term.advance();
    });
  }
  for (auto& w : workers) w.join();
  EXPECT_EQ(plain.done(), 4 * PER_THREAD);
  EXPECT_EQ(term.done(), 4 * PER_THREAD);
  plain.finish();
  term.finish();
  // At most one line per 10 % step, in increasing order (a step another thread overtook before it
  // could print is skipped), then the final line.
  const std::vector<std::string> lines = lines_of(plain_cap.text());
  ASSERT_GE(lines.size(), 1u);
  ASSERT_LE(lines.size(), 10u);
  EXPECT_EQ(lines.back().rfind("mt 20000/20000 100%  elapsed ", 0), 0u) << lines.back();
  int last_percent = 0;
  for (std::size_t k = 0; k + 1 < lines.size(); ++k) {
    const int percent = std::atoi(lines[k].substr(lines[k].find('%') - 3, 3).c_str());
    EXPECT_GT(percent, last_percent) << lines[k];
    EXPECT_LT(percent, 100) << lines[k];
    last_percent = percent;
  }
  EXPECT_NE(term_cap.text().find("20000/20007"), std::string::npos);
}

TEST(Progress, FormatDuration) {
  EXPECT_EQ(Progress::format_duration(0.0), "0:00");
  EXPECT_EQ(Progress::format_duration(59.4), "0:59");
  EXPECT_EQ(Progress::format_duration(61.0), "1:01");
  EXPECT_EQ(Progress::format_duration(3600.0), "1:00:00");
  EXPECT_EQ(Progress::format_duration(-1.0), "--");
  EXPECT_EQ(Progress::format_duration(std::numeric_limits<double>::quiet_NaN()), "--");
}

}  // namespace
}  // namespace orthoflow::evaluation
