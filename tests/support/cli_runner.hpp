#pragma once
// Runs `shadowfilter` for the CLI tests: exit code, stdout and stderr.
//   run_cli          in process, through sf::cli::run (host/cli/run.hpp): what a command says,
//                    its exit code and what it writes, without a process start per run.
//   run_cli_process  the built binary (SF_CLI_PATH) through the shell: for what only a process
//                    has (signals, resource limits, environment read once per process such as
//                    PoCL's, main's own set-up).
#include <stdlib.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "run.hpp"

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

// The words of a command line as a shell splits them: blanks separate, single and double quotes
// group. Redirections, pipes and substitutions are not meant for run_cli: they throw.
inline std::vector<std::string> split_args(const std::string& line) {
  std::vector<std::string> words;
  std::string word;
  bool in_word = false;
  for (size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (c == ' ' || c == '\t' || c == '\n') {
      if (in_word) words.push_back(word);
      word.clear();
      in_word = false;
    } else if (c == '\'' || c == '"') {
      const size_t end = line.find(c, i + 1);
      if (end == std::string::npos) throw std::invalid_argument("run_cli: unclosed quote in: " + line);
      word += line.substr(i + 1, end - i - 1);
      in_word = true;
      i = end;
    } else if (c == '<' || c == '>' || c == '|' || c == '$' || c == '`' || c == ';' || c == '&' || c == '\\') {
      throw std::invalid_argument(std::string("run_cli: shell syntax '") + c + "' needs run_cli_process: " + line);
    } else {
      word += c;
      in_word = true;
    }
  }
  if (in_word) words.push_back(word);
  return words;
}

// Environment variables set for a scope, and restored.
class ScopedEnvironment {
 public:
  // `assignments`: "NAME=value NAME2=value2" (an empty value sets the variable empty).
  explicit ScopedEnvironment(const std::string& assignments) {
    for (const std::string& a : split_args(assignments)) {
      const size_t eq = a.find('=');
      if (eq == std::string::npos) throw std::invalid_argument("run_cli: not NAME=value: " + a);
      const std::string name = a.substr(0, eq);
      const char* old = std::getenv(name.c_str());
      saved_.emplace_back(name, old ? std::optional<std::string>(old) : std::nullopt);
      ::setenv(name.c_str(), a.substr(eq + 1).c_str(), 1);
    }
  }
  ~ScopedEnvironment() {
    for (auto it = saved_.rbegin(); it != saved_.rend(); ++it)
      it->second ? ::setenv(it->first.c_str(), it->second->c_str(), 1) : ::unsetenv(it->first.c_str());
  }
  ScopedEnvironment(const ScopedEnvironment&) = delete;
  ScopedEnvironment& operator=(const ScopedEnvironment&) = delete;

 private:
  std::vector<std::pair<std::string, std::optional<std::string>>> saved_;
};

// `shadowfilter ARGS` in this process; `env`: variable assignments for the run ("NAME=value ...").
// `dir` is unused (the process runner's scratch files go there).
inline RunResult run_cli(const std::string& args, const std::string& /*dir*/, const std::string& env = "") {
  const ScopedEnvironment scoped(env);
  std::ostringstream out, err;
  RunResult r;
  r.exit_code = cli::run(split_args(args), out, err);
  r.out = out.str();
  r.err = err.str();
  return r;
}

// `shadowfilter ARGS` as a process, its output captured through files in `dir` (removed
// afterwards); ARGS go through the shell.
inline RunResult run_cli_process(const std::string& args, const std::string& dir, const std::string& env = "") {
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
