#include "deploy/image_files.hpp"

#include <cstdio>

namespace orthoflow::deploy {
namespace {

std::string join(const std::vector<std::string>& parts, const char* sep) {
  std::string out;
  for (const auto& p : parts) out += (out.empty() ? "" : sep) + p;
  return out;
}

std::string number(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", x);
  return buf;
}

std::string fstab() {
  return std::string(
             "# orthoflow robot image (docs/DEPLOY.md): the root file system is read-only; the "
             "perceptual\n"
             "# memory, the service's state and the SSH host keys live on the data partition. "
             "Update in\n"
             "# place: docs/DEPLOY.md section 7.\n"
             "LABEL=") +
         ROOT_LABEL + "  /  ext4  ro,noatime,errors=remount-ro  0 1\nLABEL=" + DATA_LABEL + "  " +
         DATA_DIR + "  ext4  rw,noatime,nosuid,nodev,noexec,errors=remount-ro  0 2\n" + DATA_DIR +
         "/orthoflow  " + STATE_DIR + "  none  bind,x-systemd.requires-mounts-for=" + DATA_DIR +
         "  0 0\nLABEL=" + ESP_LABEL +
         "  /boot/efi  vfat  ro,noauto,umask=0077  0 0\n"
         "tmpfs  /tmp  tmpfs  mode=1777,nosuid,nodev,size=25%  0 0\n"
         "tmpfs  /var/tmp  tmpfs  mode=1777,nosuid,nodev,size=64M  0 0\n"
         "tmpfs  /var/log  tmpfs  mode=0755,nosuid,nodev,size=32M  0 0\n";
}

std::string sshd_config() {
  return std::string(
             "# orthoflow robot image (docs/DEPLOY.md): keys only, root by key only; the host keys "
             "are this\n"
             "# robot's own, made at its first boot on the data partition.\n"
             "PasswordAuthentication no\n"
             "KbdInteractiveAuthentication no\n"
             "PermitRootLogin prohibit-password\n"
             "HostKey ") +
         DATA_DIR + "/ssh/ssh_host_ed25519_key\n";
}

std::string network_file(const NetworkSettings& n) {
  std::string s =
      "# orthoflow robot image: from network in /etc/orthoflow/robot.yaml\n[Match]\nName=" +
      join(n.interfaces, " ") + "\n\n[Network]\n";
  if (n.dhcp) {
    s += "DHCP=yes\n";
  } else {
    s += "Address=" + n.address + "\n";
    if (!n.gateway.empty()) s += "Gateway=" + n.gateway + "\n";
    for (const auto& d : n.dns) s += "DNS=" + d + "\n";
  }
  return s;
}

std::string service_unit(const RobotConfig& c) {
  std::string exec = "/usr/lib/orthoflow-image/robot-run " + c.source;
  for (const auto& a : service_arguments(c)) exec += " " + a;
  return "# orthoflow robot image (docs/DEPLOY.md): the perception service, from "
         "/etc/orthoflow/robot.yaml.\n"
         "# A failure is restarted every 5 s for ever (StartLimitIntervalSec=0): the reason is in\n"
         "# `journalctl -u orthoflow` and in the health report on the console, never a reboot "
         "loop.\n"
         "[Unit]\n"
         "Description=orthoflow object perception (robot image)\n"
         "After=network.target orthoflow-firstboot.service\n"
         "Wants=orthoflow-firstboot.service\n"
         "RequiresMountsFor=" +
         std::string(STATE_DIR) +
         "\n"
         "StartLimitIntervalSec=0\n"
         "\n[Service]\n"
         "Type=simple\n"
         "User=orthoflow\n"
         "Group=orthoflow\n"
         "SupplementaryGroups=plugdev\n"
         "StateDirectory=orthoflow\n"
         "WorkingDirectory=" +
         STATE_DIR + "\nExecStart=" + exec +
         "\n"
         "Restart=always\n"
         "RestartSec=5\n"
         "KillSignal=SIGTERM\n"
         "TimeoutStopSec=10\n"
         "Nice=-5\n"
         "LimitMEMLOCK=infinity\n"
         "NoNewPrivileges=yes\n"
         "ProtectSystem=strict\n"
         "ProtectHome=yes\n"
         "ReadWritePaths=/tmp /dev/shm\n"
         "\n[Install]\n"
         "WantedBy=multi-user.target\n";
}

std::string image_env(const RobotConfig& c) {
  // Read by the health report and the first-boot script (sh `.`): every value was checked by
  // check_robot_config to hold no character a shell would interpret.
  return "# orthoflow robot image: settings for its scripts (written by orthoflow image render)\n"
         "ORTHOFLOW_UI_PORT=" +
         std::to_string(ui_port(c)) +
         "\nORTHOFLOW_UI_TOKEN=" + (c.ui.enabled ? token_path_on_robot(c) : "") +
         "\nORTHOFLOW_STATE_DIR=" + STATE_DIR + "\nORTHOFLOW_DATA_DIR=" + DATA_DIR +
         "\nORTHOFLOW_SSH=" + (c.admin.ssh_authorized_keys.empty() ? "0" : "1") + "\n";
}

}  // namespace

std::string token_path_on_robot(const RobotConfig& c) {
  return c.ui.token_file.empty() ? std::string(STATE_DIR) + "/ui-token" : "/etc/orthoflow/ui-token";
}

std::vector<std::string> service_arguments(const RobotConfig& c) {
  std::vector<std::string> a = {"--db", std::string(STATE_DIR) + "/memory", "--learner", c.learner};
  if (c.graph != "tabletop") {
    a.emplace_back("--graph");
    a.emplace_back("/etc/orthoflow/graph.yaml");
  }
  if (c.rate_hz > 0.0) {
    a.emplace_back("--rate");
    a.push_back(number(c.rate_hz));
  }
  a.emplace_back("--threads");
  a.push_back(std::to_string(c.threads));
  if (c.ui.enabled) {
    a.emplace_back("--ui");
    a.push_back(c.ui.listen);
    a.emplace_back("--ui-token-file");
    a.push_back(token_path_on_robot(c));
  }
  a.emplace_back("--telemetry-json");
  a.push_back(std::string(STATE_DIR) + "/telemetry.json");
  return a;
}

std::vector<ImageFile> root_files(const RobotConfig& c) {
  std::vector<ImageFile> files = {
      {"etc/hostname", c.hostname + "\n", 0644},
      {"etc/hosts",
       "127.0.0.1 localhost\n127.0.1.1 " + c.hostname +
           "\n::1 localhost ip6-localhost ip6-loopback\n",
       0644},
      {"etc/fstab", fstab(), 0644},
      {"etc/systemd/network/80-orthoflow.network", network_file(c.network), 0644},
      {"etc/systemd/system/orthoflow.service", service_unit(c), 0644},
      {"etc/orthoflow/image.env", image_env(c), 0644},
  };
  if (!c.admin.ssh_authorized_keys.empty()) {
    files.push_back({"etc/ssh/sshd_config.d/orthoflow-image.conf", sshd_config(), 0644});
    files.push_back({"etc/systemd/system/ssh.service.d/orthoflow-image.conf",
                     "# orthoflow robot image: the host keys are made by the first boot\n[Unit]\n"
                     "After=orthoflow-firstboot.service\nWants=orthoflow-firstboot.service\n",
                     0644});
  }
  return files;
}

std::string kernel_command_line(const RobotConfig& c, Arch arch) {
  // The last console= is /dev/console (systemd's messages and the health report).
  std::string line = std::string("root=LABEL=") + ROOT_LABEL +
                     " ro rootwait console=tty0 console=" + kernel_console(c, arch);
  for (const auto& p : c.image.cmdline) line += " " + p;
  return line;
}

std::string grub_config(const RobotConfig& c, Arch arch) {
  return std::string(
             "# orthoflow robot image (docs/DEPLOY.md): built into the EFI boot loader by "
             "scripts/build_image.sh.\n"
             "set timeout=1\n"
             "insmod part_gpt\ninsmod ext2\n"
             "search --no-floppy --label --set=root ") +
         ROOT_LABEL +
         "\n"
         "menuentry 'orthoflow (Debian 12)' {\n"
         "  linux /vmlinuz " +
         kernel_command_line(c, arch) +
         "\n"
         "  initrd /initrd.img\n"
         "}\n";
}

std::string image_layout(const RobotConfig& c) {
  std::vector<std::string> packages = c.image.packages;
  if (!c.admin.ssh_authorized_keys.empty()) packages.emplace_back("openssh-server");
  return "esp_mib " + std::to_string(c.image.esp_mib) + "\nroot_mib " +
         std::to_string(c.image.root_mib) + "\ndata_mib " + std::to_string(c.image.data_mib) +
         "\nui_port " + std::to_string(ui_port(c)) + "\ninitramfs " + c.image.initramfs +
         "\npackages " + join(packages, " ") + "\nroot_label " + ROOT_LABEL + "\ndata_label " +
         DATA_LABEL + "\nesp_label " + ESP_LABEL + "\n";
}

}  // namespace orthoflow::deploy
