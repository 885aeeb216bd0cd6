#include <iostream>

#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "shadowfilter/runtime.hpp"

namespace sf::cli {

CLI::App* add_devices_command(CLI::App& app, DevicesArgs& a) {
  CLI::App* c = app.add_subcommand("devices", "List OpenCL platforms and devices (pick one with --device P:D)");
  c->add_flag("--json", a.json, "Print the devices as a JSON array");
  c->footer("Example:\n  shadowfilter devices\n  shadowfilter filter ... --device 0:0");
  return c;
}

int run_devices(const DevicesArgs& a) {
  auto devices = list_devices();
  if (devices.empty()) {
    if (a.json) std::cout << "[]\n";
    std::cout << (a.json ? "" : "no OpenCL devices found (install an ICD, e.g. pocl-opencl-icd)\n");
    return 1;
  }
  const std::string chosen = [] {
    try {
      return Runtime::create()->info().device_name;
    } catch (const std::exception&) {
      return std::string();
    }
  }();
  if (a.json) {
    nlohmann::json list = nlohmann::json::array();
    for (const auto& d : devices)
      list.push_back({{"device", std::to_string(d.platform_index) + ":" + std::to_string(d.device_index)},
                      {"type", d.type},
                      {"name", d.device_name},
                      {"platform", d.platform_name},
                      {"driver", d.driver_version},
                      {"global_mem_mib", d.global_mem_bytes >> 20},
                      {"compute_units", d.compute_units},
                      {"default", d.device_name == chosen}});
    std::cout << list.dump() << "\n";
    return 0;
  }
  for (const auto& d : devices) {
    std::cout << d.platform_index << ":" << d.device_index << "  " << d.type << "  " << d.device_name << "  ["
              << d.platform_name << ", driver " << d.driver_version << "]  " << (d.global_mem_bytes >> 20) << " MiB, "
              << d.compute_units << " compute units" << (d.device_name == chosen ? "  (default)" : "") << "\n";
  }
  return 0;
}

}  // namespace sf::cli
