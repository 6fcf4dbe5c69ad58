// hardbody: thin entry point. Subcommands parse their arguments and call the library.
// Exit status: 0 success, 2 bad input, 3 failure at run time.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>

#include <string>
#include <vector>
#include <unistd.h>

#include "io/config.hpp"
#include "io/convert.hpp"
#include "io/pair_query.hpp"

#include <filesystem>
#include <fstream>
#include <iostream>
#include "io/run.hpp"

int main(int argc, char** argv) {
  CLI::App app{"hardbody: event-driven molecular dynamics of hard rigid bodies"};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("hardbody ") + HB_VERSION);
  app.footer(std::string("Documentation: ") + HB_DOCS_DIR +
             " (README.md; config.md lists every config key, observables.md every output).\n"
             "Exit status: 0 done, 2 bad input (nothing written), 3 run-time failure (checkpoint "
             "written), 128+signal interrupted (continue with --resume).");

  hb::RunOptions run;
  auto* cmd_run = app.add_subcommand("run", "run a simulation from a TOML config");
  cmd_run->add_option("config", run.config_path, "configuration file (TOML)")->required();
  cmd_run->add_option("--out", run.out_dir, "output directory (default ./run-<config stem>)");
  // one value per --set (a config path after `--set k=v` once was swallowed as another value)
  cmd_run->add_option("--set", run.overrides, "override a key: section.key=value (repeat for more)")
      ->expected(1)
      ->allow_extra_args(false)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  cmd_run->add_flag("--resume", run.resume, "continue from checkpoint.gsd in the output directory");
  cmd_run->add_flag("--overwrite", run.overwrite, "replace a previous run in the output directory");
  cmd_run->add_flag("--quiet", run.quiet, "no progress line");

  std::string conv_in, conv_out, conv_to = "xyz";
  auto* cmd_conv = app.add_subcommand("convert", "convert a GSD trajectory (extended XYZ for OVITO)");
  cmd_conv->add_option("trajectory", conv_in, "GSD file")->required();
  cmd_conv->add_option("--to", conv_to, "output format")->check(CLI::IsMember({"xyz"}));
  cmd_conv->add_option("-o,--output", conv_out, "output file (default: input with .xyz)");

  std::string dist_file, ct_file;
  double ct_eps = 1e-5;
  auto* cmd_dist = app.add_subcommand("distance", "distance of body pairs (JSON lines)");
  cmd_dist->add_option("file", dist_file, "JSON-lines input (default stdin)");
  auto* cmd_ct = app.add_subcommand("contact-time", "first contact time of moving pairs (JSON lines)");
  cmd_ct->add_option("file", ct_file, "JSON-lines input (default stdin)");
  // (range checked by contact_time_queries against each pair's size, with a readable message:
  // CLI::PositiveNumber printed DBL_MAX in 309 digits)
  cmd_ct->add_option("--eps-d", ct_eps, "distance accuracy epsilon_d (a length, default 1e-5)");

  auto* cmd_ref = app.add_subcommand("config-reference", "print the reference of every config key (docs/config.md)");

  std::string plot_dir;
  auto* cmd_plot = app.add_subcommand("plot", "write PNG plots of a run directory");
  cmd_plot->add_option("run_dir", plot_dir, "run directory")->required();

  // Campaigns (many runs over a grid of --set values, locally or as Slurm job arrays) are driven
  // by the Python workflow in python/hardbody_campaign.py; its arguments are passed through.
  std::vector<std::string> campaign_args;
  auto* cmd_campaign = app.add_subcommand("campaign", "run or inspect a campaign of many runs (docs/campaigns.md)");
  cmd_campaign->allow_extras();
  cmd_campaign->prefix_command();
  cmd_campaign->set_help_flag();  // `hardbody campaign --help` is the driver's own help

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : 2;
  }
  try {
    if (cmd_run->parsed()) {
      run.out_given = cmd_run->get_option("--out")->count() > 0;
      hb::run_simulation(run);
    }
    if (cmd_ref->parsed()) std::cout << hb::config_reference();
    auto lines = [](const std::string& file, auto&& fn) {
      if (file.empty()) return fn(std::cin, std::string("<stdin>"));
      // (an ifstream opens a directory, and its first read fails like an empty file's end)
      if (std::filesystem::is_directory(file))
        throw hb::InputError(file + ": is a directory, not a JSON-lines file");
      std::ifstream in(file);
      if (!in) throw hb::InputError(file + ": cannot open");
      return fn(in, file);
    };
    if (cmd_dist->parsed())
      lines(dist_file, [](std::istream& in, const std::string& src) {
        return hb::distance_queries(in, std::cout, src);
      });
    if (cmd_ct->parsed())
      lines(ct_file, [&](std::istream& in, const std::string& src) {
        return hb::contact_time_queries(in, std::cout, src, ct_eps);
      });
    if (cmd_conv->parsed()) {
      if (conv_out.empty()) {
        conv_out = conv_in;
        const auto dot = conv_out.rfind(".gsd");
        if (dot != std::string::npos) conv_out.erase(dot);
        conv_out += ".xyz";
      }
      try {
        hb::convert_gsd_to_xyz(conv_in, conv_out);
      } catch (const std::runtime_error& e) {
        throw hb::InputError(e.what());
      }
    }
    if (cmd_campaign->parsed()) {
      const std::string script = std::string(HB_PYTHON_DIR) + "/hardbody_campaign.py";
      std::vector<std::string> args{"python3", script};
      for (const auto& a : cmd_campaign->remaining()) args.push_back(a);
      std::vector<char*> argv2;
      for (auto& a : args) argv2.push_back(a.data());
      argv2.push_back(nullptr);
      // the campaign runs this very executable
      setenv("HARDBODY", std::filesystem::canonical("/proc/self/exe").c_str(), 0);
      execv("/usr/bin/python3", argv2.data());
      std::perror("hardbody campaign: cannot start /usr/bin/python3");
      return 3;
    }
    if (cmd_plot->parsed()) {
      // The plots are Python (matplotlib); Debian's interpreter sees python3-matplotlib.
      const std::string script = std::string(HB_PYTHON_DIR) + "/hardbody_plot.py";
      execl("/usr/bin/python3", "python3", script.c_str(), plot_dir.c_str(), (char*)nullptr);
      std::perror("hardbody plot: cannot start /usr/bin/python3");
      return 3;
    }
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
