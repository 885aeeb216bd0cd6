// The harnesses without libFuzzer (any compiler): `sf_fuzz_replay HARNESS DIR...` runs every file
// of the directories once through HARNESS, so the committed corpus and the regressions are checked
// by the ordinary suite. A refusal is fine; a crash, a sanitizer report or any exception other
// than sf::InputError ends the process abnormally, which fails the test.
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

// Each harness is compiled with its entry point renamed to sf_fuzz_<name> (tests/CMakeLists.txt).
extern "C" int sf_fuzz_image(const uint8_t*, size_t);
extern "C" int sf_fuzz_cascade(const uint8_t*, size_t);
extern "C" int sf_fuzz_csm(const uint8_t*, size_t);
extern "C" int sf_fuzz_frame_list(const uint8_t*, size_t);
extern "C" int sf_fuzz_light_list(const uint8_t*, size_t);
extern "C" int sf_fuzz_mesh(const uint8_t*, size_t);
extern "C" int sf_fuzz_view_file(const uint8_t*, size_t);

namespace {

struct Harness {
  const char* name;
  int (*run)(const uint8_t*, size_t);
};

const Harness kHarnesses[] = {
    {"image", sf_fuzz_image},           {"cascade", sf_fuzz_cascade},       {"csm", sf_fuzz_csm},
    {"frame_list", sf_fuzz_frame_list}, {"light_list", sf_fuzz_light_list}, {"mesh", sf_fuzz_mesh},
    {"view_file", sf_fuzz_view_file}};

}  // namespace

int main(int argc, char** argv) {
  const Harness* harness = nullptr;
  for (const Harness& h : kHarnesses)
    if (argc > 1 && std::strcmp(argv[1], h.name) == 0) harness = &h;
  if (!harness) {
    std::fprintf(stderr, "usage: sf_fuzz_replay image|cascade|csm|frame_list|light_list|mesh|view_file DIR...\n");
    return 2;
  }
  std::vector<std::filesystem::path> files;
  for (int a = 2; a < argc; ++a) {
    std::error_code ec;
    for (const auto& entry : std::filesystem::directory_iterator(argv[a], ec))
      if (entry.is_regular_file()) files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  if (files.empty()) {
    std::fprintf(stderr, "sf_fuzz_replay %s: no inputs in the directories given\n", harness->name);
    return 1;
  }
  for (const auto& file : files) {
    std::ifstream in(file, std::ios::binary);
    const std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::fprintf(stderr, "%s\n", file.c_str());
    harness->run(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size());
  }
  std::printf("sf_fuzz_replay %s: %zu inputs, none crashed\n", harness->name, files.size());
  return 0;
}
