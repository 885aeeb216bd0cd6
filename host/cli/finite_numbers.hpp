#pragma once
// Every number option of the command line must be finite: "nan", "inf" and values past the
// float range (1e50 parses to +inf in a float) are input errors, never a silent default or a
// NaN passed on to the library.
#include <CLI/CLI.hpp>

#include <string>
#include <vector>

namespace sf::cli {

// Adds the finiteness check to every floating-point option (CLI11 type name FLOAT, vectors
// included: each element is checked) of `app` and of all its subcommands.
void require_finite_numbers(CLI::App& app);

// --light-size of `soft` and `scene`: an area light's sides, "L" (a square) or "W,H" (W along the
// light's right, the map's u axis; H along its down, v), each a finite number >= 0 that a float
// holds, into `sides` (one or two values). Given once: a second --light-size is an error, not
// the rectangle's other side.
CLI::Option* add_light_size_option(CLI::App* command, std::vector<double>& sides, const std::string& help);

}  // namespace sf::cli
