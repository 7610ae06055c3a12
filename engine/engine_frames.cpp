// The engine's frame path (Engine::Impl, engine/engine_impl.hpp): admission hands out the
// max_in_flight tokens, the pacer thread holds early ones until the next tick, routing counts every
// message of a frame in its slot, and the last message consumed completes the frame and returns
// its token. Construction of the flow graph is in engine.cpp.
#include <algorithm>
#include <chrono>
#include <mutex>
#include <thread>

#include "engine/engine_impl.hpp"

namespace orthoflow::engine {

namespace {

using detail::now_ns;

}  // namespace

bool Engine::Impl::should_stop() const noexcept {
  return stop_requested.load(std::memory_order_relaxed) ||
         (external_stop != nullptr && external_stop->load(std::memory_order_relaxed));
}

// Admission (the limiter): exactly max_in_flight tokens circulate. run() puts them all into
// this serial node; each completed frame puts its token back (done()). A token either becomes
// the next frame (paced at the graph period) or is retired when the run is stopping, so frames in
// flight never exceed the pool's blocks and the source never takes a block it cannot use yet.
void Engine::Impl::admit(std::uint32_t token) noexcept {
  if (max_frames > 0 && next_frame >= max_frames && reason == StopReason::SOURCE_END) {
    reason = StopReason::FRAME_LIMIT;
  }
  if (reason == StopReason::SOURCE_END && should_stop()) reason = StopReason::STOP_REQUESTED;
  if (reason != StopReason::SOURCE_END || source_ended) return;  // token retired
  if (graph.spec.period_ns > 0 && now_ns() < next_tick_ns.load(std::memory_order_relaxed)) {
    park(token);  // too early: the pacer thread gives it back at the next tick
    return;
  }
  Message m;
  const std::int64_t start = now_ns();
  if (graph.nodes[graph.source]->produce(m) == SourceStatus::END) {
    source_ended = true;
    return;
  }
  next_tick_ns.store(
      std::max(next_tick_ns.load(std::memory_order_relaxed) + graph.spec.period_ns, now_ns()),
      std::memory_order_relaxed);
  NodeStats& source_stats = *runtimes[graph.source]->stats;
  source_stats.processed.fetch_add(1, std::memory_order_relaxed);
  source_stats.service.record(now_ns() - start);
  m.frame_id = next_frame++;
  m.stamp_ns = now_ns();
  m.slot = token;
  FrameSlot& slot = slots[token];
  slot.stamp_ns = m.stamp_ns;
  slot.pending.store(1, std::memory_order_relaxed);  // the dispatcher's own hold, released below
  stats.frames_in.fetch_add(1, std::memory_order_relaxed);
  if (m.skipped) stats.source_drops.fetch_add(1, std::memory_order_relaxed);
  NodeRuntime& source = *runtimes[graph.source];
  for (std::size_t port = 0; port < source.out.size(); ++port) send(source, port, m);
  m.payload.reset();
  done(m.slot);
}

void Engine::Impl::park(std::uint32_t token) noexcept {
  g->reserve_wait();  // keeps wait_for_all() from returning while the token is parked
  {
    const std::lock_guard<std::mutex> lock(park_mutex);
    parked.push_back(token);  // never reallocates: at most max_in_flight tokens exist
  }
  park_cv.notify_one();
}

void Engine::Impl::pace() {
  std::unique_lock<std::mutex> lock(park_mutex);
  while (true) {
    park_cv.wait(lock, [this] { return pacer_exit || !parked.empty(); });
    if (parked.empty()) return;
    Message token;
    token.slot = parked.back();
    parked.pop_back();
    lock.unlock();
    // Sleep in short slices so a stop request is seen within ~2 ms.
    while (now_ns() < next_tick_ns.load(std::memory_order_relaxed) && !should_stop()) {
      const std::int64_t left_us =
          (next_tick_ns.load(std::memory_order_relaxed) - now_ns()) / 1000 + 1;
      std::this_thread::sleep_for(std::chrono::microseconds(std::min<std::int64_t>(2000, left_us)));
    }
    dispatch->try_put(token);
    g->release_wait();
    lock.lock();
  }
}

void Engine::Impl::send(NodeRuntime& from, std::size_t port, const Message& message) noexcept {
  for (const Target& t : from.out[port]) {
    NodeRuntime& to = *runtimes[t.node];
    slots[message.slot].pending.fetch_add(1, std::memory_order_relaxed);
    if (to.policy == Policy::LATEST) {
      std::uint64_t seen = to.newest.load(std::memory_order_relaxed);
      while (message.frame_id > seen && !to.newest.compare_exchange_weak(seen, message.frame_id)) {}
    }
    Message copy = message;
    copy.port = t.port;
    to.entry->try_put(copy);
  }
}

void Engine::Impl::forward_tombstone(NodeRuntime& rt, const Message& m) noexcept {
  Message tomb = m;
  tomb.skipped = true;
  tomb.payload.reset();
  for (std::size_t port = 0; port < rt.out.size(); ++port) send(rt, port, tomb);
}

void Engine::Impl::run_node(NodeRuntime& rt, const Message& m) noexcept {
  const std::int64_t start = now_ns();
  if ((m.skipped || m.object_count == 0) && !rt.node->wants_skipped()) {
    // Tombstones and empty frames (no objects) flow through untouched so joins and sequencers
    // downstream still see exactly one message per frame.
    rt.stats->skipped.fetch_add(1, std::memory_order_relaxed);
    for (std::size_t port = 0; port < rt.out.size(); ++port) send(rt, port, m);
  } else if (rt.policy == Policy::LATEST &&
             m.frame_id < rt.newest.load(std::memory_order_relaxed)) {
    rt.stats->dropped.fetch_add(1, std::memory_order_relaxed);  // a newer frame is already queued
    forward_tombstone(rt, m);
  } else {
    Router router(this, &rt, &m);
    // Concurrency gauge: shows per-object work really runs in parallel (telemetry, tests).
    const std::uint32_t running = rt.stats->running.fetch_add(1, std::memory_order_relaxed) + 1;
    std::uint32_t seen = rt.stats->max_running.load(std::memory_order_relaxed);
    while (running > seen && !rt.stats->max_running.compare_exchange_weak(seen, running)) {}
    rt.node->process(m, router);
    rt.stats->running.fetch_sub(1, std::memory_order_relaxed);
    const std::int64_t end = now_ns();
    rt.stats->processed.fetch_add(1, std::memory_order_relaxed);
    rt.stats->service.record(end - start);
    if (rt.deadline_ns > 0 && end - start > rt.deadline_ns) rt.stats->deadline_misses.fetch_add(1);
    if (rt.stats->sink) rt.stats->age.record(end - m.stamp_ns);
  }
  // TBB hands the body a reference to its own non-const copy (held by the task or buffer);
  // releasing the block here, before the frame can complete, guarantees admission never
  // admits a frame while the previous frame's block is still held by a finishing task.
  const_cast<Message&>(m).payload.reset();
  done(m.slot);
}

// Called once per consumed message; the call that takes the count to zero completes the frame.
void Engine::Impl::done(std::uint32_t slot_index) noexcept {
  FrameSlot& slot = slots[slot_index];
  if (slot.pending.fetch_sub(1, std::memory_order_acq_rel) != 1) return;
  const std::int64_t latency = now_ns() - slot.stamp_ns;
  stats.frame_latency.record(latency);
  if (graph.spec.period_ns > 0 && latency > graph.spec.period_ns)
    stats.deadline_misses.fetch_add(1);
  const std::uint64_t k = stats.frames_done.fetch_add(1, std::memory_order_relaxed);
  if (k < latency_trace.size()) latency_trace[k] = latency;
  Message token;
  token.slot = slot_index;
  dispatch->try_put(token);  // hand the token back: the next frame may start
}

}  // namespace orthoflow::engine
