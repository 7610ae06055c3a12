#pragma once
/// @file
/// @brief A robot's configuration for a flashable image (issue 24, docs/DEPLOY.md): what the
/// orthoflow service runs on it (source, graph, learner), the web view and its token, the network,
/// and the disk layout. Read from YAML at image build time (`orthoflow image check`,
/// scripts/build_image.sh --config): unknown keys, wrong types and values out of range are errors
/// naming the key. Every text that ends up in a unit file, fstab or the boot loader's command line
/// is held to a character set that cannot break out of its line or its quoting.
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "core/result.hpp"

namespace orthoflow::deploy {

/// @brief The architectures an image is built for.
enum class Arch { amd64, arm64 };

/// @brief "amd64" / "arm64" to Arch; anything else is an error naming the text.
[[nodiscard]] Result<Arch, std::string> parse_arch(std::string_view text);
[[nodiscard]] std::string_view arch_name(Arch arch) noexcept;

struct UiSettings {
  bool enabled = true;
  std::string listen = "0.0.0.0:8080";  ///< [ADDR:]PORT; beyond loopback it needs the bearer token
  /// A file on the build machine holding the bearer token (copied to /etc/orthoflow/ui-token);
  /// empty: the robot makes one at its first boot, on the data partition.
  std::string token_file;
};

struct NetworkSettings {
  bool dhcp = true;
  std::vector<std::string> interfaces{"en*", "eth*"};  ///< name globs systemd-networkd matches
  std::string address;                                 ///< static CIDR (a.b.c.d/n) when not dhcp
  std::string gateway;                                 ///< static gateway, optional
  std::vector<std::string> dns;                        ///< static resolvers, optional
};

/// @brief Remote administration: none unless keys are given (the image has no root password).
struct AdminSettings {
  /// A file on the build machine with SSH public keys for root (authorized_keys format); empty: no
  /// SSH server. With it: openssh-server, keys only, host keys made at the first boot on the data
  /// partition (every robot its own).
  std::string ssh_authorized_keys;
};

struct ImageSettings {
  std::uint32_t esp_mib = 64;         ///< the EFI system partition (the boot loader)
  std::uint32_t root_mib = 1536;      ///< the read-only root file system
  std::uint32_t data_mib = 256;       ///< the data partition: the perceptual memory
  std::string console;                ///< kernel console; empty: ttyS0 (amd64), ttyAMA0 (arm64)
  std::vector<std::string> cmdline;   ///< extra kernel parameters
  std::vector<std::string> packages;  ///< extra Debian packages
  /// The initramfs: "list" (the storage drivers of deploy/image/initramfs/hooks/orthoflow-image) or
  /// "most" (Debian's default: every storage driver; slow to build under emulation).
  std::string initramfs = "list";
};

/// @brief Everything a robot image is built from; the defaults make a working image.
struct RobotConfig {
  std::string hostname = "orthoflow";
  /// auto (the Kinect when one is plugged in at start, else the simulated one), kinect[:SERIAL],
  /// kinect-sim[:SEED] or synthetic:SEED.
  std::string source = "auto";
  /// "tabletop" (the graph built into orthoflow) or a graph file on the build machine, copied to
  /// /etc/orthoflow/graph.yaml.
  std::string graph = "tabletop";
  std::string learner = "instance";  ///< instance or bayes
  double rate_hz = 0.0;              ///< 0: the graph's own period
  std::uint32_t threads = 0;         ///< 0: all cores
  UiSettings ui;
  NetworkSettings network;
  AdminSettings admin;
  ImageSettings image;
};

/// @brief Reads @p path (YAML) over the defaults and checks the result (check_robot_config).
[[nodiscard]] Result<RobotConfig, std::string> load_robot_config(const std::string& path);
/// @brief The same from YAML text; @p name labels the errors.
[[nodiscard]] Result<RobotConfig, std::string> parse_robot_config(const std::string& text,
                                                                  const std::string& name);
/// @brief Every rule of the file format on a config however it was made.
[[nodiscard]] Result<void, std::string> check_robot_config(const RobotConfig& config);

/// @brief The UI's port from `listen` ([ADDR:]PORT), 0 when the UI is off.
[[nodiscard]] std::uint16_t ui_port(const RobotConfig& config) noexcept;
/// @brief Checks the text of an authorized_keys file: at most 64 KiB, every line empty, a comment
/// or a public key of a type OpenSSH takes (ssh-ed25519, ssh-rsa, ecdsa-sha2-*, sk-*), no options.
[[nodiscard]] Result<void, std::string> check_authorized_keys(std::string_view text);
/// @brief The kernel console for @p arch: config.image.console or the architecture's default.
[[nodiscard]] std::string kernel_console(const RobotConfig& config, Arch arch);

}  // namespace orthoflow::deploy
