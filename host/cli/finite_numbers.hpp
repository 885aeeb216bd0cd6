#pragma once
// Every number option of the command line must be finite: "nan", "inf" and values past the
// float range (1e50 parses to +inf in a float) are input errors, never a silent default or a
// NaN passed on to the library.
#include <CLI/CLI.hpp>

namespace sf::cli {

// Adds the finiteness check to every floating-point option (CLI11 type name FLOAT, vectors
// included: each element is checked) of `app` and of all its subcommands.
void require_finite_numbers(CLI::App& app);

}  // namespace sf::cli
