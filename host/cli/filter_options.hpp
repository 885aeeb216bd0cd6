#pragma once
// The `filter` command's option groups: each registers its flags and summarises what ran.
#include <CLI/CLI.hpp>

#include <string>

#include "shadowfilter/options.hpp"

namespace sf::cli {

// --receiver-plane, --receiver-plane-max-slope and --slope-bias of the depth tests `methods`
// names (options_methods.cpp; filter and soft).
void add_receiver_plane_options(CLI::App& cmd, ReceiverPlaneOptions& opt, const std::string& methods);

// --method and every method's parameters (options_methods.cpp).
void add_method_options(CLI::App& cmd, FilterOptions& opt);
std::string method_summary(const FilterOptions& opt);

// Prefilter (blur) and lookup options (options_prefilter.cpp).
void add_prefilter_options(CLI::App& cmd, FilterOptions& opt);
std::string prefilter_summary(const FilterOptions& opt);

}  // namespace sf::cli
