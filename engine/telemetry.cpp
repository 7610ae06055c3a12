#include "engine/telemetry.hpp"

#include <algorithm>
#include <array>
#include <cstdio>
#include <nlohmann/json.hpp>

namespace orthoflow::engine {

namespace {

constexpr double Q[] = {0.5, 0.9, 0.99, 0.999};

double per_second(std::uint64_t count, std::int64_t elapsed_ns) {
  return elapsed_ns > 0 ? static_cast<double>(count) * 1e9 / static_cast<double>(elapsed_ns) : 0.0;
}

nlohmann::json histogram_json(const LatencyHistogram& h) {
  return {{"count", h.count()},
          {"p50_ns", h.percentile(0.5)},
          {"p90_ns", h.percentile(0.9)},
          {"p99_ns", h.percentile(0.99)},
          {"p999_ns", h.percentile(0.999)},
          {"max_ns", h.max()}};
}

std::string row(const std::string& name, const LatencyHistogram& h, std::uint64_t count,
                double rate, std::uint64_t drops, std::uint64_t misses,
                const LatencyHistogram* age) {
  char line[256];
  auto us = [](std::int64_t ns) { return static_cast<double>(ns) / 1e3; };
  std::snprintf(line, sizeof line,
                "%-16s %10llu %10.1f %9.1f %9.1f %9.1f %9.1f %9.1f %8llu %8llu %10.1f\n",
                name.c_str(), static_cast<unsigned long long>(count), rate, us(h.percentile(Q[0])),
                us(h.percentile(Q[1])), us(h.percentile(Q[2])), us(h.percentile(Q[3])), us(h.max()),
                static_cast<unsigned long long>(drops), static_cast<unsigned long long>(misses),
                age != nullptr ? us(age->percentile(0.5)) : 0.0);
  return line;
}

}  // namespace

std::uint64_t GraphStats::total_drops() const noexcept {
  std::uint64_t drops = source_drops.load();
  for (const auto& n : nodes) drops += n.dropped.load();
  return drops;
}

std::string format_table(const GraphStats& stats) {
  const std::int64_t elapsed = stats.elapsed_ns.load();
  std::string table =
      "node                  count      msg/s   p50(us)   p90(us)   p99(us) p99.9(us)   max(us)    "
      "drops   misses "
      "age50(us)\n";
  for (const auto& n : stats.nodes) {
    table += row(n.name, n.service, n.processed.load(), per_second(n.processed.load(), elapsed),
                 n.dropped.load(), n.deadline_misses.load(), n.sink ? &n.age : nullptr);
  }
  table += row("[graph " + stats.name + "]", stats.frame_latency, stats.frames_done.load(),
               per_second(stats.frames_done.load(), elapsed), stats.total_drops(),
               stats.deadline_misses.load(), nullptr);
  for (const auto& n : stats.nodes) {
    std::array<DeviceCounter, MAX_DEVICE_COUNTERS> counters{};
    const std::size_t k = n.device ? std::min(n.device(counters), counters.size()) : 0;
    if (k == 0) continue;
    table += n.name + " " + n.counter_group + ":";
    for (std::size_t i = 0; i < k; ++i)
      table += std::string(i == 0 ? " " : ", ") + counters[i].name + " " +
               std::to_string(counters[i].value);
    table += '\n';
  }
  return table;
}

std::string to_json(const GraphStats& stats) {
  const std::int64_t elapsed = stats.elapsed_ns.load();
  nlohmann::json nodes = nlohmann::json::array();
  for (const auto& n : stats.nodes) {
    nlohmann::json node = {{"name", n.name},
                           {"processed", n.processed.load()},
                           {"throughput_per_s", per_second(n.processed.load(), elapsed)},
                           {"dropped", n.dropped.load()},
                           {"skipped", n.skipped.load()},
                           {"deadline_misses", n.deadline_misses.load()},
                           {"max_concurrency", n.max_running.load()},
                           {"latency", histogram_json(n.service)}};
    if (n.sink) node["frame_age"] = histogram_json(n.age);
    std::array<DeviceCounter, MAX_DEVICE_COUNTERS> counters{};
    const std::size_t k = n.device ? std::min(n.device(counters), counters.size()) : 0;
    if (k > 0) {
      nlohmann::json group = nlohmann::json::object();
      for (std::size_t i = 0; i < k; ++i) group[counters[i].name] = counters[i].value;
      node[n.counter_group] = std::move(group);
    }
    nodes.push_back(std::move(node));
  }
  nlohmann::json graph = {{"name", stats.name},
                          {"period_ns", stats.period_ns},
                          {"elapsed_ns", elapsed},
                          {"frames_in", stats.frames_in.load()},
                          {"frames_done", stats.frames_done.load()},
                          {"throughput_fps", per_second(stats.frames_done.load(), elapsed)},
                          {"source_drops", stats.source_drops.load()},
                          {"drops", stats.total_drops()},
                          {"deadline_misses", stats.deadline_misses.load()},
                          {"frame_latency", histogram_json(stats.frame_latency)},
                          {"nodes", std::move(nodes)}};
  return graph.dump(2);
}

}  // namespace orthoflow::engine
