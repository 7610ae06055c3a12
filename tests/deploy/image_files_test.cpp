// The files a robot configuration puts into an image (issue 24): the unit runs what robot.yaml
// says, fstab keeps the root read-only and the memory on the data partition, the boot loader finds
// the root by label with the configured console, and the layout holds the sizes build_image.sh
// reads.
#include "deploy/image_files.hpp"

#include <gtest/gtest.h>

#include <string>

namespace orthoflow::deploy {
namespace {

const ImageFile& file(const std::vector<ImageFile>& files, const std::string& path) {
  for (const auto& f : files)
    if (f.path == path) return f;
  ADD_FAILURE() << "no " << path;
  static const ImageFile none;
  return none;
}

bool has(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

TEST(ImageFiles, TheUnitRunsTheConfiguredSourceWithTheMemoryOnTheDataPartition) {
  RobotConfig c;
  c.source = "kinect-sim:3";
  c.learner = "bayes";
  c.rate_hz = 15;
  const auto files = root_files(c);
  const std::string unit = file(files, "etc/systemd/system/orthoflow.service").text;
  EXPECT_TRUE(has(
      unit,
      "ExecStart=/usr/lib/orthoflow-image/robot-run kinect-sim:3 --db /var/lib/orthoflow/memory "
      "--learner bayes --rate 15 --threads 0 --ui 0.0.0.0:8080 --ui-token-file "
      "/var/lib/orthoflow/ui-token --telemetry-json /var/lib/orthoflow/telemetry.json\n"))
      << unit;
  EXPECT_TRUE(has(unit, "Restart=always\n"));
  EXPECT_TRUE(has(unit, "StartLimitIntervalSec=0\n"));  // restarted for ever, never given up
  EXPECT_TRUE(has(unit, "RequiresMountsFor=/var/lib/orthoflow\n"));
  EXPECT_TRUE(has(unit, "User=orthoflow\n"));
  EXPECT_TRUE(has(unit, "ProtectSystem=strict\n"));
}

TEST(ImageFiles, AGivenTokenAndGraphAreUsedFromEtc) {
  RobotConfig c;
  c.ui.token_file = "token.txt";
  c.graph = "graphs/mine.yaml";
  const std::string unit = file(root_files(c), "etc/systemd/system/orthoflow.service").text;
  EXPECT_TRUE(has(unit, "--graph /etc/orthoflow/graph.yaml"));
  EXPECT_TRUE(has(unit, "--ui-token-file /etc/orthoflow/ui-token"));
  EXPECT_EQ(token_path_on_robot(c), "/etc/orthoflow/ui-token");
  const std::string env = file(root_files(c), "etc/orthoflow/image.env").text;
  EXPECT_TRUE(has(env, "ORTHOFLOW_UI_TOKEN=/etc/orthoflow/ui-token\n"));
  EXPECT_TRUE(has(env, "ORTHOFLOW_UI_PORT=8080\n"));
}

TEST(ImageFiles, WithoutTheUiNoTokenNorPort) {
  RobotConfig c;
  c.ui.enabled = false;
  const auto files = root_files(c);
  EXPECT_FALSE(has(file(files, "etc/systemd/system/orthoflow.service").text, "--ui"));
  EXPECT_TRUE(has(file(files, "etc/orthoflow/image.env").text,
                  "ORTHOFLOW_UI_PORT=0\nORTHOFLOW_UI_TOKEN=\n"));
}

TEST(ImageFiles, ReadOnlyRootAndTheMemoryOnItsOwnPartition) {
  const std::string fstab = file(root_files(RobotConfig{}), "etc/fstab").text;
  EXPECT_TRUE(has(fstab, "LABEL=orthoflow-root  /  ext4  ro,"));
  EXPECT_TRUE(has(fstab, "LABEL=orthoflow-data  /data  ext4  rw,"));
  EXPECT_TRUE(has(fstab,
                  "/data/orthoflow  /var/lib/orthoflow  none  "
                  "bind,x-systemd.requires-mounts-for=/data  0 0\n"));
  EXPECT_TRUE(has(fstab, "tmpfs  /tmp  tmpfs"));
}

TEST(ImageFiles, HostNameAndNetwork) {
  RobotConfig c;
  c.hostname = "kitchen-1";
  auto files = root_files(c);
  EXPECT_EQ(file(files, "etc/hostname").text, "kitchen-1\n");
  EXPECT_TRUE(has(file(files, "etc/hosts").text, "127.0.1.1 kitchen-1\n"));
  EXPECT_TRUE(has(file(files, "etc/systemd/network/80-orthoflow.network").text,
                  "Name=en* eth*\n\n[Network]\nDHCP=yes\n"));
  c.network.dhcp = false;
  c.network.address = "10.0.0.5/24";
  c.network.gateway = "10.0.0.1";
  c.network.dns = {"10.0.0.1"};
  files = root_files(c);
  EXPECT_TRUE(has(file(files, "etc/systemd/network/80-orthoflow.network").text,
                  "Address=10.0.0.5/24\nGateway=10.0.0.1\nDNS=10.0.0.1\n"));
}

TEST(ImageFiles, TheBootLoaderFindsTheRootByLabelOnTheConsole) {
  RobotConfig c;
  c.image.cmdline = {"quiet"};
  const std::string amd = grub_config(c, Arch::amd64);
  EXPECT_TRUE(has(amd, "search --no-floppy --label --set=root orthoflow-root\n"));
  EXPECT_TRUE(has(amd,
                  "linux /vmlinuz root=LABEL=orthoflow-root ro rootwait console=tty0 "
                  "console=ttyS0,115200 quiet\n"));
  EXPECT_TRUE(has(amd, "initrd /initrd.img\n"));
  EXPECT_TRUE(has(grub_config(c, Arch::arm64), "console=ttyAMA0,115200"));
  EXPECT_EQ(kernel_command_line(c, Arch::arm64),
            "root=LABEL=orthoflow-root ro rootwait console=tty0 console=ttyAMA0,115200 quiet");
}

TEST(ImageFiles, SshOnlyWithKeysAndThenKeysOnlyWithTheRobotsOwnHostKey) {
  RobotConfig c;
  for (const auto& f : root_files(c)) EXPECT_EQ(f.path.find("ssh"), std::string::npos) << f.path;
  EXPECT_FALSE(has(image_layout(c), "openssh-server"));
  c.admin.ssh_authorized_keys = "admin.pub";
  const auto files = root_files(c);
  const std::string sshd = file(files, "etc/ssh/sshd_config.d/orthoflow-image.conf").text;
  EXPECT_TRUE(has(sshd, "PasswordAuthentication no\n"));
  EXPECT_TRUE(has(sshd, "PermitRootLogin prohibit-password\n"));
  EXPECT_TRUE(has(sshd, "HostKey /data/ssh/ssh_host_ed25519_key\n"));
  EXPECT_TRUE(has(file(files, "etc/systemd/system/ssh.service.d/orthoflow-image.conf").text,
                  "After=orthoflow-firstboot.service\n"));
  EXPECT_TRUE(has(file(files, "etc/orthoflow/image.env").text, "ORTHOFLOW_SSH=1\n"));
  EXPECT_TRUE(has(image_layout(c), "packages openssh-server\n"));
}

TEST(ImageFiles, TheLayoutHoldsTheSizes) {
  RobotConfig c;
  c.image.packages = {"openssh-server", "htop"};
  EXPECT_EQ(image_layout(c),
            "esp_mib 64\nroot_mib 1536\ndata_mib 256\nui_port 8080\ninitramfs list\npackages "
            "openssh-server htop\nroot_label orthoflow-root\ndata_label orthoflow-data\nesp_label "
            "ORTHO-EFI\n");
}

}  // namespace
}  // namespace orthoflow::deploy
