#include <iostream>

#include "commands.hpp"
#include "shadowfilter/runtime.hpp"

namespace sf::cli {

CLI::App* add_devices_command(CLI::App& app, DevicesArgs&) {
  return app.add_subcommand("devices", "List OpenCL platforms and devices (pick one with --device P:D)");
}

int run_devices(const DevicesArgs&) {
  auto devices = list_devices();
  if (devices.empty()) {
    std::cout << "no OpenCL devices found (install an ICD, e.g. pocl-opencl-icd)\n";
    return 1;
  }
  const std::string chosen = [] {
    try {
      return Runtime::create()->info().device_name;
    } catch (const std::exception&) {
      return std::string();
    }
  }();
  for (const auto& d : devices) {
    std::cout << d.platform_index << ":" << d.device_index << "  " << d.type << "  " << d.device_name << "  ["
              << d.platform_name << ", driver " << d.driver_version << "]  " << (d.global_mem_bytes >> 20) << " MiB, "
              << d.compute_units << " compute units" << (d.device_name == chosen ? "  (default)" : "") << "\n";
  }
  return 0;
}

}  // namespace sf::cli
