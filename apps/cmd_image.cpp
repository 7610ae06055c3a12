// `orthoflow image check|render`: a robot image's configuration (issue 24, docs/DEPLOY.md).
// `check ROBOT.yaml` validates it; `render ROBOT.yaml --arch A --out DIR` writes what
// scripts/build_image.sh puts into the image: DIR/rootfs/ (files over the root file system: host
// name, fstab, network, the orthoflow unit and its settings, the robot.yaml itself, the token,
// graph and SSH key files it names), DIR/grub.cfg (the boot loader's configuration), DIR/cmdline
// (the kernel command line) and DIR/layout (partition sizes, extra packages).
#include <sys/stat.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <string>

#include "apps/commands.hpp"
#include "apps/graph_run.hpp"
#include "core/file_output.hpp"
#include "core/regular_file.hpp"
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

/// A robot.yaml and the files it names, each read once: what was checked is what the image gets.
struct LoadedConfig {
  deploy::RobotConfig config;
  std::string yaml, token, keys, graph;
};

/// A file robot.yaml names under @p key: resolved (symbolic links too) inside the config's own
/// folder, a regular file of at most @p limit bytes, read once.
std::string named_file(const std::string& config, const std::string& key, const std::string& name,
                       std::size_t limit) {
  std::error_code ec;
  const fs::path here = fs::canonical(fs::absolute(fs::path(config)).parent_path(), ec);
  if (ec)
    fail(config + ": the config's folder cannot be resolved: " + ec.message(), EXIT_BAD_INPUT);
  const fs::path file = fs::canonical(here / name, ec);
  if (ec)
    fail(config + ": " + key + ": " + (here / name).string() + " is not a file (" + ec.message() +
             ")",
         EXIT_BAD_INPUT);
  if (std::mismatch(here.begin(), here.end(), file.begin(), file.end()).first != here.end())
    fail(config + ": " + key + ": '" + name + "' leads outside the config's folder " +
             here.string() + " (to " + file.string() + ")",
         EXIT_BAD_INPUT);
  auto text = core::read_regular_text(file, limit);
  if (!text) fail(config + ": " + key + ": " + text.error().message, EXIT_BAD_INPUT);
  return *text;
}

LoadedConfig load_or_throw(const std::string& path) {
  auto config = deploy::load_robot_config(path);
  if (!config) fail(config.error(), EXIT_BAD_INPUT);
  LoadedConfig loaded{*config, {}, {}, {}, {}};
  auto yaml = core::read_regular_text(path, std::size_t{1} << 20);
  if (!yaml) fail(yaml.error().message, EXIT_BAD_INPUT);
  loaded.yaml = std::move(*yaml);
  // The files it names must be there now, at build time, and be what they claim to be.
  if (config->ui.enabled && !config->ui.token_file.empty()) {
    loaded.token = named_file(path, "ui.token_file", config->ui.token_file, 4096);
    if (auto t = ui::token_from_text(loaded.token, path + ": ui.token_file"); !t)
      fail(t.error(), EXIT_BAD_INPUT);
  }
  if (!config->admin.ssh_authorized_keys.empty()) {
    loaded.keys =
        named_file(path, "admin.ssh_authorized_keys", config->admin.ssh_authorized_keys, 1 << 16);
    if (auto ok = deploy::check_authorized_keys(loaded.keys); !ok)
      fail(path + ": admin.ssh_authorized_keys: " + ok.error(), EXIT_BAD_INPUT);
  }
  if (config->graph != "tabletop") {
    loaded.graph = named_file(path, "graph", config->graph, std::size_t{1} << 20);
    auto spec = engine::parse_graph(loaded.graph, config->graph);
    if (!spec) fail(path + ": graph: " + engine::to_string(spec.error()), EXIT_BAD_INPUT);
    auto built = engine::build_graph(*spec, make_graph_registry(), engine::BuildMode::CHECK);
    if (!built) fail(path + ": graph: " + engine::to_string(built.error()), EXIT_BAD_INPUT);
  }
  return loaded;
}

void write_file(const fs::path& path, const std::string& text, unsigned mode) {
  std::error_code ec;
  fs::create_directories(path.parent_path(), ec);
  if (auto written = core::write_whole_file(path, text); !written)
    fail("cannot write " + written.error(), EXIT_FAILURE_GENERIC);
  if (::chmod(path.c_str(), mode) != 0) fail("cannot chmod " + path.string(), EXIT_FAILURE_GENERIC);
}

void render(const ImageArgs& a) {
  auto arch = deploy::parse_arch(a.arch);
  if (!arch) fail(arch.error(), EXIT_USAGE);
  const LoadedConfig loaded = load_or_throw(a.config);
  const deploy::RobotConfig& config = loaded.config;
  const fs::path out(a.out);
  const fs::path root = out / "rootfs";
  for (const auto& f : deploy::root_files(config)) write_file(root / f.path, f.text, f.mode);
  write_file(root / "etc/orthoflow/robot.yaml", loaded.yaml, 0644);
  if (config.ui.enabled && !config.ui.token_file.empty())
    write_file(root / "etc/orthoflow/ui-token", loaded.token, 0640);
  if (config.graph != "tabletop") write_file(root / "etc/orthoflow/graph.yaml", loaded.graph, 0644);
  if (!config.admin.ssh_authorized_keys.empty()) {
    write_file(root / "root/.ssh/authorized_keys", loaded.keys, 0600);
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
    const auto config = load_or_throw(args->config).config;
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
