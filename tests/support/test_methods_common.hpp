#pragma once
// Helpers shared by the method tests: every basis method x storage the registry accepts, reading
// stored planes back in any storage format, and structured depth maps.
#include <cmath>
#include <cstdint>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "reference.hpp"
#include "sf_test_env.hpp"
#include "method_cases.hpp"
#include "shadowfilter/methods.hpp"
#include "shadowfilter/options.hpp"

namespace sf::test {

using ::sf::MethodCase;  // tests/support/method_cases.hpp: shared with sf_bench

// Every basis method with every storage it accepts (csm at M = 4; more orders in f32).
inline std::vector<MethodCase> basis_cases() {
  std::vector<MethodCase> out = method_storage_cases({4});
  for (int M : {1, 2, 8, 16, 32}) out.push_back({"csm", Storage::F32, M});
  return out;
}

inline float half_to_float(uint16_t h) {
  const int sign = h >> 15, exp = (h >> 10) & 31, mant = h & 1023;
  float v;
  if (exp == 0) {
    v = std::ldexp(float(mant), -24);
  } else if (exp == 31) {
    v = mant ? NAN : INFINITY;
  } else {
    v = std::ldexp(float(mant + 1024), exp - 25);
  }
  return sign ? -v : v;
}

// `count` stored values read back as the floats sf_load gives.
inline std::vector<float> read_stored(const cl::Buffer& buf, size_t count, Storage s) {
  std::vector<uint8_t> raw(count * storage_bytes(s));
  runtime().queue().enqueueReadBuffer(buf, CL_TRUE, 0, raw.size(), raw.data());
  std::vector<float> out(count);
  for (size_t i = 0; i < count; ++i) {
    switch (s) {
      case Storage::F32:
        std::memcpy(&out[i], &raw[4 * i], 4);
        break;
      case Storage::F16: {
        uint16_t h;
        std::memcpy(&h, &raw[2 * i], 2);
        out[i] = half_to_float(h);
        break;
      }
      case Storage::Unorm16: {
        uint16_t h;
        std::memcpy(&h, &raw[2 * i], 2);
        out[i] = h * (1.0f / 65535.0f);  // exactly as sf_load
        break;
      }
      case Storage::Unorm8:
        out[i] = raw[i] * (1.0f / 255.0f);
        break;
    }
  }
  return out;
}

// One step of the storage format at value v: the most a correct rounding can differ from another
// correct rounding of a value within float error of the same number.
inline double storage_step(double v, Storage s) {
  switch (s) {
    case Storage::F32:
      return 0;
    case Storage::F16:
      return std::max(std::fabs(v) * std::ldexp(1.0, -10), std::ldexp(1.0, -24));
    case Storage::Unorm16:
      return 1.0 / 65535;
    case Storage::Unorm8:
      return 1.0 / 255;
  }
  return 0;
}

// Depth maps that stress every method: exact 0 and 1, a constant (`constant`), a 0/1
// checkerboard, random.
inline std::vector<HostImage> stress_depths(float constant = 0.37f) {
  std::vector<HostImage> out;
  out.push_back(HostImage(17, 9, 1, 0.0f));
  out.push_back(HostImage(17, 9, 1, 1.0f));
  out.push_back(HostImage(17, 9, 1, constant));
  HostImage checker(33, 31, 1);
  for (int y = 0; y < checker.height; ++y)
    for (int x = 0; x < checker.width; ++x) checker.at(x, y) = float((x + y) % 2);
  out.push_back(checker);
  out.push_back(random_depth(61, 47, 7));
  return out;
}

// Random stored texels of format s (bytes as the device reads them) and their values as sf_load
// gives them (half: exponents 2^-10 .. 2^-1 with every mantissa; unorm: every code).
struct StoredImage {
  std::vector<uint8_t> bytes;
  std::vector<float> values;
};
inline StoredImage random_stored(size_t count, Storage s, unsigned seed) {
  StoredImage img;
  img.bytes.resize(count * storage_bytes(s));
  img.values.resize(count);
  std::mt19937 rng(seed);
  for (size_t i = 0; i < count; ++i) {
    const uint32_t r = rng();
    switch (s) {
      case Storage::F32: {
        const float v = float(r >> 8) * (1.0f / 16777216.0f);
        std::memcpy(&img.bytes[4 * i], &v, 4);
        img.values[i] = v;
        break;
      }
      case Storage::F16: {
        const uint16_t h = uint16_t(((5 + r % 10) << 10) | ((r >> 8) & 1023));
        std::memcpy(&img.bytes[2 * i], &h, 2);
        img.values[i] = half_to_float(h);
        break;
      }
      case Storage::Unorm16: {
        const uint16_t h = uint16_t(r >> 16);
        std::memcpy(&img.bytes[2 * i], &h, 2);
        img.values[i] = h * (1.0f / 65535.0f);
        break;
      }
      case Storage::Unorm8:
        img.bytes[i] = uint8_t(r >> 24);
        img.values[i] = img.bytes[i] * (1.0f / 255.0f);
        break;
    }
  }
  return img;
}

inline cl::Buffer stored_buffer(const StoredImage& img) {
  return cl::Buffer(runtime().context(), CL_MEM_READ_WRITE | CL_MEM_COPY_HOST_PTR, img.bytes.size(),
                    const_cast<uint8_t*>(img.bytes.data()));
}

}  // namespace sf::test
