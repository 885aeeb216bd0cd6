// Each kernel against the scalar reference (tolerances stated per test).
#include <gtest/gtest.h>

#include <array>
#include <cmath>

#include "reference.hpp"
#include "sf_test_env.hpp"
#include "test_methods_common.hpp"
#include "shadowfilter/frame_filter.hpp"
#include "shadowfilter/errors.hpp"
#include "shadowfilter/blur.hpp"
#include "shadowfilter/method_kernels.hpp"
#include "shadowfilter/methods.hpp"
#include "shadowfilter/pipeline.hpp"
#include "test_methods_common.hpp"

namespace sf::test {
namespace {

FilterOptions esm_options(float c, int radius = 0) {
  FilterOptions o;
  o.method = "esm";
  o.esm.c = c;
  o.blur.radius = radius;
  // The kernels alone: the reference has no classification stage (esm classifies by default).
  o.esm_classify.mode = EsmClassify::None;
  return o;
}

class EsmTransform : public ::testing::TestWithParam<float> {};

// float32 exp(c (z - 1/2)): the argument is rounded to half an ulp of |c/2| <= 44, so the
// relative error is about 6e-8 * c/2 plus a few ulp of exp: tolerance 1e-6 + 1e-7 c.
TEST_P(EsmTransform, MatchesReference) {
  const float c = GetParam();
  const double tol = 1e-6 + 1e-7 * c;
  for (const HostImage& depth : stress_depths(0.5f)) {  // the constant: ESM's centre, exp(0) = 1
    const auto opt = esm_options(c);
    cl::Buffer z = to_device(depth.data);
    cl::Buffer basis(runtime().context(), CL_MEM_READ_WRITE, depth.texels() * sizeof(float));
    enqueue_transform(runtime(), *sf::method("esm"), opt, depth.width, depth.height, z, basis).wait();
    const auto got = from_device(basis, depth.texels());
    const auto want = ref::transform(opt, depth);
    for (size_t i = 0; i < got.size(); ++i) {
      ASSERT_TRUE(std::isfinite(got[i])) << "texel " << i;
      ASSERT_NEAR(got[i], want.data[i], tol * want.data[i]) << "texel " << i << " z=" << depth.data[i];
    }
  }
}
INSTANTIATE_TEST_SUITE_P(Exponents, EsmTransform, ::testing::Values(1.0f, 40.0f, 80.0f, 88.0f, 174.0f));

TEST(EsmTransform, RefusesExponentsBeyondTheFloat32Limit) {
  auto opt = esm_options(200.0f);
  try {
    sf::method("esm")->validate(opt);
    FAIL() << "c = 200 accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("174"), std::string::npos) << e.what();
  }
}

struct BlurCase {
  int width, height, channels, radius, vec;
};

class Blur : public ::testing::TestWithParam<BlurCase> {};

// Float32 separable sums of at most 2R+1 positive terms per pass against double: relative 1e-5.
TEST_P(Blur, MatchesReference) {
  const BlurCase bc = GetParam();
  ref::Planes in(bc.width, bc.height, bc.channels);
  std::vector<float> host(in.data.size());
  std::mt19937 rng(bc.width * 131 + bc.radius);
  std::uniform_real_distribution<float> dist(0.05f, 1.0f);
  for (size_t i = 0; i < host.size(); ++i) in.data[i] = host[i] = dist(rng);

  ImageShape shape{bc.width, bc.height, bc.channels};
  cl::Buffer src = to_device(host);
  cl::Buffer tmp(runtime().context(), CL_MEM_READ_WRITE, shape.bytes());
  cl::Buffer dst(runtime().context(), CL_MEM_READ_WRITE, shape.bytes());
  BlurOptions blur{bc.radius, 0.0f};
  ScheduleOptions sched;
  sched.blur_vector_width = bc.vec;
  enqueue_blur(runtime(), blur, sched, Storage::F32, shape, src, tmp, dst).wait();
  const auto got = from_device(dst, host.size());
  const auto want = ref::blur(in, bc.radius, 0.0);
  for (size_t i = 0; i < got.size(); ++i) ASSERT_NEAR(got[i], want.data[i], 1e-5 * want.data[i]) << "index " << i;
}

INSTANTIATE_TEST_SUITE_P(Shapes, Blur,
                         ::testing::Values(BlurCase{1, 1, 1, 3, 16}, BlurCase{1, 9, 1, 2, 16}, BlurCase{9, 1, 1, 2, 16},
                                           BlurCase{7, 5, 1, 32, 16}, BlurCase{37, 29, 3, 1, 16},
                                           BlurCase{37, 29, 1, 0, 16}, BlurCase{64, 64, 1, 3, 16},
                                           BlurCase{130, 70, 2, 7, 16}, BlurCase{130, 70, 1, 15, 8},
                                           BlurCase{101, 67, 1, 7, 4}, BlurCase{257, 33, 1, 32, 16},
                                           BlurCase{40, 300, 1, 64, 16}));

// The max filter (blur.cl with SF_BLUR_MAX) in both launch families: exactly the max over the
// clamped (2R+1)^2 window, brute force (a max rounds nothing).
class MaxFilter : public ::testing::TestWithParam<std::tuple<BlurCase, ScheduleFamily>> {};

TEST_P(MaxFilter, EqualsTheWindowMax) {
  const auto [bc, fam] = GetParam();
  const HostImage img = random_depth(bc.width, bc.height, bc.width * 7 + bc.radius);
  ImageShape shape{bc.width, bc.height, 1};
  cl::Buffer src = to_device(img.data), dst(runtime().context(), CL_MEM_READ_WRITE, shape.bytes());
  ScheduleOptions sched;
  sched.family = fam;
  sched.blur_vector_width = bc.vec;
  enqueue_max_filter(runtime(), bc.radius, sched, shape, src, dst).wait();
  const auto got = from_device(dst, img.texels());
  const int R = bc.radius;
  for (int y = 0; y < bc.height; ++y)
    for (int x = 0; x < bc.width; ++x) {
      float m = 0.0f;
      for (int b = std::max(y - R, 0); b <= std::min(y + R, bc.height - 1); ++b)
        for (int a = std::max(x - R, 0); a <= std::min(x + R, bc.width - 1); ++a) m = std::max(m, img.at(a, b));
      ASSERT_EQ(got[size_t(y) * bc.width + x], m) << x << "," << y << " R=" << R;
    }
}

INSTANTIATE_TEST_SUITE_P(ShapesAndFamilies, MaxFilter,
                         ::testing::Combine(::testing::Values(BlurCase{1, 1, 1, 3, 16}, BlurCase{9, 1, 1, 2, 16},
                                                              BlurCase{37, 29, 1, 0, 16}, BlurCase{130, 70, 1, 7, 16},
                                                              BlurCase{101, 67, 1, 3, 4}, BlurCase{40, 300, 1, 64, 8}),
                                            ::testing::Values(ScheduleFamily::Cpu, ScheduleFamily::Gpu)));

TEST(MaxFilter, RefusesInPlaceAndRadiiPastTheBlurs) {
  ImageShape shape{8, 8, 1};
  cl::Buffer a(runtime().context(), CL_MEM_READ_WRITE, shape.bytes()),
      b(runtime().context(), CL_MEM_READ_WRITE, shape.bytes());
  EXPECT_THROW(enqueue_max_filter(runtime(), 2, {}, shape, a, a), InputError);
  EXPECT_THROW(enqueue_max_filter(runtime(), kMaxBlurRadius + 1, {}, shape, a, b), InputError);
  EXPECT_THROW(enqueue_max_filter(runtime(), -1, {}, shape, a, b), InputError);
}

TEST(Blur, InPlaceEqualsOutOfPlace) {
  const HostImage img = random_depth(53, 41, 3);
  ImageShape shape{53, 41, 1};
  cl::Buffer a = to_device(img.data), b = to_device(img.data), out = to_device(img.data);
  cl::Buffer tmp(runtime().context(), CL_MEM_READ_WRITE, shape.bytes());
  enqueue_blur(runtime(), {5, 2.0f}, {}, Storage::F32, shape, a, tmp, a).wait();
  enqueue_blur(runtime(), {5, 2.0f}, {}, Storage::F32, shape, b, tmp, out).wait();
  EXPECT_EQ(from_device(a, img.texels()), from_device(out, img.texels()));
}

// The blur in every storage format: random codes (f16: both signs, exponents 2^-24 .. 2^1
// including subnormals; unorm: every code) decoded as sf_load does, blurred by the scalar
// reference in double, against the kernel's stored result decoded the same way. The kernel
// decodes once, sums in float and rounds once on store, so
//   |got - want| <= step(want) / 2 + e,  e = 1.2e-7 (R + 2) max|input|
// (half a step of the storage format at the value, storage_step in test_methods_common.hpp, plus
// the float error of two passes of R + 1 fma each, which may also tip a value near a rounding
// boundary to the other neighbour).
struct BlurStorageCase {
  Storage storage;
  int width, height, channels, radius, vec;
};

std::vector<uint8_t> random_codes(Storage st, size_t count, unsigned seed) {
  std::mt19937 rng(seed);
  std::vector<uint8_t> raw(count * storage_bytes(st));
  for (size_t i = 0; i < count; ++i) {
    uint32_t code = rng();
    if (st == Storage::F16) {  // sign, exponent 0 .. 16 (values below 4), mantissa
      code = (code & 0x8000u) | ((code >> 16) % 17u) << 10 | (code & 0x3ffu);
    } else if (st == Storage::F32) {
      const float v = std::uniform_real_distribution<float>(-1.0f, 1.0f)(rng);
      std::memcpy(&code, &v, 4);
    }
    std::memcpy(&raw[i * storage_bytes(st)], &code, storage_bytes(st));  // little endian
  }
  return raw;
}

cl::Buffer raw_to_device(const std::vector<uint8_t>& raw) {
  return cl::Buffer(runtime().context(), CL_MEM_READ_WRITE | CL_MEM_COPY_HOST_PTR, raw.size(),
                    const_cast<uint8_t*>(raw.data()));
}

std::vector<uint8_t> raw_from_device(const cl::Buffer& buf, size_t bytes) {
  std::vector<uint8_t> raw(bytes);
  runtime().queue().enqueueReadBuffer(buf, CL_TRUE, 0, bytes, raw.data());
  return raw;
}

class BlurStorage : public ::testing::TestWithParam<BlurStorageCase> {};

TEST_P(BlurStorage, MatchesReferenceWithinHalfAStep) {
  const BlurStorageCase bc = GetParam();
  const ImageShape shape{bc.width, bc.height, bc.channels, storage_bytes(bc.storage)};
  const size_t n = shape.plane_texels() * shape.channels;
  const auto codes = random_codes(bc.storage, n, bc.width * 31 + bc.radius);
  cl::Buffer src = raw_to_device(codes);
  const auto decoded = read_stored(src, n, bc.storage);
  ref::Planes in(bc.width, bc.height, bc.channels);
  double maxabs = 0;
  for (size_t i = 0; i < n; ++i) {
    in.data[i] = decoded[i];
    maxabs = std::max(maxabs, std::fabs(double(decoded[i])));
  }
  cl::Buffer tmp(runtime().context(), CL_MEM_READ_WRITE, shape.bytes());
  cl::Buffer dst(runtime().context(), CL_MEM_READ_WRITE, shape.bytes());
  ScheduleOptions sched;
  sched.blur_vector_width = bc.vec;
  enqueue_blur(runtime(), {bc.radius, 0.0f}, sched, bc.storage, shape, src, tmp, dst).wait();
  const auto got = read_stored(dst, n, bc.storage);
  const auto want = ref::blur(in, bc.radius, 0.0);
  const double e = 1.2e-7 * (bc.radius + 2) * maxabs;
  double worst = 0;  // in steps
  for (size_t i = 0; i < n; ++i) {
    const double w = want.data[i], step = storage_step(std::fabs(w) + e, bc.storage);
    ASSERT_TRUE(std::isfinite(got[i])) << "index " << i;
    ASSERT_LE(std::fabs(got[i] - w), 0.5 * step + e) << "index " << i << " want " << w;
    if (step > 0) worst = std::max(worst, std::fabs(got[i] - w) / step);
  }
  if (n > size_t(bc.channels)) {  // the storage rounding is there (a 1x1 blur is exact)
    EXPECT_GT(worst, 0.0);
  }
  // In place (through tmp and the copy back) gives the same codes.
  cl::Buffer a = raw_to_device(codes);
  enqueue_blur(runtime(), {bc.radius, 0.0f}, sched, bc.storage, shape, a, tmp, a).wait();
  EXPECT_EQ(raw_from_device(a, shape.bytes()), raw_from_device(dst, shape.bytes()));
}

// Partial strips and vectors (odd sizes, widths below one vector), several planes, radii larger
// than the image, every vector width.
std::vector<BlurStorageCase> blur_storage_cases() {
  std::vector<BlurStorageCase> out;
  for (Storage st : {Storage::F16, Storage::Unorm16, Storage::Unorm8}) {
    for (BlurStorageCase c : {BlurStorageCase{st, 1, 1, 1, 3, 16}, BlurStorageCase{st, 9, 1, 2, 2, 16},
                              BlurStorageCase{st, 7, 5, 1, 32, 16}, BlurStorageCase{st, 37, 29, 3, 1, 16},
                              BlurStorageCase{st, 64, 64, 1, 3, 16}, BlurStorageCase{st, 130, 70, 2, 7, 8},
                              BlurStorageCase{st, 101, 67, 1, 7, 4}, BlurStorageCase{st, 257, 33, 1, 3, 16},
                              BlurStorageCase{st, 40, 300, 1, 64, 16}})
      out.push_back(c);
  }
  return out;
}

INSTANTIATE_TEST_SUITE_P(Formats, BlurStorage, ::testing::ValuesIn(blur_storage_cases()),
                         [](const ::testing::TestParamInfo<BlurStorageCase>& i) {
                           const BlurStorageCase& c = i.param;
                           return std::string(storage_name(c.storage)) + "_" + std::to_string(c.width) + "x" +
                                  std::to_string(c.height) + "x" + std::to_string(c.channels) + "_R" +
                                  std::to_string(c.radius) + "_v" + std::to_string(c.vec);
                         });

// Every schedule (vector width, strip, rows) computes every texel by the same float sequence:
// the stored codes are bit-identical in every format.
TEST(BlurStorage, SchedulesAreBitIdentical) {
  const ImageShape base{203, 141, 2};
  for (Storage st : {Storage::F32, Storage::F16, Storage::Unorm16, Storage::Unorm8}) {
    ImageShape shape = base;
    shape.value_bytes = storage_bytes(st);
    const auto codes = random_codes(st, shape.plane_texels() * shape.channels, 5);
    cl::Buffer src = raw_to_device(codes);
    cl::Buffer tmp(runtime().context(), CL_MEM_READ_WRITE, shape.bytes());
    std::vector<uint8_t> first;
    for (auto [vec, strip, rows] : {std::array<int, 3>{16, 0, 0}, {4, 4, 3}, {8, 256, 64}, {16, 32, 7}}) {
      ScheduleOptions sched;
      sched.blur_vector_width = vec;
      sched.blur_strip_texels = strip;
      sched.blur_rows = rows;
      cl::Buffer dst(runtime().context(), CL_MEM_READ_WRITE, shape.bytes());
      enqueue_blur(runtime(), {4, 0.0f}, sched, st, shape, src, tmp, dst).wait();
      const auto got = raw_from_device(dst, shape.bytes());
      if (first.empty()) first = got;
      EXPECT_EQ(got, first) << storage_name(st) << " vec " << vec << " strip " << strip << " rows " << rows;
    }
  }
}

// A constant unorm image stays the same constant (the weights sum to 1 within float error, far
// below half a step), and the all-ones image stays at the top code: no overflow past 1.
TEST(BlurStorage, ConstantsStayConstant) {
  for (Storage st : {Storage::F16, Storage::Unorm16, Storage::Unorm8}) {
    const ImageShape shape{45, 23, 1, storage_bytes(st)};
    for (uint32_t code : {0u, 1u, 77u, st == Storage::Unorm8 ? 255u : st == Storage::F16 ? 0x3c00u : 65535u}) {
      std::vector<uint8_t> raw(shape.bytes());
      for (size_t i = 0; i < shape.plane_texels(); ++i)
        std::memcpy(&raw[i * shape.value_bytes], &code, shape.value_bytes);
      cl::Buffer a = raw_to_device(raw);
      cl::Buffer tmp(runtime().context(), CL_MEM_READ_WRITE, shape.bytes());
      enqueue_blur(runtime(), {7, 0.0f}, {}, st, shape, a, tmp, a).wait();
      EXPECT_EQ(raw_from_device(a, shape.bytes()), raw) << storage_name(st) << " code " << code;
    }
  }
}

TEST(BlurStorage, RefusesAShapeOfAnotherFormat) {
  const ImageShape shape{8, 8, 1, 4};
  cl::Buffer a(runtime().context(), CL_MEM_READ_WRITE, shape.bytes());
  EXPECT_THROW(enqueue_blur(runtime(), {2, 0.0f}, {}, Storage::F16, shape, a, a, a), InputError);
}

TEST(Blur, WeightsAreNormalisedAndDefaultSigmaSpansThreeSigma) {
  for (int r : {1, 3, 7, 32}) {
    auto w = gaussian_weights(r, 0.0f);
    double sum = w[0];
    for (int k = 1; k <= r; ++k) sum += 2 * w[k];
    EXPECT_NEAR(sum, 1.0, 1e-6);
    EXPECT_FLOAT_EQ(default_blur_sigma(r), (2 * r + 1) / 6.0f);
    // At the last tap (R ~ 3 sigma) the weight is about exp(-4.5) of the centre's.
    EXPECT_NEAR(w[r] / w[0], std::exp(-double(r) * r / (2 * std::pow((2 * r + 1) / 6.0, 2))), 1e-5);
  }
  EXPECT_THROW(gaussian_weights(-1, 0.0f), InputError);
  EXPECT_THROW(gaussian_weights(kMaxBlurRadius + 1, 0.0f), InputError);
}

// Receivers covering the odd cases of methods.md sec. 1 plus random interior points.
Receivers odd_and_random_receivers(unsigned seed) {
  Receivers rx;
  const float nan = std::nanf("");
  std::vector<std::array<float, 3>> pts = {{0.5f, 0.5f, nan},      {0.5f, 0.5f, INFINITY}, {-0.1f, 0.5f, 0.5f},
                                           {0.5f, 1.2f, 0.5f},     {0.0f, 0.0f, 0.3f},     {1.0f, 1.0f, 0.3f},
                                           {0.5f, 0.5f, -0.5f},    {0.5f, 0.5f, 1.5f},     {nan, 0.5f, 0.5f},
                                           {0.999f, 0.001f, 1.0f}, {0.25f, 0.75f, 0.0f}};
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  for (int i = 0; i < 500; ++i) pts.push_back({unit(rng), unit(rng), unit(rng)});
  rx.width = int(pts.size());
  rx.height = 1;
  for (auto& p : pts) {
    rx.u.push_back(p[0]);
    rx.v.push_back(p[1]);
    rx.d.push_back(p[2]);
  }
  rx.f.assign(pts.size(), 1.0f);
  return rx;
}

class EsmPipeline : public ::testing::TestWithParam<std::tuple<float, int>> {};

// Transform + blur + bilinear reconstruction against the double reference. The blurred basis
// has relative error ~1e-5 and the reconstruction's exp(c (1/2 - d)) adds ~1e-7 c: visibility in [0,1]
// is compared with an absolute tolerance 2e-5 + 1e-7 c.
TEST_P(EsmPipeline, PointsAndGridMatchReference) {
  const auto [c, radius] = GetParam();
  const auto opt = esm_options(c, radius);
  const double tol = 2e-5 + 1e-7 * c;
  HostImage depth = random_depth(45, 38, 11, 0.2f, 0.8f);
  for (int y = 10; y < 25; ++y)  // an occluder block well in front
    for (int x = 5; x < 20; ++x) depth.at(x, y) = 0.1f;

  const Receivers rx = odd_and_random_receivers(5);
  const auto got = filter(runtime_ptr(), opt, depth, rx);
  const auto want = ref::filter(opt, depth, rx);
  for (size_t i = 0; i < want.size(); ++i) {
    ASSERT_TRUE(std::isfinite(got.visibility.data[i]));
    ASSERT_NEAR(got.visibility.data[i], want[i], tol) << "receiver " << i;
  }
  EXPECT_EQ(got.background, 2u);
  EXPECT_EQ(got.outside, 3u);

  Receivers grid;
  grid.grid = true;
  grid.width = depth.width;
  grid.height = depth.height;
  grid.d = random_depth(depth.width, depth.height, 9).data;
  grid.d[7] = std::nanf("");
  const auto got_grid = filter(runtime_ptr(), opt, depth, grid);
  const auto want_grid = ref::filter(opt, depth, grid);
  for (size_t i = 0; i < want_grid.size(); ++i)
    ASSERT_NEAR(got_grid.visibility.data[i], want_grid[i], tol) << "texel " << i;
  EXPECT_EQ(got_grid.visibility.data[7], 1.0f);
}

INSTANTIATE_TEST_SUITE_P(ExponentsAndRadii, EsmPipeline,
                         ::testing::Combine(::testing::Values(1.0f, 40.0f, 80.0f, 88.0f), ::testing::Values(0, 1, 4)));

TEST(Pipeline, RefusesMapsThatDoNotFitTheDevice) {
  const auto& info = runtime().info();
  const size_t texels = info.max_alloc_bytes / sizeof(float) + 1;
  const int side = int(std::ceil(std::sqrt(double(texels))));
  try {
    Pipeline p(runtime_ptr(), esm_options(80), side, side);
    FAIL() << "a " << side << "x" << side << " map was accepted";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_TRUE(msg.find("MiB") != std::string::npos || msg.find("too large") != std::string::npos) << msg;
  }
}

}  // namespace
}  // namespace sf::test
