// Round trip between two processes: iceoryx (engine::IpcPublisher/IpcSubscriber, zero copy: the
// payload is loaned and published, the receiver reads the header in place) vs a Unix-domain stream
// socket (the payload is copied into the kernel and out again). Each round trip sends one payload
// (64 B, 1.2 MB, a 640x480 RGB+label frame) and waits for a 64 B acknowledgement. The program
// starts its own RouDi (config/roudi_bench.toml) in a private mount namespace (root or
// CAP_SYS_ADMIN). Shape after iceoryx_examples/iceperf: fork, busy-poll, percentiles. Run:
// build/bench/engine/ipc_bench
#include <sched.h>
#include <signal.h>
#include <sys/mount.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <thread>
#include <vector>

#include "engine/frame_payload.hpp"
#include "engine/ipc_pubsub.hpp"

namespace {

using namespace orthoflow::engine;
using Clock = std::chrono::steady_clock;

constexpr std::uint64_t STOP = UINT64_MAX;  // sequence number that ends a server
constexpr std::size_t ACK_BYTES = 64;
const IpcPayloadType PING_TYPE{FRAME_TYPE_ID, FRAME_VERSION};

struct Case {
  const char* name;
  std::size_t bytes;
  int rounds;
};

// The common payload header: type id, version, sequence at 8, payload_bytes at 48.
void write_header(std::byte* p, std::uint64_t sequence, std::uint64_t bytes) {
  std::memcpy(p, &PING_TYPE.type_id, 4);
  std::memcpy(p + 4, &PING_TYPE.version, 2);
  std::memcpy(p + 8, &sequence, 8);
  std::memcpy(p + PAYLOAD_BYTES_OFFSET, &bytes, 8);
}
std::uint64_t sequence_of(const std::byte* p) {
  std::uint64_t s = 0;
  std::memcpy(&s, p + 8, 8);
  return s;
}
std::uint64_t bytes_of(const std::byte* p) {
  std::uint64_t b = 0;
  std::memcpy(&b, p + PAYLOAD_BYTES_OFFSET, 8);
  return b;
}

[[noreturn]] void die(const char* what, const std::string& why) {
  std::fprintf(stderr, "ipc_bench: %s: %s\n", what, why.c_str());
  std::exit(1);
}

bool io_all(int fd, std::byte* p, std::size_t n, bool write) {
  while (n > 0) {
    const ssize_t k = write ? ::write(fd, p, n) : ::read(fd, p, n);
    if (k <= 0) return false;
    p += k;
    n -= static_cast<std::size_t>(k);
  }
  return true;
}

// ---- Unix-domain socket transport: a copying server.
void uds_server(int fd, std::size_t max_bytes) {
  std::vector<std::byte> buffer(max_bytes), ack(ACK_BYTES);
  while (io_all(fd, buffer.data(), PAYLOAD_HEADER_BYTES, false)) {
    const std::uint64_t bytes = bytes_of(buffer.data());
    if (bytes > max_bytes ||
        !io_all(fd, buffer.data() + PAYLOAD_HEADER_BYTES, bytes - PAYLOAD_HEADER_BYTES, false))
      break;
    if (sequence_of(buffer.data()) == STOP) break;
    write_header(ack.data(), sequence_of(buffer.data()), ACK_BYTES);
    if (!io_all(fd, ack.data(), ACK_BYTES, true)) break;
  }
  ::_exit(0);
}

std::vector<double> uds_round_trips(int fd, const Case& c, std::vector<std::byte>& payload) {
  std::vector<double> us;
  std::byte ack[ACK_BYTES];
  for (int i = -50; i < c.rounds; ++i) {
    const auto start = Clock::now();
    write_header(payload.data(), static_cast<std::uint64_t>(i + 50), c.bytes);
    if (!io_all(fd, payload.data(), c.bytes, true) || !io_all(fd, ack, ACK_BYTES, false))
      die("uds", "peer gone");
    if (i >= 0)
      us.push_back(std::chrono::duration<double, std::micro>(Clock::now() - start).count());
  }
  return us;
}

// ---- iceoryx transport: busy-polling echo server replying with a 64 B loaned ack.
std::pair<std::unique_ptr<IpcPublisher>, std::unique_ptr<IpcSubscriber>> endpoints(
    const char* name, const char* out, const char* in, std::size_t max_out) {
  if (auto init = init_ipc_runtime(name); !init) die("init", to_string(init.error()));
  auto pools = load_roudi_pools(ORTHOFLOW_SOURCE_DIR "/config/roudi_bench.toml");
  if (!pools) die("pools", to_string(pools.error()));
  auto pub = IpcPublisher::create(*parse_topic(out),
                                  IpcPublisherConfig{PING_TYPE, max_out, 0, false}, *pools);
  auto sub = IpcSubscriber::create(*parse_topic(in),
                                   IpcSubscriberConfig{PING_TYPE, IpcPolicy::QUEUE, 4, 0});
  if (!pub || !sub) die("endpoints", to_string(pub ? sub.error() : pub.error()));
  return {std::move(*pub), std::move(*sub)};
}

std::optional<IpcSample> spin_take(IpcSubscriber& sub) {
  for (std::uint64_t spins = 0;; ++spins) {
    auto taken = sub.take();
    if (!taken) die("take", to_string(taken.error()));
    if (taken->has_value()) return std::move(*taken);
    if ((spins & 0xFFFF) == 0xFFFF && !probe_roudi()) die("take", "RouDi lost");
    // Idle for long (the other transport is being measured): stop burning one of the two cores.
    if (spins > 200000) std::this_thread::sleep_for(std::chrono::microseconds(100));
  }
}

void send_small(IpcPublisher& pub, std::uint64_t sequence) {
  auto chunk = pub.loan(ACK_BYTES);
  if (!chunk) die("loan", to_string(chunk.error()));
  write_header(chunk->data(), sequence, ACK_BYTES);
  if (auto sent = pub.publish(*chunk); !sent) die("publish", to_string(sent.error()));
}

void iox_server() {
  auto [pub, sub] = endpoints("ipc_bench_server", "bench/ipc/pong", "bench/ipc/ping", ACK_BYTES);
  for (;;) {
    auto sample = spin_take(*sub);
    const std::uint64_t sequence = sequence_of(sample->bytes().data());
    sample->reset();
    if (sequence == STOP) break;
    send_small(*pub, sequence);
  }
  pub.reset();
  sub.reset();
  ::_exit(0);
}

std::vector<double> iox_round_trips(IpcPublisher& pub, IpcSubscriber& sub, const Case& c) {
  std::vector<double> us;
  for (int i = -50; i < c.rounds; ++i) {
    const auto start = Clock::now();
    auto chunk = pub.loan(c.bytes);
    if (!chunk) die("loan", to_string(chunk.error()));
    write_header(chunk->data(), static_cast<std::uint64_t>(i + 50), c.bytes);
    if (auto sent = pub.publish(*chunk); !sent) die("publish", to_string(sent.error()));
    auto ack = spin_take(sub);
    if (sequence_of(ack->bytes().data()) != static_cast<std::uint64_t>(i + 50))
      die("ack", "out of order");
    if (i >= 0)
      us.push_back(std::chrono::duration<double, std::micro>(Clock::now() - start).count());
  }
  return us;
}

// ---- set-up: private mounts, RouDi, percentiles.
pid_t start_roudi() {
  if (::unshare(CLONE_NEWNS) != 0 ||
      ::mount(nullptr, "/", nullptr, MS_REC | MS_PRIVATE, nullptr) != 0 ||
      ::mount("tmpfs", "/dev/shm", "tmpfs", 0, "mode=1777") != 0 ||
      ::mount("tmpfs", "/tmp", "tmpfs", 0, "mode=1777") != 0) {
    die("private mount namespace (needs root or CAP_SYS_ADMIN)", std::strerror(errno));
  }
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);
    ::setsid();
    std::freopen("/dev/null", "r", stdin);
    std::freopen("/tmp/roudi.log", "w", stdout);
    std::freopen("/tmp/roudi.log", "a", stderr);
    ::execl("/usr/bin/iox-roudi", "iox-roudi", "-c",
            ORTHOFLOW_SOURCE_DIR "/config/roudi_bench.toml", nullptr);
    ::_exit(127);
  }
  for (int i = 0; i < 1000 && !probe_roudi(); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  if (!probe_roudi()) die("RouDi", "not reachable within 5 s");
  return pid;
}

double percentile(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<std::size_t>(q * static_cast<double>(v.size())))];
}

}  // namespace

int main() {
  const std::size_t frame = frame_payload_bytes(640, 480, FRAME_FIELD_RGB | FRAME_FIELD_LABEL);
  const std::vector<Case> cases{
      {"64 B", 64, 5000}, {"1.2 MB", 1200000, 1000}, {"640x480 frame", frame, 1000}};
  int fds[2];
  if (::socketpair(AF_UNIX, SOCK_STREAM, 0, fds) != 0) die("socketpair", std::strerror(errno));
  if (::fork() == 0) {
    ::close(fds[0]);
    uds_server(fds[1], frame);
  }
  ::close(fds[1]);
  const pid_t roudi = start_roudi();
  const pid_t server = ::fork();
  if (server == 0) iox_server();
  auto [pub, sub] = endpoints("ipc_bench_client", "bench/ipc/ping", "bench/ipc/pong", frame);
  const auto until = Clock::now() + std::chrono::seconds(5);
  while (!(pub->has_subscribers() && sub->subscribed()) && Clock::now() < until)
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  if (!pub->has_subscribers() || !sub->subscribed())
    die("connect", "server not connected within 5 s");
  std::vector<std::byte> payload(frame);
  std::printf(
      "| payload | bytes | rounds | iceoryx p50 / p99 / p99.9 us | UDS p50 / p99 / p99.9 us | UDS "
      "/ iceoryx p50 / p99 / p99.9 |\n|---|---|---|---|---|---|\n");
  for (const Case& c : cases) {
    const auto iox = iox_round_trips(*pub, *sub, c);
    const auto uds = uds_round_trips(fds[0], c, payload);
    double q[3] = {0.5, 0.99, 0.999}, a[3], b[3];
    for (int k = 0; k < 3; ++k) a[k] = percentile(iox, q[k]), b[k] = percentile(uds, q[k]);
    std::printf(
        "| %s | %zu | %d | %.1f / %.1f / %.1f | %.1f / %.1f / %.1f | %.1fx / %.1fx / %.1fx |\n",
        c.name, c.bytes, c.rounds, a[0], a[1], a[2], b[0], b[1], b[2], b[0] / a[0], b[1] / a[1],
        b[2] / a[2]);
  }
  write_header(payload.data(), STOP, PAYLOAD_HEADER_BYTES);
  io_all(fds[0], payload.data(), PAYLOAD_HEADER_BYTES, true);
  auto stop = pub->loan(ACK_BYTES);
  if (stop) write_header(stop->data(), STOP, ACK_BYTES), (void)pub->publish(*stop);
  ::waitpid(server, nullptr, 0);
  // RouDi (PR_SET_PDEATHSIG) is killed when this process exits, after the runtime has unregistered.
  (void)roudi;
  return 0;
}
