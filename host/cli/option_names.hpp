#pragma once
// The library names option fields in its messages ("FilterOptions::esm.c must be ..."); the
// command speaks of its own flags. cli_message rewrites every field the CLI sets by a flag.
#include <string>

namespace sf::cli {

std::string cli_message(std::string library_message);

}  // namespace sf::cli
