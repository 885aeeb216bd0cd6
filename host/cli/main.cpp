// `shadowfilter`: a thin command-line client of the library.
#include <CLI/CLI.hpp>

#include <csignal>
#include <iostream>
#include <new>

#include "commands.hpp"
#include "finite_numbers.hpp"
#include "interrupts.hpp"
#include "help_format.hpp"
#include "option_names.hpp"
#include "output_file.hpp"
#include "options_soft.hpp"
#include "shadowfilter/errors.hpp"
#include "shadowfilter/runtime.hpp"

namespace {

// The one error boundary: every exception that leaves a command, its option parsing included,
// becomes one line and an exit code (2 input, 3 OpenCL, 1 anything else); none reaches
// std::terminate.
int exit_for_current_exception() {
  try {
    throw;
  } catch (const sf::InputError& e) {
    std::cerr << "shadowfilter: error: " << sf::cli::cli_message(e.what()) << "\n";
    return 2;
  } catch (const sf::DeviceError& e) {
    std::cerr << "shadowfilter: device error: " << e.what() << "\n";
    return 3;
  } catch (const cl::Error& e) {
    std::cerr << "shadowfilter: OpenCL error " << e.err() << " in " << e.what() << "\n";
    return 3;
  } catch (const std::bad_alloc&) {
    std::cerr << "shadowfilter: out of memory\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "shadowfilter: " << e.what() << "\n";
    return 1;
  } catch (...) {
    std::cerr << "shadowfilter: unknown error\n";
    return 1;
  }
}

}  // namespace

int main(int argc, char** argv) try {
  sf::cli::watch_interrupts();
  // Past a file size limit (ulimit -f) a write fails with EFBIG and is reported like a full disk,
  // instead of the default SIGXFSZ ending the process mid-write.
  std::signal(SIGXFSZ, SIG_IGN);
  sf::io::guard_inputs_read(true);  // no output of a command replaces a file it read
  CLI::App app{"shadowfilter: pre-filtered shadow maps on OpenCL devices"};
  app.formatter(sf::cli::wrapping_formatter(sf::cli::help_width()));  // before the commands: they inherit it
  app.require_subcommand(1);
  app.set_help_all_flag("--help-all", "Help for every command");
  app.set_version_flag("--version", "shadowfilter " SF_VERSION);
  sf::cli::DevicesArgs devices_args;
  sf::cli::MethodsArgs methods_args;
  sf::cli::FilterArgs filter_args;
  sf::cli::SceneArgs scene_args;
  CLI::App* devices = sf::cli::add_devices_command(app, devices_args);
  CLI::App* methods = sf::cli::add_methods_command(app, methods_args);
  CLI::App* filter = sf::cli::add_filter_command(app, filter_args);
  CLI::App* scene = sf::cli::add_scene_command(app, scene_args);
  sf::cli::EvaluateArgs evaluate_args;
  CLI::App* evaluate = sf::cli::add_evaluate_command(app, evaluate_args);
  sf::cli::EvaluateLayoutsArgs layouts_args;
  CLI::App* evaluate_layouts = sf::cli::add_evaluate_layouts_command(app, layouts_args);
  sf::cli::SoftArgs soft_args;
  CLI::App* soft = sf::cli::add_soft_command(app, soft_args);
  sf::cli::ReceiversArgs receivers_args;
  CLI::App* receivers = sf::cli::add_receivers_command(app, receivers_args);
  sf::cli::CoherentCommands coherent;
  sf::cli::add_coherent_command(app, coherent);
  sf::cli::require_finite_numbers(app);
  sf::cli::add_examples(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::cerr << "shadowfilter: " << e.what() << " (see --help)\n";
    return 2;
  }
  if (devices->parsed()) return sf::cli::run_devices(devices_args);
  if (methods->parsed()) return sf::cli::run_methods(methods_args);
  if (filter->parsed()) return sf::cli::run_filter(filter_args);
  if (scene->parsed()) return sf::cli::run_scene(scene_args);
  if (evaluate->parsed()) return sf::cli::run_evaluate(evaluate_args);
  if (evaluate_layouts->parsed()) return sf::cli::run_evaluate_layouts(layouts_args);
  if (soft->parsed()) return sf::cli::run_soft(soft_args);
  if (receivers->parsed()) return sf::cli::run_receivers(receivers_args);
  if (coherent.app->parsed()) return sf::cli::run_coherent(coherent);
  return 1;
} catch (...) {
  return exit_for_current_exception();
}
