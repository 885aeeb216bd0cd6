#include <gtest/gtest.h>

#include <filesystem>

#include "sf_test_env.hpp"

namespace sf::test {

std::shared_ptr<Runtime> runtime_ptr() {
  static std::shared_ptr<Runtime> rt = Runtime::create();
  return rt;
}
Runtime& runtime() { return *runtime_ptr(); }

cl::Buffer to_device(const std::vector<float>& host) {
  cl::Buffer b(runtime().context(), CL_MEM_READ_WRITE, std::max<size_t>(host.size(), 1) * sizeof(float));
  if (!host.empty()) runtime().queue().enqueueWriteBuffer(b, CL_TRUE, 0, host.size() * sizeof(float), host.data());
  return b;
}

std::vector<float> from_device(const cl::Buffer& buf, size_t count) {
  std::vector<float> out(count);
  runtime().queue().enqueueReadBuffer(buf, CL_TRUE, 0, count * sizeof(float), out.data());
  return out;
}

HostImage random_depth(int w, int h, unsigned seed, float lo, float hi) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> dist(lo, hi);
  HostImage img(w, h, 1);
  for (auto& v : img.data) v = dist(rng);
  return img;
}

std::string temp_dir(const std::string& name) {
  namespace fs = std::filesystem;
  fs::path p = fs::path(SF_TEST_TMP) / name;
  fs::remove_all(p);
  fs::create_directories(p);
  return p.string();
}

std::string data_path(const std::string& rel) { return std::string(SF_DATA_DIR) + "/" + rel; }

}  // namespace sf::test

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
