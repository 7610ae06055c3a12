#include "engine/ipc_runtime.hpp"

#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstring>
#include <mutex>
#include <thread>

#include "iceoryx_posh/iceoryx_posh_config.hpp"
#include "iceoryx_posh/mepoo/chunk_header.hpp"
#include "iceoryx_posh/mepoo/chunk_settings.hpp"
#include "iceoryx_posh/popo/subscriber.hpp"
#include "iceoryx_posh/roudi/introspection_types.hpp"
#include "iceoryx_posh/roudi/roudi_config_toml_file_provider.hpp"
#include "iceoryx_posh/runtime/posh_runtime.hpp"

namespace orthoflow::engine {

namespace {

// iceoryx allows one runtime per process (PoshRuntime is a process singleton), so its name and the
// "RouDi lost" flag are process-wide too; they are written at start-up or set once, never reset.
std::mutex runtime_mutex;
std::string runtime_name;
std::atomic<bool> runtime_ready{false};
std::atomic<bool> roudi_lost{false};

IpcError make_error(IpcError::Code code, std::string message) {
  return IpcError{code, std::move(message)};
}

bool valid_name(std::string_view name) {
  if (name.empty() || name.size() > 100) return false;
  return std::all_of(name.begin(), name.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
           c == '-' || c == '.';
  });
}

IpcPools pools_of(const iox::RouDiConfig_t& config) {
  IpcPools pools;
  for (const auto& segment : config.m_sharedMemorySegments) {
    for (const auto& entry : segment.m_mempoolConfig.m_mempoolConfig) {
      pools.push_back(IpcPool{entry.m_size, entry.m_chunkCount});
    }
  }
  return pools;
}

std::string_view parse_error_name(iox::roudi::RouDiConfigFileParseError error) {
  const auto index = static_cast<std::size_t>(error);
  constexpr std::size_t count = sizeof(iox::roudi::ROUDI_CONFIG_FILE_PARSE_ERROR_STRINGS) /
                                sizeof(iox::roudi::ROUDI_CONFIG_FILE_PARSE_ERROR_STRINGS[0]);
  return index < count ? iox::roudi::ROUDI_CONFIG_FILE_PARSE_ERROR_STRINGS[index] : "UNKNOWN";
}

}  // namespace

std::string_view to_string(IpcError::Code code) noexcept {
  switch (code) {
    case IpcError::Code::ROUDI_UNREACHABLE:
      return "ROUDI_UNREACHABLE";
    case IpcError::Code::ROUDI_LOST:
      return "ROUDI_LOST";
    case IpcError::Code::RUNTIME_NAME:
      return "RUNTIME_NAME";
    case IpcError::Code::BAD_TOPIC:
      return "BAD_TOPIC";
    case IpcError::Code::CONFIG:
      return "CONFIG";
    case IpcError::Code::NO_POOL_INFO:
      return "NO_POOL_INFO";
    case IpcError::Code::NO_FITTING_POOL:
      return "NO_FITTING_POOL";
    case IpcError::Code::POOL_EXHAUSTED:
      return "POOL_EXHAUSTED";
    case IpcError::Code::TOO_MANY_LOANS:
      return "TOO_MANY_LOANS";
    case IpcError::Code::WRONG_TYPE:
      return "WRONG_TYPE";
    case IpcError::Code::WRONG_VERSION:
      return "WRONG_VERSION";
    case IpcError::Code::BAD_SIZE:
      return "BAD_SIZE";
  }
  return "UNKNOWN";
}

std::string to_string(const IpcError& error) {
  return std::string(to_string(error.code)) + ": " + error.message;
}

Result<void, IpcError> probe_roudi() noexcept {
  // RouDi binds a SOCK_DGRAM unix socket at /tmp/roudi; connect() on a datagram socket only checks
  // that a live process is bound there (ENOENT: never started, ECONNREFUSED: died without cleanup).
  const int fd = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return err(IpcError{IpcError::Code::ROUDI_UNREACHABLE, {}});
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  std::memcpy(address.sun_path, ROUDI_SOCKET_PATH.data(), ROUDI_SOCKET_PATH.size());
  const int rc = ::connect(fd, reinterpret_cast<const sockaddr*>(&address), sizeof(address));
  const int error = errno;
  ::close(fd);
  if (rc == 0) return {};
  try {
    return err(
        make_error(IpcError::Code::ROUDI_UNREACHABLE,
                   "no RouDi on " + std::string(ROUDI_SOCKET_PATH) + " (" + std::strerror(error) +
                       "): start it with `iox-roudi -c config.toml` (see `orthoflow ipc config`)"));
  } catch (...) {  // out of memory while formatting: still report the code
    return err(IpcError{IpcError::Code::ROUDI_UNREACHABLE, {}});
  }
}

Result<void, IpcError> init_ipc_runtime(std::string_view app_name) {
  const std::lock_guard<std::mutex> lock(runtime_mutex);
  if (!valid_name(app_name)) {
    return err(make_error(
        IpcError::Code::RUNTIME_NAME,
        "runtime name '" + std::string(app_name) + "': 1..100 characters of [A-Za-z0-9_.-]"));
  }
  if (runtime_ready.load()) {
    if (runtime_name == app_name) return {};
    return err(make_error(IpcError::Code::RUNTIME_NAME,
                          "this process is already registered with RouDi as '" + runtime_name +
                              "', cannot register as '" + std::string(app_name) + "'"));
  }
  if (auto probe = probe_roudi(); !probe) return probe;
  iox::RuntimeName_t name(iox::cxx::TruncateToCapacity, app_name.data(), app_name.size());
  iox::runtime::PoshRuntime::initRuntime(name);
  runtime_name = std::string(app_name);
  runtime_ready.store(true);
  return {};
}

bool ipc_runtime_ready() noexcept { return runtime_ready.load(); }
bool ipc_roudi_lost() noexcept { return roudi_lost.load(std::memory_order_relaxed); }
void mark_roudi_lost() noexcept { roudi_lost.store(true, std::memory_order_relaxed); }

Result<IpcPools, IpcError> load_roudi_pools(const std::string& path) {
  iox::config::CmdLineArgs_t args;
  if (!path.empty()) {
    struct stat info {};
    if (::stat(path.c_str(), &info) != 0 || !S_ISREG(info.st_mode)) {
      return err(
          make_error(IpcError::Code::CONFIG, "RouDi config '" + path + "': not a readable file"));
    }
    if (path.size() > iox::roudi::ConfigFilePathString_t::capacity()) {
      return err(make_error(IpcError::Code::CONFIG,
                            "RouDi config '" + path + "': path too long for iceoryx"));
    }
    args.configFilePath =
        iox::roudi::ConfigFilePathString_t(iox::cxx::TruncateToCapacity, path.c_str());
  } else {
    return default_roudi_pools();
  }
  iox::config::TomlRouDiConfigFileProvider provider(args);
  auto parsed = provider.parse();
  if (parsed.has_error()) {
    return err(make_error(
        IpcError::Code::CONFIG,
        "RouDi config '" + path + "': " + std::string(parse_error_name(parsed.get_error()))));
  }
  return pools_of(parsed.value());
}

IpcPools default_roudi_pools() {
  iox::RouDiConfig_t config;
  config.setDefaults();
  return pools_of(config);
}

Result<IpcPools, IpcError> query_roudi_pools(std::chrono::milliseconds timeout) {
  if (!ipc_runtime_ready())
    return err(make_error(IpcError::Code::NO_POOL_INFO, "IPC runtime not initialised"));
  iox::popo::SubscriberOptions options;
  options.queueCapacity = 1;
  options.historyRequest = 1;
  iox::popo::Subscriber<iox::roudi::MemPoolIntrospectionInfoContainer> subscriber(
      iox::roudi::IntrospectionMempoolService, options);
  const auto until = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < until) {
    IpcPools pools;
    bool got = false;
    subscriber.take().and_then([&](const auto& sample) {
      got = true;
      // Entry 0 describes RouDi's own introspection memory; user pools follow, one entry per
      // segment.
      for (std::size_t s = 1; s < sample->size(); ++s) {
        for (const auto& info : (*sample)[s].m_mempoolInfo)
          pools.push_back(IpcPool{info.m_chunkPayloadSize, info.m_numChunks});
      }
    });
    if (got) return pools;
    if (!probe_roudi()) {
      mark_roudi_lost();
      return err(
          make_error(IpcError::Code::ROUDI_LOST, "RouDi disappeared while its pools were queried"));
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return err(
      make_error(IpcError::Code::NO_POOL_INFO, "RouDi published no MemPool introspection within " +
                                                   std::to_string(timeout.count()) + " ms"));
}

std::uint64_t ipc_required_chunk_bytes(std::uint64_t payload_bytes,
                                       std::uint32_t alignment) noexcept {
  if (payload_bytes > UINT32_MAX) return 0;
  auto settings =
      iox::mepoo::ChunkSettings::create(static_cast<std::uint32_t>(payload_bytes), alignment);
  return settings.has_error() ? 0 : settings.value().requiredChunkSize();
}

Result<void, IpcError> check_pool_fits(const IpcPools& pools, std::uint64_t payload_bytes,
                                       std::uint32_t alignment, std::string_view who) {
  const std::uint64_t needed = ipc_required_chunk_bytes(payload_bytes, alignment);
  std::uint64_t largest = 0;
  // A pool configured with `size` payload bytes holds chunks of size + sizeof(ChunkHeader)
  // (iox::mepoo::MemoryManager::sizeWithChunkHeaderStruct); the loan fits if its chunk does.
  for (const IpcPool& pool : pools) {
    const std::uint64_t chunk = pool.payload_bytes + sizeof(iox::mepoo::ChunkHeader);
    largest = std::max(largest, pool.payload_bytes);
    if (needed != 0 && pool.count > 0 && needed <= chunk) return {};
  }
  return err(make_error(IpcError::Code::NO_FITTING_POOL,
                        std::string(who) + ": a " + std::to_string(payload_bytes) +
                            " B payload needs a " + std::to_string(needed) +
                            " B chunk; RouDi's largest pool holds " + std::to_string(largest) +
                            " B payloads (" + std::to_string(pools.size()) +
                            " pools): add a pool (`orthoflow ipc config`)"));
}

}  // namespace orthoflow::engine
