#pragma once
/// @file
/// @brief The files a robot configuration puts into an image (issue 24): host name, fstab
/// (read-only root, the perceptual memory on the data partition), the network, the orthoflow unit
/// with its command line, the health report's settings and the boot loader's configuration.
/// scripts/build_image.sh writes them with `orthoflow image render` and copies them over the root
/// file system together with the fixed files in deploy/image/rootfs/.
#include <string>
#include <vector>

#include "deploy/robot_config.hpp"

namespace orthoflow::deploy {

/// @brief File system labels the image's fstab and boot loader find their partitions by.
inline constexpr const char* ROOT_LABEL = "orthoflow-root";
inline constexpr const char* DATA_LABEL = "orthoflow-data";
inline constexpr const char* ESP_LABEL = "ORTHO-EFI";  // FAT: at most 11 upper-case characters
/// @brief The data partition's mount point; it holds orthoflow/ (the service's state, bound onto
/// STATE_DIR) and ssh/ (the robot's own SSH host keys, root only).
inline constexpr const char* DATA_DIR = "/data";
/// @brief Where the service keeps its state: DATA_DIR/orthoflow, bound here.
inline constexpr const char* STATE_DIR = "/var/lib/orthoflow";

/// @brief One file of the root file system: a path relative to its root, the text, the mode.
struct ImageFile {
  std::string path;
  std::string text;
  unsigned mode = 0644;
};

/// @brief The configuration's files, relative to the root file system. The configured token file
/// and graph file (when the configuration names them) are copied by the caller to
/// etc/orthoflow/ui-token and etc/orthoflow/graph.yaml, where the unit expects them.
[[nodiscard]] std::vector<ImageFile> root_files(const RobotConfig& config);

/// @brief The `orthoflow run` arguments of the service after the source (the robot-run launcher
/// picks the source), one per element.
[[nodiscard]] std::vector<std::string> service_arguments(const RobotConfig& config);

/// @brief The boot loader's (GRUB's) configuration: find the root by its label, boot the
/// kernel Debian links at /vmlinuz with its initrd, read-only, on the configured console.
[[nodiscard]] std::string grub_config(const RobotConfig& config, Arch arch);

/// @brief The kernel command line grub_config passes (also for booting the image's kernel
/// directly, as the image test does).
[[nodiscard]] std::string kernel_command_line(const RobotConfig& config, Arch arch);

/// @brief The layout scripts/build_image.sh reads: one "key value..." line each (esp_mib,
/// root_mib, data_mib, ui_port, initramfs, packages: the configured ones, and openssh-server when
/// admin keys are given; root_label, data_label, esp_label: the labels fstab and the boot loader
/// find the partitions by), values checked by check_robot_config.
[[nodiscard]] std::string image_layout(const RobotConfig& config);

/// @brief Path of the UI's token on the robot: /etc/orthoflow/ui-token when the configuration
/// names a token file, else the one the first boot writes on the data partition.
[[nodiscard]] std::string token_path_on_robot(const RobotConfig& config);

}  // namespace orthoflow::deploy
