#pragma once
/// @file
/// @brief The process side of iceoryx 2.0.3: a RouDi probe that never blocks, a guarded
/// `initRuntime`, and RouDi's memory pools (from its TOML file or from its live introspection) so
/// that a loan is checked against the pools before it is made. See docs/IPC.md.
///
/// iceoryx 2.0.3 blocks 60 s and then aborts inside `initRuntime` when RouDi is absent, and aborts
/// on a loan larger than every pool; everything here exists to turn those into errors.
#include <chrono>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "core/result.hpp"

namespace orthoflow::engine {

/// @brief Every failure of the IPC layer, with a message saying what and where.
struct IpcError {
  enum class Code {
    ROUDI_UNREACHABLE,  ///< no RouDi answers on its socket (checked before initRuntime)
    ROUDI_LOST,         ///< RouDi was reachable and is gone now
    RUNTIME_NAME,       ///< process name invalid or a second, different init in one process
    BAD_TOPIC,          ///< topic not `service/instance/event` of [A-Za-z0-9_.-]
    CONFIG,             ///< RouDi TOML file unreadable or invalid
    NO_POOL_INFO,       ///< RouDi's pools could not be learned in time
    NO_FITTING_POOL,    ///< a payload larger than every RouDi pool (iceoryx would abort)
    POOL_EXHAUSTED,     ///< the fitting pools have no free chunk right now
    TOO_MANY_LOANS,     ///< more chunks loaned or held at once than iceoryx allows
    WRONG_TYPE,         ///< payload type id differs from the topic's
    WRONG_VERSION,      ///< payload version differs from the topic's
    BAD_SIZE,           ///< payload_bytes at offset 48 disagrees with the chunk or loan
  };
  Code code = Code::ROUDI_UNREACHABLE;
  std::string message;
};

/// @brief Name of a code, e.g. "NO_FITTING_POOL".
[[nodiscard]] std::string_view to_string(IpcError::Code code) noexcept;
/// @brief "CODE: message".
[[nodiscard]] std::string to_string(const IpcError& error);

/// @brief One RouDi memory pool: chunks of `payload_bytes` usable bytes (RouDi adds its header).
struct IpcPool {
  std::uint64_t payload_bytes = 0;
  std::uint32_t count = 0;
};
using IpcPools = std::vector<IpcPool>;

/// @brief Where RouDi keeps its socket (iceoryx 2.0.3: IOX_UDS_SOCKET_PATH_PREFIX + "roudi").
inline constexpr std::string_view ROUDI_SOCKET_PATH = "/tmp/roudi";

/// @brief Checks that a RouDi process is bound to its unix-domain socket, by connecting a datagram
/// socket to it (no message is sent). Takes microseconds; never blocks.
/// @return ROUDI_UNREACHABLE naming the socket and errno text when no RouDi runs.
/// @note Thread-safe, no allocation on success.
[[nodiscard]] Result<void, IpcError> probe_roudi() noexcept;

/// @brief Registers this process with RouDi (iox::runtime::PoshRuntime::initRuntime), once.
/// Probes first, so a missing RouDi is an error within a millisecond instead of a 60 s block and an
/// abort. Later calls with the same name return at once; a different name is RUNTIME_NAME.
/// @pre app_name: 1..100 characters of [A-Za-z0-9_.-]. Start-up only (allocates).
/// @note Thread-safe (serialised by a mutex); iceoryx allows one runtime per process.
[[nodiscard]] Result<void, IpcError> init_ipc_runtime(std::string_view app_name);

/// @brief True once init_ipc_runtime succeeded in this process.
[[nodiscard]] bool ipc_runtime_ready() noexcept;

/// @brief Set by any IPC wrapper that saw RouDi disappear; the CLI maps it to an exit code.
[[nodiscard]] bool ipc_roudi_lost() noexcept;
/// @brief Marks RouDi as lost (called by the wrappers' liveness checks). Thread-safe.
void mark_roudi_lost() noexcept;

/// @brief Pools of a RouDi started with `iox-roudi -c path` (parsed by iceoryx's own TOML reader,
/// so the answer is what RouDi will use). An empty path means RouDi's built-in defaults.
[[nodiscard]] Result<IpcPools, IpcError> load_roudi_pools(const std::string& path);

/// @brief RouDi's built-in pools when started without a config file.
[[nodiscard]] IpcPools default_roudi_pools();

/// @brief Asks the running RouDi for its pools through its MemPool introspection topic, waiting at
/// most `timeout` (RouDi publishes it about once a second).
/// @pre init_ipc_runtime succeeded. @return NO_POOL_INFO on timeout.
[[nodiscard]] Result<IpcPools, IpcError> query_roudi_pools(std::chrono::milliseconds timeout);

/// @brief Chunk bytes iceoryx needs for a payload of `payload_bytes` aligned to `alignment`
/// (iox::mepoo::ChunkSettings), or 0 if iceoryx rejects the parameters.
[[nodiscard]] std::uint64_t ipc_required_chunk_bytes(std::uint64_t payload_bytes,
                                                     std::uint32_t alignment) noexcept;

/// @brief Checks that some pool can hold a `payload_bytes` payload aligned to `alignment`.
/// @return NO_FITTING_POOL naming `who`, the bytes needed and the largest pool.
[[nodiscard]] Result<void, IpcError> check_pool_fits(const IpcPools& pools,
                                                     std::uint64_t payload_bytes,
                                                     std::uint32_t alignment, std::string_view who);

}  // namespace orthoflow::engine
