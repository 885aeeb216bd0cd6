// `shadowfilter`: a thin command-line client of the library. The commands are sf::cli::run
// (run.hpp); what is here belongs to the process.
#include <csignal>
#include <iostream>
#include <string>
#include <vector>

#include "interrupts.hpp"
#include "run.hpp"

int main(int argc, char** argv) {
  sf::cli::watch_interrupts();
  // Past a file size limit (ulimit -f) a write fails with EFBIG and is reported like a full disk,
  // instead of the default SIGXFSZ ending the process mid-write.
  std::signal(SIGXFSZ, SIG_IGN);
  return sf::cli::run(std::vector<std::string>(argv + 1, argv + argc), std::cout, std::cerr);
}
