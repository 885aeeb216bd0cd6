// The points reconstruction at every vector width (ScheduleOptions::reconstruct_vector_width,
// kernels/reconstruct.cl): each lookup kind against the double reference for ESM (the vector
// visibility), the per-lane fallback of the other methods against width 1, receivers outside
// the frustum or in the background at every lane position, and counts that leave a partial
// vector at the end.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>

#include "reference.hpp"
#include "sf_test_env.hpp"
#include "shadowfilter/frame_filter.hpp"
#include "shadowfilter/method_kernels.hpp"
#include "shadowfilter/mips.hpp"
#include "shadowfilter/errors.hpp"
#include "shadowfilter/methods.hpp"
#include "shadowfilter/pipeline.hpp"

namespace sf::test {
namespace {

// n receivers (n % 16 != 0): random in [0,1]^2 with footprints 0.5 .. 256 texels, and every
// 13th one outside: u or v past [0,1], NaN or inf coordinates, NaN or inf depth.
Receivers make_rx(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> coord(0.0f, 1.0f), depth(0.2f, 0.9f), lf(-1.0f, 8.0f);
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  Receivers rx;
  rx.width = n;
  rx.height = 1;
  rx.has_footprint = true;
  for (int i = 0; i < n; ++i) {
    float u = coord(rng), v = coord(rng), d = depth(rng);
    if (i % 13 == 0) {
      switch ((i / 13) % 6) {
        case 0:
          u = -0.01f;
          break;
        case 1:
          v = 1.02f;
          break;
        case 2:
          u = nan;
          break;
        case 3:
          v = -inf;
          break;
        case 4:
          d = nan;
          break;
        default:
          d = inf;
          break;
      }
    }
    rx.u.push_back(u);
    rx.v.push_back(v);
    rx.d.push_back(d);
    rx.f.push_back(i % 7 == 0 ? 1.0f : std::exp2(lf(rng)));
  }
  return rx;
}

bool outside(const Receivers& rx, int i) {
  return !std::isfinite(rx.d[i]) || !(rx.u[i] >= 0.0f && rx.u[i] <= 1.0f) || !(rx.v[i] >= 0.0f && rx.v[i] <= 1.0f);
}

class EsmWidths : public ::testing::TestWithParam<std::tuple<int, Lookup>> {};

// Tolerance of test_kernels.cpp's EsmPipeline / test_lookup.cpp's EsmLookupPipeline:
// 2e-5 + 1e-7 c. Outside receivers are exactly 1.
TEST_P(EsmWidths, MatchReference) {
  const auto [width, kind] = GetParam();
  FilterOptions opt;
  opt.esm.c = 80.0f;
  opt.blur.radius = 2;
  opt.lookup.kind = kind;
  // The kernels alone: the reference has no classification stage (esm classifies by default).
  opt.esm_classify.mode = EsmClassify::None;
  opt.schedule.reconstruct_vector_width = width;
  HostImage depth = random_depth(67, 45, 5, 0.3f, 0.7f);
  for (int y = 8; y < 30; ++y)
    for (int x = 4; x < 33; ++x) depth.at(x, y) = 0.15f;
  const Receivers rx = make_rx(1003, 21);
  const auto got = filter(runtime_ptr(), opt, depth, rx);
  const auto want = ref::filter(opt, depth, rx);
  int lit = 0, dark = 0;
  for (int i = 0; i < rx.width; ++i) {
    const float g = got.visibility.data[i];
    ASSERT_TRUE(std::isfinite(g)) << "receiver " << i;
    if (outside(rx, i)) {
      ASSERT_EQ(g, 1.0f) << "outside receiver " << i;
      continue;
    }
    ASSERT_NEAR(g, want[i], 2e-5 + 1e-7 * opt.esm.c) << "receiver " << i << " f=" << rx.f[i];
    lit += want[i] > 0.99;
    dark += want[i] < 0.01;
  }
  EXPECT_GT(lit, 50);  // the comparison covers both ends of [0, 1]
  EXPECT_GT(dark, 50);
}

INSTANTIATE_TEST_SUITE_P(WidthsAndLookups, EsmWidths,
                         ::testing::Combine(::testing::Values(1, 4, 8, 16),
                                            ::testing::Values(Lookup::Bilinear, Lookup::Mips)));

// Multi-channel methods have no vector visibility: the kernel calls sf_visibility lane by lane
// after the vector lookup; the box lookup runs lane by lane for every method. Every width gives
// width 1's result to float rounding. (ESM with the box lookup runs at c = 20 here: at c = 80 the
// table cannot hold this map's exp(c (zmax - zmin)), box means of ~1e-12 under prefix sums of
// ~1e10, and the pipeline refuses it; test_lookup.cpp's EsmLookupPipeline checks the box against
// the double reference.)
class MethodWidths : public ::testing::TestWithParam<std::tuple<std::string, Lookup>> {};

TEST_P(MethodWidths, EqualWidthOne) {
  const auto [method, kind] = GetParam();
  FilterOptions opt;
  opt.method = method;
  opt.blur.radius = 1;
  opt.lookup.kind = kind;
  // The table holds esm's c (zmax - zmin) up to about 15 on this map (docs/numerics.md, "Lookup
  // limits"): c = 20 over the 0.6 of depths.
  if (kind == Lookup::Sat && method == "esm") opt.esm.c = 20.0f;
  HostImage depth = random_depth(41, 38, 8, 0.2f, 0.8f);
  const Receivers rx = make_rx(517, 3);
  opt.schedule.reconstruct_vector_width = 1;
  const auto one = filter(runtime_ptr(), opt, depth, rx);
  for (int width : {4, 8, 16}) {
    opt.schedule.reconstruct_vector_width = width;
    const auto got = filter(runtime_ptr(), opt, depth, rx);
    for (int i = 0; i < rx.width; ++i)
      ASSERT_NEAR(got.visibility.data[i], one.visibility.data[i], 2e-6)
          << method << " width " << width << " receiver " << i;
  }
}

INSTANTIATE_TEST_SUITE_P(MethodsAndLookups, MethodWidths,
                         ::testing::Combine(::testing::Values("esm", "vsm", "msm", "csm"),
                                            ::testing::Values(Lookup::Bilinear, Lookup::Mips, Lookup::Sat)));

// csm M = 16 and 32 (32 and 64 planes) with mips overflowed PoCL's work-item stack at width 16
// when the launch was large (a crash; 517 receivers did not show it): the host narrows their
// width (kernels.cpp). 200k receivers; every 997th against the double reference.
TEST(ReconstructWidth, WideMethodsRunWithMips) {
  const Receivers rx = make_rx(200003, 3);
  Receivers some;
  some.width = 0;
  some.height = 1;
  some.has_footprint = true;
  for (int i = 0; i < rx.width; i += 997) {
    some.u.push_back(rx.u[i]), some.v.push_back(rx.v[i]), some.d.push_back(rx.d[i]);
    some.f.push_back(rx.f[i]);
    ++some.width;
  }
  for (int order : {16, 32}) {
    FilterOptions opt;
    opt.method = "csm";
    opt.csm.order = order;
    opt.blur.radius = 1;
    opt.lookup.kind = Lookup::Mips;
    HostImage depth = random_depth(41, 38, 8, 0.2f, 0.8f);
    const auto got = filter(runtime_ptr(), opt, depth, rx);
    const auto want = ref::filter(opt, depth, some);
    for (int j = 0; j < some.width; ++j)
      ASSERT_NEAR(got.visibility.data[size_t(j) * 997], want[j], 1e-3) << "M " << order << " receiver " << j * 997;
  }
}

// Mips: the pipeline keeps level 0 and the chain in one buffer (kernels.cpp: SF_MIPS_JOINED;
// one base for every gather, f32 texel pairs as 8-byte loads, a table of level offsets, a
// vector log2); callers may pass them as two buffers (per-lane buffer choice, PoCL's log2).
// Both layouts give the same visibility (the two log2 differ by ulps: tolerance 2e-5 + 1e-7 c
// for ESM, 1e-5 for the moments), at every storage and for maps one texel wide or tall (the
// pair loads then read the padding value after the chain). The joined layout's level-offset
// table built per call, passed in (LookupBuffers::level_offsets) and the pipeline's own (built
// once with its chain) give bit-identical visibility.
TEST(ReconstructWidth, JoinedMipLayoutMatchesSeparate) {
  const Receivers rx = make_rx(1003, 9);
  auto u = to_device(rx.u), v = to_device(rx.v), d = to_device(rx.d), f = to_device(rx.f);
  const size_t align = std::max<size_t>(runtime().device().getInfo<CL_DEVICE_MEM_BASE_ADDR_ALIGN>() / 8, 4);
  const std::pair<const char*, Storage> cases[] = {
      {"esm", Storage::F32}, {"vsm", Storage::F32}, {"vsm", Storage::F16}, {"msm", Storage::Unorm16}};
  const std::pair<int, int> sizes[] = {{67, 45}, {1, 37}, {37, 1}, {1, 1}};
  int compared = 0;
  for (const auto& [method, storage] : cases) {
    for (const auto& [w, h] : sizes) {
      FilterOptions opt;
      opt.method = method;
      opt.storage = storage;
      opt.blur.radius = 1;
      opt.lookup.kind = Lookup::Mips;
      opt.esm_classify.mode = EsmClassify::None;  // reconstruct() against the reconstruction alone
      Pipeline pipe(runtime_ptr(), opt, w, h);
      pipe.prefilter(to_device(random_depth(w, h, 5, 0.2f, 0.8f).data)).wait();
      const ImageShape shape = pipe.basis_shape();
      const size_t vb = shape.value_bytes, chain_values = mip_layout(w, h, shape.channels).chain_values;
      auto& q = runtime().queue();
      cl::Buffer level0(runtime().context(), CL_MEM_READ_WRITE, shape.bytes());
      q.enqueueCopyBuffer(pipe.basis(), level0, 0, 0, shape.bytes());
      LookupBuffers separate;
      separate.kind = Lookup::Mips;
      separate.footprint = f;
      separate.chain = cl::Buffer(runtime().context(), CL_MEM_READ_WRITE, std::max<size_t>(chain_values, 1) * vb);
      enqueue_pyramid(runtime(), Reduce::Mean, storage, {}, shape, level0, separate.chain).wait();
      const size_t off = (shape.bytes() + align - 1) / align * align;
      cl::Buffer joined(runtime().context(), CL_MEM_READ_WRITE, off + (chain_values + 1) * vb);
      q.enqueueCopyBuffer(level0, joined, 0, 0, shape.bytes());
      if (chain_values) q.enqueueCopyBuffer(separate.chain, joined, 0, off, chain_values * vb);
      LookupBuffers one = separate;
      cl_buffer_region region{off, (chain_values + 1) * vb};
      one.chain = joined.createSubBuffer(CL_MEM_READ_WRITE, CL_BUFFER_CREATE_TYPE_REGION, &region);
      LookupBuffers prebuilt = one;
      prebuilt.level_offsets = mip_level_offsets(runtime(), storage, joined, one.chain, shape);
      ASSERT_TRUE(prebuilt.level_offsets());
      EXPECT_FALSE(mip_level_offsets(runtime(), storage, level0, separate.chain, shape)());
      if (w * h > 1) {  // a table of another chain's size is refused
        LookupBuffers wrong = one;
        wrong.level_offsets = cl::Buffer(runtime().context(), CL_MEM_READ_ONLY, sizeof(cl_int));
        EXPECT_THROW(enqueue_reconstruct_points(runtime(), *sf::method(method), opt, w, h, rx.u.size(), 0, joined,
                                                &wrong, u, v, d, u),
                     InputError);
      }
      DeviceReceivers drx;
      drx.count = rx.u.size();
      drx.u = u, drx.v = v, drx.d = d, drx.f = f;
      q.finish();
      const double tol = opt.method == "esm" ? 2e-5 + 1e-7 * opt.esm.c : 1e-5;
      for (int width : {1, 16}) {
        opt.schedule.reconstruct_vector_width = width;
        cl::Buffer a(runtime().context(), CL_MEM_READ_WRITE, rx.u.size() * 4),
            b(runtime().context(), CL_MEM_READ_WRITE, rx.u.size() * 4);
        const MethodDesc& m = *sf::method(method);
        enqueue_reconstruct_points(runtime(), m, opt, w, h, rx.u.size(), 0, level0, &separate, u, v, d, a);
        enqueue_reconstruct_points(runtime(), m, opt, w, h, rx.u.size(), 0, joined, &one, u, v, d, b);
        const auto va = from_device(a, rx.u.size()), vj = from_device(b, rx.u.size());
        auto same_bits = [&](const std::vector<float>& got, const char* path) {
          for (size_t i = 0; i < got.size(); ++i) {
            uint32_t x, y;
            std::memcpy(&x, &got[i], 4), std::memcpy(&y, &vj[i], 4);
            ASSERT_EQ(x, y) << path << " " << method << " " << storage_name(storage) << " " << w << "x" << h
                            << " width " << width << " receiver " << i << ": " << got[i] << " vs " << vj[i];
          }
        };
        enqueue_reconstruct_points(runtime(), m, opt, w, h, rx.u.size(), 0, joined, &prebuilt, u, v, d, a);
        same_bits(from_device(a, rx.u.size()), "prebuilt table");
        if (width == pipe.options().schedule.reconstruct_vector_width) {
          pipe.reconstruct(drx, a).wait();
          same_bits(from_device(a, rx.u.size()), "pipeline");
        }
        for (size_t i = 0; i < va.size(); ++i) {
          ASSERT_TRUE(std::isfinite(vj[i])) << method << " " << storage_name(storage) << " " << w << "x" << h;
          ASSERT_NEAR(vj[i], va[i], tol) << method << " " << storage_name(storage) << " " << w << "x" << h << " width "
                                         << width << " receiver " << i;
          compared += va[i] > 0.01 && va[i] < 0.99;
        }
      }
    }
  }
  EXPECT_GT(compared, 1000);  // not all lit or all dark
}

TEST(ReconstructWidth, RefusesOtherWidths) {
  FilterOptions opt;
  opt.schedule.reconstruct_vector_width = 3;
  const Receivers rx = make_rx(20, 1);
  EXPECT_THROW(filter(runtime_ptr(), opt, random_depth(8, 8, 1), rx), InputError);
}

}  // namespace
}  // namespace sf::test
