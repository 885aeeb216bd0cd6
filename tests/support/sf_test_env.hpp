#pragma once
// One OpenCL context, queue and program cache for the whole test binary: a program build costs
// about half a second on PoCL, so every test shares them.
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "shadowfilter/host_image.hpp"
#include "shadowfilter/runtime.hpp"

namespace sf::test {

Runtime& runtime();
std::shared_ptr<Runtime> runtime_ptr();

// Device buffer helpers.
cl::Buffer to_device(const std::vector<float>& host);
std::vector<float> from_device(const cl::Buffer& buf, size_t count);

// Deterministic random depth map in [lo, hi].
HostImage random_depth(int w, int h, unsigned seed, float lo = 0.0f, float hi = 1.0f);

// A fresh empty directory for one test's files (under SF_TEST_TMP).
std::string temp_dir(const std::string& name);

// Path of a bundled data file (data/...).
std::string data_path(const std::string& rel);

}  // namespace sf::test
