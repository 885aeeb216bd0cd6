#pragma once
// Runs the `shadowfilter` binary (SF_CLI_PATH) for the CLI tests: exit code, stdout and stderr.
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace sf::test {

struct RunResult {
  int exit_code = -1;
  std::string out, err;
};

inline std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// `shadowfilter ARGS`, its output captured through files in `dir` (removed afterwards); `env`:
// variable assignments for the command ("NAME=value ...").
inline RunResult run_cli(const std::string& args, const std::string& dir, const std::string& env = "") {
  const std::string out = dir + "/stdout.txt", err = dir + "/stderr.txt";
  const std::string cmd =
      (env.empty() ? "" : env + " ") + std::string(SF_CLI_PATH) + " " + args + " > " + out + " 2> " + err;
  const int status = std::system(cmd.c_str());
  RunResult r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = slurp(out);
  r.err = slurp(err);
  std::filesystem::remove(out);
  std::filesystem::remove(err);
  return r;
}

inline size_t count_lines(const std::string& s) {
  size_t n = 0;
  for (char c : s) n += (c == '\n');
  return n;
}

}  // namespace sf::test
