// hardbody: thin entry point. Subcommands parse their arguments and call the library.
// Exit status: 0 success, 2 bad input, 3 failure at run time.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>

#include "io/config.hpp"
#include "io/run.hpp"

int main(int argc, char** argv) {
  CLI::App app{"hardbody: event-driven molecular dynamics of hard rigid bodies"};
  app.require_subcommand(1);

  hb::RunOptions run;
  auto* cmd_run = app.add_subcommand("run", "run a simulation from a TOML config");
  cmd_run->add_option("config", run.config_path, "configuration file (TOML)")->required();
  cmd_run->add_option("--out", run.out_dir, "output directory (default ./run-<config stem>)");
  cmd_run->add_option("--set", run.overrides, "override a key: section.key=value")->take_all();
  cmd_run->add_flag("--resume", run.resume, "continue from checkpoint.gsd in the output directory");
  cmd_run->add_flag("--quiet", run.quiet, "no progress line");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : 2;
  }
  try {
    if (cmd_run->parsed()) hb::run_simulation(run);
    return 0;
  } catch (const hb::ConfigError& e) {
    std::fprintf(stderr, "hardbody: error: %s\n", e.what());
    return 2;
  } catch (const hb::InputError& e) {
    std::fprintf(stderr, "hardbody: error: %s\n", e.what());
    return 2;
  } catch (const hb::RunInterrupted& e) {
    std::fprintf(stderr, "hardbody: %s\n", e.what());
    return 128 + e.signal;
  } catch (const hb::RunFailure& e) {
    std::fprintf(stderr, "hardbody: run failed: %s\n", e.what());
    return 3;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "hardbody: run failed: %s\n", e.what());
    return 3;
  }
}
