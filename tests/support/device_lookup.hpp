#pragma once
// Device lookups (kernels/lookup_values.cl) of a planar float32 image, for the lookup tests: the
// table the lookup reads (mip chain or summed-area table) built on the device, then the values at
// the receivers. Header-only: the test binaries that use it link the core library.
#include <algorithm>
#include <vector>

#include "reference.hpp"
#include "sf_test_env.hpp"
#include "shadowfilter/lookup.hpp"
#include "shadowfilter/mips.hpp"
#include "shadowfilter/sat.hpp"

namespace sf::test {

// out[c][i]: channel c of `img` at receiver (u[i], v[i]) through `lk` (its kind, footprint,
// Jacobian and max_anisotropy; chain and sat are built here from img).
inline std::vector<std::vector<float>> device_lookup(const ref::Planes& img, LookupBuffers lk,
                                                     const std::vector<float>& u, const std::vector<float>& v) {
  const ImageShape shape{img.width, img.height, img.channels, 4};
  cl::Buffer level0 = to_device(std::vector<float>(img.data.begin(), img.data.end()));
  if (lk.kind == Lookup::Mips) {
    const MipLayout L = mip_layout(img.width, img.height, img.channels);
    lk.chain = cl::Buffer(runtime().context(), CL_MEM_READ_WRITE, std::max<size_t>(L.chain_values, 1) * 4);
    enqueue_pyramid(runtime(), Reduce::Mean, Storage::F32, {}, shape, level0, lk.chain).wait();
  } else if (lk.kind == Lookup::Sat) {
    const SatLayout L = sat_layout(shape);
    lk.sat = cl::Buffer(runtime().context(), CL_MEM_READ_WRITE, L.table_floats * 4);
    cl::Buffer bands(runtime().context(), CL_MEM_READ_WRITE, L.band_floats * 4);
    enqueue_sat(runtime(), Storage::F32, {}, {}, shape, level0, lk.sat, bands).wait();
  }
  const size_t n = u.size();
  cl::Buffer out(runtime().context(), CL_MEM_READ_WRITE, n * img.channels * 4);
  enqueue_lookup_points(runtime(), Storage::F32, shape, n, lk, level0, to_device(u), to_device(v), out).wait();
  const auto flat = from_device(out, n * img.channels);
  std::vector<std::vector<float>> res(size_t(img.channels));
  for (int c = 0; c < img.channels; ++c) res[size_t(c)].assign(flat.begin() + c * n, flat.begin() + (c + 1) * n);
  return res;
}

}  // namespace sf::test
