#pragma once
// The rows of the defaults sweep (measure_defaults_sweep.cpp writes them, measure_defaults_tables.cpp
// reads them back): one per scene x method x candidate setting, as CSV so that the tables can be
// printed again, or from several runs at once, without measuring.
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace sf::test::sweep {

struct Row {
  std::string scene;                    // the scene directory's name and the map size: "spheres-512"
  std::string method;                   // registry or soft method name
  std::string candidate;                // the setting's label (no commas)
  bool is_default = false;              // the candidate equals default-constructed options
  double acne = 0, leak = 0;            // fractions (eval::acne_leak, receivers facing the light)
  size_t lit = 0, shadowed = 0;         // receivers lit / shadowed inside (the classes' sizes)
  double soft_rmse = 0, hard_rmse = 0;  // against reference_soft / reference_hard, same receivers
};

inline const char* kCsvHeader =
    "scene,method,candidate,default,acne,leak,lit_inside,shadowed_inside,soft_rmse,hard_rmse";

inline std::string csv_line(const Row& r) {
  char buf[512];
  std::snprintf(buf, sizeof buf, "%s,%s,%s,%d,%.8f,%.8f,%zu,%zu,%.8f,%.8f", r.scene.c_str(), r.method.c_str(),
                r.candidate.c_str(), r.is_default ? 1 : 0, r.acne, r.leak, r.lit, r.shadowed, r.soft_rmse, r.hard_rmse);
  return buf;
}

inline void write_csv(const std::string& path, const std::vector<Row>& rows) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp);
    if (!out) throw std::runtime_error("cannot write " + tmp);
    out << kCsvHeader << "\n";
    for (const Row& r : rows) out << csv_line(r) << "\n";
    if (!out) throw std::runtime_error("cannot write " + tmp);
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) throw std::runtime_error("cannot rename " + tmp);
}

inline std::vector<Row> read_csv(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read " + path);
  std::string line;
  std::getline(in, line);
  if (line != kCsvHeader) throw std::runtime_error(path + ": not a defaults sweep CSV");
  std::vector<Row> rows;
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    std::vector<std::string> f;
    std::istringstream s(line);
    for (std::string cell; std::getline(s, cell, ',');) f.push_back(cell);
    if (f.size() != 10) throw std::runtime_error(path + ": bad line '" + line + "'");
    Row r;
    r.scene = f[0];
    r.method = f[1];
    r.candidate = f[2];
    r.is_default = f[3] == "1";
    r.acne = std::stod(f[4]);
    r.leak = std::stod(f[5]);
    r.lit = std::stoul(f[6]);
    r.shadowed = std::stoul(f[7]);
    r.soft_rmse = std::stod(f[8]);
    r.hard_rmse = std::stod(f[9]);
    rows.push_back(r);
  }
  return rows;
}

}  // namespace sf::test::sweep
