// kartograf: the command-line front end. Subcommands live in *_command.cpp.
#include <csignal>
#include <cstdlib>
#include <exception>
#include <iostream>
#include <new>
#include <string>

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "interrupts.hpp"
#include "output_transaction.hpp"

namespace {

int report_error(const std::string& message) {
  std::cout.flush();
  std::cerr << "kartograf: error: " << kartograf::cli::describe_output_error(message) << "\n";
  kartograf::cli::exit_if_interrupted();  // a signal that waited for the error: its exit status
  return 1;
}

// `demo`: its --backend defaults to $KARTOGRAF_BACKEND; backend_option tells whether it was given.
CLI::App* add_demo_subcommand(CLI::App& app, kartograf::cli::DemoOptions& options,
                              CLI::Option*& backend_option) {
  if (const char* env_backend = std::getenv("KARTOGRAF_BACKEND"); env_backend && *env_backend) {
    options.backend = env_backend;
    options.backend_source = "KARTOGRAF_BACKEND";
  }
  CLI::App* demo = app.add_subcommand("demo",
                                      "Render a frame of the synthetic world, back-project, "
                                      "estimate normals, write pictures and a PLY");
  demo->add_option("--out", options.out_dir, "Output directory")->capture_default_str();
  backend_option =
      demo->add_option("--backend", options.backend,
                       "auto|cpu|vulkan|opencl (default: $KARTOGRAF_BACKEND, else auto)");
  demo->add_flag("--force", options.force, "Replace the files of an earlier run");
  return demo;
}

}  // namespace

int main(int argc, char** argv) {
  // Before any thread exists: every thread inherits the blocked signals (interrupts.hpp).
  kartograf::cli::start_interrupt_watcher();
  // A file over RLIMIT_FSIZE fails like a full disk (EFBIG), with a message, instead of killing.
  std::signal(SIGXFSZ, SIG_IGN);
  CLI::App app{"Kartograf: dense RGB-D mapping on CPU, Vulkan and OpenCL"};
  app.require_subcommand(1);

  CLI::App* devices = app.add_subcommand("devices", "List compute backends and their devices");

  kartograf::cli::DemoOptions demo_options;
  CLI::Option* backend_option = nullptr;
  CLI::App* demo = add_demo_subcommand(app, demo_options, backend_option);

  kartograf::cli::EvalOptions eval_options;
  CLI::App* eval = kartograf::cli::add_eval_command(app, eval_options);
  kartograf::cli::SynthOptions synth_options;
  CLI::App* synth = kartograf::cli::add_synth_command(app, synth_options);
  kartograf::cli::OdometryOptions odometry_options;
  CLI::App* odometry = kartograf::cli::add_odometry_command(app, odometry_options);
  kartograf::cli::SlamOptions slam_options;
  CLI::App* slam = kartograf::cli::add_slam_command(app, slam_options);
  kartograf::cli::PlanesOptions planes_options;
  CLI::App* planes = kartograf::cli::add_planes_command(app, planes_options);
  kartograf::cli::RoomsOptions rooms_options;
  CLI::App* rooms = kartograf::cli::add_rooms_command(app, rooms_options);
  kartograf::cli::RoomsEvalOptions rooms_eval_options;
  CLI::App* rooms_eval = kartograf::cli::add_rooms_eval_command(app, rooms_eval_options);
  kartograf::cli::SemanticOptions semantic_options;
  CLI::App* semantic = kartograf::cli::add_semantic_command(app, semantic_options);
  kartograf::cli::MapOptions map_options;
  CLI::App* map = kartograf::cli::add_map_command(app, map_options);
  kartograf::cli::FuseOptions fuse_options;
  CLI::App* fuse = kartograf::cli::add_fuse_command(app, fuse_options);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 1;
  }
  if (backend_option->count() > 0) demo_options.backend_source = "--backend";

  try {
    if (*devices) return kartograf::cli::run_devices_command(std::cout);
    if (*demo) return kartograf::cli::run_demo_command(demo_options, std::cout);
    if (*eval) return kartograf::cli::run_eval_command(eval_options, std::cout);
    if (*synth) return kartograf::cli::run_synth_command(synth_options, std::cout, std::cerr);
    if (*odometry) {
      return kartograf::cli::run_odometry_command(odometry_options, std::cout, std::cerr);
    }
    if (*slam) return kartograf::cli::run_slam_command(slam_options, std::cout, std::cerr);
    if (*planes) return kartograf::cli::run_planes_command(planes_options, std::cout, std::cerr);
    if (*rooms) {
      const bool resolution_given = rooms->get_option("--resolution")->count() > 0;
      return kartograf::cli::run_rooms_command(rooms_options, resolution_given, std::cout);
    }
    if (*rooms_eval) {
      return kartograf::cli::run_rooms_eval_command(rooms_eval_options, std::cout, std::cerr);
    }
    if (*map) return kartograf::cli::run_map_command(map_options, std::cout, std::cerr);
    if (*fuse) return kartograf::cli::run_fuse_command(fuse_options, std::cout, std::cerr);
    if (*semantic)
      return kartograf::cli::run_semantic_command(semantic_options, std::cout, std::cerr);
  } catch (const std::bad_alloc&) {
    const std::string command = app.get_subcommands().front()->get_name();
    return report_error("out of memory (std::bad_alloc) in 'kartograf " + command +
                        "': the input or the options need more memory than this machine has; "
                        "try a smaller input, fewer frames or coarser options");
  } catch (const std::exception& e) {
    return report_error(e.what());
  }
  return 1;
}
