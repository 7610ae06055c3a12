#include <CLI/CLI.hpp>

int main(int argc, char** argv) {
  CLI::App app{"orthoflow: real-time open-ended 3D object perception"};
  app.require_subcommand(1);
  CLI11_PARSE(app, argc, argv);
  return 0;
}
