// `shadowfilter`'s commands as a function (run.hpp): option parsing and the one error boundary.
#include "run.hpp"

#include <CLI/CLI.hpp>

#include <iostream>
#include <new>

#include "commands.hpp"
#include "finite_numbers.hpp"
#include "help_format.hpp"
#include "option_names.hpp"
#include "output_file.hpp"
#include "options_soft.hpp"
#include "print.hpp"
#include "shadowfilter/errors.hpp"
#include "shadowfilter/runtime.hpp"

namespace sf::cli {
namespace {

// The one error boundary: every exception that leaves a command, its option parsing included,
// becomes one line and an exit code (2 input, 3 OpenCL, 1 anything else); none reaches
// std::terminate.
int exit_for_current_exception() {
  try {
    throw;
  } catch (const sf::InputError& e) {
    std::cerr << "shadowfilter: error: " << cli_message(e.what()) << "\n";
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

// std::cout and std::cerr write to the caller's streams for the life of a run, and the guard of
// inputs read is on; both are restored however the run ends.
class RunScope {
 public:
  RunScope(std::ostream& out, std::ostream& err)
      : cout_(std::cout.rdbuf(out.rdbuf())), cerr_(std::cerr.rdbuf(err.rdbuf())) {
    set_process_streams(&out == &std::cout && &err == &std::cerr);
    sf::io::guard_inputs_read(true);  // no output of a command replaces a file it read
  }
  ~RunScope() {
    sf::io::guard_inputs_read(false);
    std::cout.flush();
    std::cerr.flush();
    std::cout.rdbuf(cout_);
    std::cerr.rdbuf(cerr_);
    set_process_streams(true);
  }
  RunScope(const RunScope&) = delete;
  RunScope& operator=(const RunScope&) = delete;

 private:
  std::streambuf* cout_;
  std::streambuf* cerr_;
};

int run_command(const std::vector<std::string>& args) try {
  CLI::App app{"shadowfilter: pre-filtered shadow maps on OpenCL devices"};
  app.formatter(wrapping_formatter(help_width()));  // before the commands: they inherit it
  app.require_subcommand(1);
  app.set_help_all_flag("--help-all", "Help for every command");
  app.set_version_flag("--version", "shadowfilter " SF_VERSION);
  DevicesArgs devices_args;
  MethodsArgs methods_args;
  FilterArgs filter_args;
  SceneArgs scene_args;
  CLI::App* devices = add_devices_command(app, devices_args);
  CLI::App* methods = add_methods_command(app, methods_args);
  CLI::App* filter = add_filter_command(app, filter_args);
  CLI::App* scene = add_scene_command(app, scene_args);
  EvaluateArgs evaluate_args;
  CLI::App* evaluate = add_evaluate_command(app, evaluate_args);
  EvaluateLayoutsArgs layouts_args;
  CLI::App* evaluate_layouts = add_evaluate_layouts_command(app, layouts_args);
  SoftArgs soft_args;
  CLI::App* soft = add_soft_command(app, soft_args);
  ReceiversArgs receivers_args;
  CLI::App* receivers = add_receivers_command(app, receivers_args);
  CoherentCommands coherent;
  add_coherent_command(app, coherent);
  require_finite_numbers(app);
  add_examples(app);
  try {
    std::vector<std::string> reversed(args.rbegin(), args.rend());  // CLI11 takes them last first
    app.parse(reversed);
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
  if (devices->parsed()) return run_devices(devices_args);
  if (methods->parsed()) return run_methods(methods_args);
  if (filter->parsed()) return run_filter(filter_args);
  if (scene->parsed()) return run_scene(scene_args);
  if (evaluate->parsed()) return run_evaluate(evaluate_args);
  if (evaluate_layouts->parsed()) return run_evaluate_layouts(layouts_args);
  if (soft->parsed()) return run_soft(soft_args);
  if (receivers->parsed()) return run_receivers(receivers_args);
  if (coherent.app->parsed()) return run_coherent(coherent);
  return 1;
} catch (...) {
  return exit_for_current_exception();
}

}  // namespace

int run(const std::vector<std::string>& args, std::ostream& out, std::ostream& err) {
  const RunScope scope(out, err);
  return run_command(args);
}

}  // namespace sf::cli
