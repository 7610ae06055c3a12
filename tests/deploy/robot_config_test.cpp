// robot.yaml (issue 24): the defaults are a working configuration, the committed example checks,
// and every rule refuses what would break the image or let a value escape its line in a unit file,
// fstab or the kernel command line, with an error naming the key.
#include "deploy/robot_config.hpp"

#include <gtest/gtest.h>

#include <string>

namespace orthoflow::deploy {
namespace {

Result<RobotConfig, std::string> parse(const std::string& text) {
  return parse_robot_config(text, "robot.yaml");
}

// The error of @p text, or "" when it parses.
std::string error_of(const std::string& text) {
  auto c = parse(text);
  return c ? std::string() : c.error();
}

TEST(RobotConfig, TheDefaultsCheck) {
  const RobotConfig c;
  EXPECT_TRUE(check_robot_config(c));
  EXPECT_EQ(c.source, "auto");
  EXPECT_EQ(ui_port(c), 8080);
  EXPECT_EQ(kernel_console(c, Arch::amd64), "ttyS0,115200");
  EXPECT_EQ(kernel_console(c, Arch::arm64), "ttyAMA0,115200");
}

TEST(RobotConfig, TheCommittedExampleChecks) {
  auto c = load_robot_config(std::string(ORTHOFLOW_SOURCE_DIR) + "/deploy/image/robot.yaml");
  ASSERT_TRUE(c) << c.error();
  EXPECT_EQ(c->hostname, "orthoflow");
  EXPECT_EQ(c->image.root_mib, 1536u);
  EXPECT_TRUE(c->ui.token_file.empty());
}

TEST(RobotConfig, EveryKeyIsRead) {
  auto c = parse(R"(
hostname: kitchen-robot-2
source: kinect-sim:7
graph: my_graph.yaml
learner: bayes
rate_hz: 15
threads: 2
ui: {enabled: true, listen: "127.0.0.1:9000", token_file: token.txt}
network: {dhcp: false, interfaces: [eth0], address: 192.168.1.20/24, gateway: 192.168.1.1, dns: [192.168.1.1]}
image: {esp_mib: 128, root_mib: 2048, data_mib: 1024, console: "ttyS1,9600", cmdline: [quiet, "isolcpus=1"], packages: [openssh-server]}
)");
  ASSERT_TRUE(c) << c.error();
  EXPECT_EQ(c->hostname, "kitchen-robot-2");
  EXPECT_EQ(c->source, "kinect-sim:7");
  EXPECT_EQ(c->graph, "my_graph.yaml");
  EXPECT_EQ(c->learner, "bayes");
  EXPECT_DOUBLE_EQ(c->rate_hz, 15.0);
  EXPECT_EQ(c->threads, 2u);
  EXPECT_EQ(c->ui.listen, "127.0.0.1:9000");
  EXPECT_EQ(ui_port(*c), 9000);
  EXPECT_EQ(c->ui.token_file, "token.txt");
  EXPECT_FALSE(c->network.dhcp);
  EXPECT_EQ(c->network.address, "192.168.1.20/24");
  EXPECT_EQ(c->network.dns.size(), 1u);
  EXPECT_EQ(c->image.esp_mib, 128u);
  EXPECT_EQ(c->image.data_mib, 1024u);
  EXPECT_EQ(kernel_console(*c, Arch::arm64), "ttyS1,9600");
  EXPECT_EQ(c->image.cmdline.size(), 2u);
  EXPECT_EQ(c->image.packages[0], "openssh-server");
}

TEST(RobotConfig, MalformedFilesAreRefusedWithTheirName) {
  EXPECT_NE(error_of("").find("empty"), std::string::npos);
  EXPECT_NE(error_of("[1, 2]").find("a map"), std::string::npos);
  EXPECT_NE(error_of("hostname: [unclosed").find("robot.yaml"), std::string::npos);
  EXPECT_NE(error_of("hostname: {a: 1}").find("robot.yaml"), std::string::npos);
  EXPECT_NE(error_of("threads: lots").find("robot.yaml"), std::string::npos);
  // A key twice: refused with its line, never "the last one wins" (issue 52, item 11).
  EXPECT_NE(error_of("hostname: a\nhostname: b\n").find("line 2: key 'hostname' appears twice"),
            std::string::npos);
  EXPECT_NE(error_of("ui: {token_file: a, token_file: b}").find("key 'token_file' appears twice"),
            std::string::npos);
  auto missing = load_robot_config("/nonexistent/robot.yaml");
  ASSERT_FALSE(missing);
  EXPECT_NE(missing.error().find("/nonexistent/robot.yaml: cannot be read"), std::string::npos);
}

TEST(RobotConfig, UnknownKeysAreNamed) {
  EXPECT_NE(error_of("hostnam: x").find("hostnam: unknown key"), std::string::npos);
  EXPECT_NE(error_of("ui: {port: 80}").find("ui.port: unknown key"), std::string::npos);
  EXPECT_NE(error_of("network: {wifi: true}").find("network.wifi: unknown key"), std::string::npos);
  EXPECT_NE(error_of("image: {swap_mib: 1}").find("image.swap_mib: unknown key"),
            std::string::npos);
}

TEST(RobotConfig, ValuesOutOfRangeAreNamed) {
  EXPECT_NE(error_of("threads: -1").find("threads"), std::string::npos);
  EXPECT_NE(error_of("rate_hz: 5000").find("rate_hz"), std::string::npos);
  EXPECT_NE(error_of("rate_hz: .nan").find("rate_hz"), std::string::npos);
  EXPECT_NE(error_of("rate_hz: .inf").find("rate_hz"), std::string::npos);
  EXPECT_NE(error_of("learner: svm").find("learner"), std::string::npos);
  EXPECT_NE(error_of("image: {root_mib: 100}").find("image.root_mib"), std::string::npos);
  EXPECT_NE(error_of("image: {esp_mib: 8}").find("image.esp_mib"), std::string::npos);
  EXPECT_NE(error_of("image: {initramfs: dep}").find("image.initramfs"), std::string::npos);
  EXPECT_TRUE(parse("image: {initramfs: most}"));
  EXPECT_NE(error_of("image: {data_mib: 99999999999}").find("image.data_mib"), std::string::npos);
  EXPECT_NE(error_of("ui: {listen: '0.0.0.0:0'}").find("ui.listen"), std::string::npos);
  EXPECT_NE(error_of("ui: {listen: '0.0.0.0:70000'}").find("ui.listen"), std::string::npos);
  EXPECT_NE(error_of("ui: {listen: 'robot:8080'}").find("ui.listen"), std::string::npos);
  EXPECT_NE(error_of("ui: {listen: '300.0.0.1:8080'}").find("ui.listen"), std::string::npos);
  EXPECT_TRUE(parse("ui: {enabled: false, listen: nonsense}"));  // not used when the UI is off
}

TEST(RobotConfig, SourcesAreTheOnesTheServiceRuns) {
  for (const char* ok :
       {"auto", "kinect", "kinect:A00364A01234", "kinect-sim", "kinect-sim:3", "synthetic:42"})
    EXPECT_TRUE(parse(std::string("source: '") + ok + "'")) << ok;
  for (const char* bad : {"", "pcd:/data", "kinect-sim:x", "kinect:", "synthetic:", "kinect:a b",
                          "usb", "kinect-sim:1; rm -rf /", "kinect-simulated"})
    EXPECT_NE(error_of(std::string("source: '") + bad + "'").find("source"), std::string::npos)
        << bad;
}

TEST(RobotConfig, TextsCannotLeaveTheirLine) {
  // Host name: RFC 1123 label.
  for (const char* bad :
       {"-robot", "robot-", "Robot", "ro bot", "robot\nExecStart=/bin/sh", "a.b", ""})
    EXPECT_NE(error_of(std::string("hostname: \"") + bad + "\"").find("hostname"),
              std::string::npos)
        << bad;
  EXPECT_NE(error_of("network: {interfaces: [\"eth0\\nDHCP=no\"]}").find("network.interfaces"),
            std::string::npos);
  EXPECT_NE(error_of("network: {interfaces: []}").find("network.interfaces"), std::string::npos);
  EXPECT_NE(error_of("image: {cmdline: [\"quiet init=/bin/sh\"]}").find("image.cmdline"),
            std::string::npos);
  EXPECT_NE(error_of("image: {cmdline: [\"init=/bin/sh\"]}").find("image.cmdline"),
            std::string::npos);
  EXPECT_NE(error_of("image: {cmdline: [\"root=/dev/sda1\"]}").find("image.cmdline"),
            std::string::npos);
  EXPECT_NE(error_of("image: {console: \"ttyS0 init=/bin/sh\"}").find("image.console"),
            std::string::npos);
  EXPECT_NE(error_of("image: {packages: [\"vim; rm\"]}").find("image.packages"), std::string::npos);
  EXPECT_NE(error_of("image: {packages: [\"Vim\"]}").find("image.packages"), std::string::npos);
  EXPECT_NE(error_of("image: {packages: [\"-o\"]}").find("image.packages"), std::string::npos);
  EXPECT_NE(error_of("graph: \"a\\nb.yaml\"").find("graph"), std::string::npos);
  EXPECT_NE(error_of("ui: {token_file: \"t'oken\"}").find("ui.token_file"), std::string::npos);
}

TEST(RobotConfig, StaticNetworkNeedsAnAddressAndDhcpTakesNone) {
  EXPECT_NE(error_of("network: {dhcp: false}").find("network.address"), std::string::npos);
  EXPECT_NE(error_of("network: {dhcp: false, address: 10.0.0.5}").find("network.address"),
            std::string::npos);
  EXPECT_NE(error_of("network: {dhcp: false, address: 10.0.0.5/33}").find("network.address"),
            std::string::npos);
  EXPECT_NE(error_of("network: {dhcp: false, address: 10.0.0.5/24, gateway: 10.0.0}")
                .find("network.gateway"),
            std::string::npos);
  EXPECT_NE(error_of("network: {address: 10.0.0.5/24}").find("dhcp: false"), std::string::npos);
  EXPECT_NE(
      error_of(
          "network: {dhcp: false, address: 10.0.0.5/24, dns: [1.1.1.1, 2.2.2.2, 3.3.3.3, 4.4.4.4, "
          "5.5.5.5]}")
          .find("network.dns"),
      std::string::npos);
  EXPECT_TRUE(parse("network: {dhcp: false, address: 10.0.0.5/24}"));
}

TEST(RobotConfig, AdminKeys) {
  auto c = parse("admin: {ssh_authorized_keys: keys/admin.pub}");
  ASSERT_TRUE(c) << c.error();
  EXPECT_EQ(c->admin.ssh_authorized_keys, "keys/admin.pub");
  EXPECT_NE(error_of("admin: {password: x}").find("admin.password: unknown key"),
            std::string::npos);
  EXPECT_NE(error_of("admin: {ssh_authorized_keys: \"a;b\"}").find("admin.ssh_authorized_keys"),
            std::string::npos);
  EXPECT_TRUE(RobotConfig{}.admin.ssh_authorized_keys.empty());  // no remote shell unless asked
}

TEST(RobotConfig, NamedFilesAreInsideTheConfigsFolder) {
  // The class of "token_file: /etc/shadow" (issue 52, item 1): every file a config names.
  for (const char* key : {"graph: ", "ui: {token_file: ", "admin: {ssh_authorized_keys: "}) {
    const std::string k(key);
    const bool nested = k.back() == ' ' && k.find('{') != std::string::npos;
    for (const char* path : {"/etc/shadow", "../secret", "keys/../../x", "..", "~/.ssh/id"}) {
      const std::string text = k + "\"" + path + "\"" + (nested ? "}" : "");
      EXPECT_NE(error_of(text).find("a relative path inside the config's folder"),
                std::string::npos)
          << text;
    }
    for (const char* path : {"g.yaml", "keys/admin.pub", "./tok", "a..b"}) {
      const std::string text = k + "\"" + path + "\"" + (nested ? "}" : "");
      EXPECT_EQ(error_of(text), "") << text;
    }
  }
}

TEST(RobotConfig, AuthorizedKeysAreKeysOnly) {
  EXPECT_TRUE(check_authorized_keys("ssh-ed25519 AAAAC3NzaC1lZDI1NTE5AAAAIG me@host\n"));
  EXPECT_TRUE(
      check_authorized_keys("# admins\n\nssh-rsa AAAAB3Nza x\r\necdsa-sha2-nistp256 AAAAE2 y\n"));
  EXPECT_TRUE(check_authorized_keys("sk-ssh-ed25519@openssh.com AAAAGnNr z"));
  EXPECT_FALSE(check_authorized_keys(""));
  EXPECT_FALSE(check_authorized_keys("# only a comment\n"));
  EXPECT_NE(
      check_authorized_keys("command=\"/bin/sh\" ssh-ed25519 AAAA x\n").error().find("line 1"),
      std::string::npos);
  EXPECT_NE(check_authorized_keys("ssh-ed25519 AAAA\nssh-dss AAAA\n").error().find("line 2"),
            std::string::npos);
  EXPECT_FALSE(check_authorized_keys("ssh-ed25519\n"));
  EXPECT_FALSE(check_authorized_keys("ssh-ed25519 AAAA \x01\n"));
  EXPECT_FALSE(check_authorized_keys(std::string(70000, '#')));
}

TEST(RobotConfig, Architectures) {
  EXPECT_EQ(*parse_arch("amd64"), Arch::amd64);
  EXPECT_EQ(*parse_arch("arm64"), Arch::arm64);
  EXPECT_FALSE(parse_arch("armhf"));
  EXPECT_EQ(arch_name(Arch::arm64), "arm64");
}

}  // namespace
}  // namespace orthoflow::deploy
