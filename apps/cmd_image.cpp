// `orthoflow image check|render`: a robot image's configuration (issue 24, docs/DEPLOY.md).
// `check ROBOT.yaml` validates it; `render ROBOT.yaml --arch A --out DIR` writes what
// scripts/build_image.sh puts into the image: DIR/rootfs/ (files over the root file system: host
// name, fstab, network, the orthoflow unit and its settings, the robot.yaml itself, the token,
// graph and SSH key files it names), DIR/grub.cfg (the boot loader's configuration), DIR/cmdline
// (the kernel command line) and DIR/layout (partition sizes, extra packages).
#include <sys/stat.h>

#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <string>

#include "apps/commands.hpp"
#include "deploy/image_files.hpp"
#include "deploy/robot_config.hpp"
#include "ui/server_config.hpp"

namespace orthoflow::apps {
namespace {

namespace fs = std::filesystem;

struct ImageArgs {
  std::string config;
  std::string arch = "amd64";
  std::string out;
};

[[noreturn]] void fail(const std::string& message, int code) {
  std::cerr << "orthoflow image: " << message << '\n';
  throw CLI::RuntimeError(code);
}

deploy::RobotConfig load_or_throw(const std::string& path) {
  auto config = deploy::load_robot_config(path);
  if (!config) fail(config.error(), EXIT_BAD_INPUT);
  // The files it names must be there now, at build time, not on the robot at boot.
  if (config->ui.enabled && !config->ui.token_file.empty()) {
    const fs::path token = fs::path(path).parent_path() / config->ui.token_file;
    if (auto t = ui::read_token_file(token.string()); !t)
      fail(path + ": ui.token_file: " + t.error(), EXIT_BAD_INPUT);
  }
  if (!config->admin.ssh_authorized_keys.empty()) {
    const fs::path keys = fs::path(path).parent_path() / config->admin.ssh_authorized_keys;
    std::ifstream in(keys, std::ios::binary);
    if (!in)
      fail(path + ": admin.ssh_authorized_keys: " + keys.string() + " cannot be read",
           EXIT_BAD_INPUT);
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (auto ok = deploy::check_authorized_keys(text); !ok)
      fail(path + ": admin.ssh_authorized_keys: " + keys.string() + ": " + ok.error(),
           EXIT_BAD_INPUT);
  }
  if (config->graph != "tabletop") {
    const fs::path graph = fs::path(path).parent_path() / config->graph;
    std::error_code ec;
    if (!fs::is_regular_file(graph, ec))
      fail(path + ": graph: " + graph.string() + " is not a file", EXIT_BAD_INPUT);
  }
  return *config;
}

void write_file(const fs::path& path, const std::string& text, unsigned mode) {
  std::error_code ec;
  fs::create_directories(path.parent_path(), ec);
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << text;
  out.close();
  if (!out || ::chmod(path.c_str(), mode) != 0)
    fail("cannot write " + path.string(), EXIT_FAILURE_GENERIC);
}

void copy_file(const fs::path& from, const fs::path& to, unsigned mode) {
  std::ifstream in(from, std::ios::binary);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (!in && !in.eof()) fail("cannot read " + from.string(), EXIT_BAD_INPUT);
  write_file(to, text, mode);
}

void render(const ImageArgs& a) {
  auto arch = deploy::parse_arch(a.arch);
  if (!arch) fail(arch.error(), EXIT_USAGE);
  const deploy::RobotConfig config = load_or_throw(a.config);
  const fs::path out(a.out);
  const fs::path root = out / "rootfs";
  for (const auto& f : deploy::root_files(config)) write_file(root / f.path, f.text, f.mode);
  const fs::path here = fs::path(a.config).parent_path();
  copy_file(a.config, root / "etc/orthoflow/robot.yaml", 0644);
  if (config.ui.enabled && !config.ui.token_file.empty())
    copy_file(here / config.ui.token_file, root / "etc/orthoflow/ui-token", 0640);
  if (config.graph != "tabletop")
    copy_file(here / config.graph, root / "etc/orthoflow/graph.yaml", 0644);
  if (!config.admin.ssh_authorized_keys.empty()) {
    copy_file(here / config.admin.ssh_authorized_keys, root / "root/.ssh/authorized_keys", 0600);
    if (::chmod((root / "root/.ssh").c_str(), 0700) != 0 ||
        ::chmod((root / "root").c_str(), 0700) != 0)
      fail("cannot set the mode of " + (root / "root/.ssh").string(), EXIT_FAILURE_GENERIC);
  }
  write_file(out / "grub.cfg", deploy::grub_config(config, *arch), 0644);
  write_file(out / "cmdline", deploy::kernel_command_line(config, *arch) + "\n", 0644);
  write_file(out / "layout", deploy::image_layout(config), 0644);
  std::cout << a.config << ": rendered for " << deploy::arch_name(*arch) << " into " << out.string()
            << '\n';
}

}  // namespace

void add_image_command(CLI::App& app) {
  auto* image = app.add_subcommand("image",
                                   "A robot image's configuration: check it, render its files "
                                   "(scripts/build_image.sh; docs/DEPLOY.md)");
  image->require_subcommand(1);
  auto args = std::make_shared<ImageArgs>();
  auto* check =
      image->add_subcommand("check", "Validate a robot configuration (YAML); errors name the key");
  check->add_option("FILE", args->config, "robot.yaml")->required();
  check->callback([args] {
    const auto config = load_or_throw(args->config);
    std::cout << args->config << ": ok (host " << config.hostname << ", source " << config.source
              << ", ui " << (config.ui.enabled ? config.ui.listen : std::string("off")) << ")\n";
  });
  auto* rend =
      image->add_subcommand("render", "Write the files a robot configuration puts into an image");
  rend->add_option("FILE", args->config, "robot.yaml")->required();
  rend->add_option("--arch", args->arch, "amd64 or arm64")->required();
  rend->add_option("--out", args->out, "output directory")->required();
  rend->callback([args] { render(*args); });
}

}  // namespace orthoflow::apps
