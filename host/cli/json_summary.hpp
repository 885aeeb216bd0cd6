#pragma once
// `--json`: a command's summary as one JSON object on stdout, for scripts (instead of the
// summary line, whose wording may change).
#include <nlohmann/json.hpp>

#include <string>
#include <vector>

#include "shadowfilter/options.hpp"
#include "shadowfilter/pipeline.hpp"

namespace sf::cli {

// Device milliseconds per stage; the stages that did not run are left out.
nlohmann::json stage_ms_json(const StageTimes& times, double scale = 1.0);
// The method, its parameters as `shadowfilter methods` names them, storage, prefilter and lookup.
nlohmann::json filter_options_json(const FilterOptions& options);
// Prints the object on one line.
void print_json(const nlohmann::json& summary);

}  // namespace sf::cli
