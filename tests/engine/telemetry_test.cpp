#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <random>
#include <span>
#include <thread>
#include <vector>

#include "engine/histogram.hpp"
#include "engine/telemetry.hpp"

namespace orthoflow::engine {
namespace {

TEST(LatencyHistogram, BucketsAreMonotoneAndBoundTheValue) {
  std::size_t previous = 0;
  for (std::uint64_t v = 0; v < 100000; v += 7) {
    const std::size_t b = LatencyHistogram::bucket_of(v);
    EXPECT_GE(b, previous);
    EXPECT_LE(v, LatencyHistogram::bucket_upper(b));
    if (v >= 16) {
      EXPECT_LE(static_cast<double>(LatencyHistogram::bucket_upper(b)),
                1.125 * static_cast<double>(v) + 1);
    }
    previous = b;
  }
  EXPECT_LT(LatencyHistogram::bucket_of(~std::uint64_t{0}), LatencyHistogram::BUCKETS);
}

TEST(LatencyHistogram, PercentilesWithinStatedError) {
  LatencyHistogram h;
  EXPECT_EQ(h.percentile(0.5), 0);
  std::vector<std::int64_t> values;
  std::mt19937_64 rng(42);
  std::lognormal_distribution<double> dist(10.0, 1.0);
  for (int i = 0; i < 20000; ++i) values.push_back(static_cast<std::int64_t>(dist(rng)));
  for (auto v : values) h.record(v);
  std::sort(values.begin(), values.end());
  for (double q : {0.5, 0.9, 0.99, 0.999}) {
    const auto exact =
        values[static_cast<std::size_t>(std::ceil(q * static_cast<double>(values.size()))) - 1];
    EXPECT_EQ(exact_percentile(values, q), exact) << q;
    EXPECT_GE(h.percentile(q), exact) << q;
    EXPECT_LE(static_cast<double>(h.percentile(q)), 1.125 * static_cast<double>(exact) + 1) << q;
  }
  EXPECT_EQ(h.max(), values.back());
  EXPECT_EQ(h.percentile(1.0), values.back());
  h.record(-5);  // clock skew never underflows
  EXPECT_EQ(h.count(), 20001u);
}

TEST(LatencyHistogram, ExactPercentileIsTheNearestRank) {
  const std::vector<std::int64_t> none;
  EXPECT_EQ(exact_percentile(none, 0.99), 0);
  const std::vector<std::int64_t> one{7};
  EXPECT_EQ(exact_percentile(one, 0.0), 7);
  EXPECT_EQ(exact_percentile(one, 1.0), 7);
  std::vector<std::int64_t> hundred(100);
  for (std::size_t i = 0; i < hundred.size(); ++i) hundred[i] = static_cast<std::int64_t>(i + 1);
  EXPECT_EQ(exact_percentile(hundred, 0.0), 1);  // rank at least 1
  EXPECT_EQ(exact_percentile(hundred, 0.5), 50);
  EXPECT_EQ(exact_percentile(hundred, 0.99), 99);
  EXPECT_EQ(exact_percentile(hundred, 0.991), 100);
  EXPECT_EQ(exact_percentile(hundred, 1.0), 100);
  EXPECT_EQ(exact_percentile(hundred, -1.0), 1);  // clamped
  EXPECT_EQ(exact_percentile(hundred, 2.0), 100);
}

TEST(LatencyHistogram, ConcurrentRecordingLosesNothing) {
  LatencyHistogram h;
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t) {
    threads.emplace_back([&h, t] {
      for (int i = 0; i < 50000; ++i) h.record(i * (t + 1));
    });
  }
  for (auto& t : threads) t.join();
  EXPECT_EQ(h.count(), 200000u);
  EXPECT_EQ(h.max(), 49999 * 4);
}

TEST(Telemetry, TableAndJsonCarryTheCounters) {
  GraphStats stats;
  stats.name = "g";
  stats.period_ns = 1000;
  auto& node = stats.nodes.emplace_back();
  node.name = "worker";
  node.sink = true;
  node.processed = 10;
  node.dropped = 3;
  node.deadline_misses = 2;
  node.service.record(5000);
  node.age.record(7000);
  stats.source_drops = 1;
  stats.frames_done = 10;
  stats.elapsed_ns = 1'000'000'000;
  const auto json = nlohmann::json::parse(to_json(stats));
  EXPECT_EQ(json["nodes"][0]["dropped"], 3);
  EXPECT_EQ(json["nodes"][0]["deadline_misses"], 2);
  EXPECT_EQ(json["nodes"][0]["frame_age"]["max_ns"], 7000);
  EXPECT_EQ(json["drops"], 4);
  EXPECT_DOUBLE_EQ(json["throughput_fps"].get<double>(), 10.0);
  const std::string table = format_table(stats);
  EXPECT_NE(table.find("worker"), std::string::npos);
  EXPECT_NE(table.find("p99.9"), std::string::npos);
  EXPECT_EQ(table.find("device:"), std::string::npos);  // no device behind this node
  EXPECT_FALSE(json["nodes"][0].contains("device"));
}

TEST(Telemetry, DeviceCountersAppearUnderTheirNode) {
  GraphStats stats;
  stats.name = "g";
  auto& node = stats.nodes.emplace_back();
  node.name = "source";
  std::uint64_t lost = 7;
  node.device = [&lost](std::span<DeviceCounter> out) {
    const DeviceCounter all[] = {{"lost_packets", lost}, {"reopens", 1}};
    std::size_t k = 0;
    for (const auto& c : all) {
      if (k < out.size()) out[k++] = c;
    }
    return k;
  };
  auto json = nlohmann::json::parse(to_json(stats));
  EXPECT_EQ(json["nodes"][0]["device"]["lost_packets"], 7);
  EXPECT_EQ(json["nodes"][0]["device"]["reopens"], 1);
  lost = 9;  // read at export time: a live count
  json = nlohmann::json::parse(to_json(stats));
  EXPECT_EQ(json["nodes"][0]["device"]["lost_packets"], 9);
  EXPECT_NE(format_table(stats).find("source device: lost_packets 9, reopens 1"),
            std::string::npos);
}

}  // namespace
}  // namespace orthoflow::engine
