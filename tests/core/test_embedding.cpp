// The library as another pipeline embeds it (embed.hpp, pipeline.hpp): no cl::Error escapes,
// messages name option fields, buffer plans before allocation, sub-buffers, out-of-order queues,
// and a caller's own kernel built from kernel_prelude() agreeing with the library's reconstruct.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <random>

#include "sf_test_env.hpp"
#include "shadowfilter/frame_filter.hpp"
#include "shadowfilter/blur.hpp"
#include "shadowfilter/mips.hpp"
#include "shadowfilter/sat.hpp"
#include "shadowfilter/embed.hpp"
#include "shadowfilter/errors.hpp"
#include "shadowfilter/pipeline.hpp"

namespace sf::test {
namespace {

struct Points {
  std::vector<float> u, v, d, f;
  size_t count() const { return u.size(); }
};

// Receivers spread over the map (a few outside it) with depths around the map's and footprints
// of 1..16 texels.
Points random_points(size_t n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> uv(-0.05f, 1.05f), depth(0.0f, 1.0f), fp(1.0f, 16.0f);
  Points p;
  for (size_t i = 0; i < n; ++i) {
    p.u.push_back(uv(rng));
    p.v.push_back(uv(rng));
    p.d.push_back(depth(rng));
    p.f.push_back(fp(rng));
  }
  return p;
}

// c = 40, or 15 with sat: on these maps (depths 0.2 .. 0.9) the table holds c (zmax - zmin) up
// to about 13.5 (docs/numerics.md, "Lookup limits"), and sf::filter and the Pipeline refuse more.
FilterOptions esm_options(Lookup lookup, int radius) {
  FilterOptions o;
  o.method = "esm";
  o.esm.c = lookup == Lookup::Sat ? 15.0f : 40.0f;
  o.blur.radius = radius;
  o.lookup.kind = lookup;
  // The reconstruction alone, as a caller's own kernel computes it (esm classifies by default).
  o.esm_classify.mode = EsmClassify::None;
  return o;
}

// Visibility of the points through a Pipeline on `rt`: bit-exact reference for the tests below.
std::vector<float> pipeline_visibility(const std::shared_ptr<Runtime>& rt, const FilterOptions& o,
                                       const HostImage& depth, const Points& p) {
  auto up = [&rt](const std::vector<float>& h) {
    cl::Buffer b(rt->context(), CL_MEM_READ_WRITE, h.size() * sizeof(float));
    rt->queue().enqueueWriteBuffer(b, CL_TRUE, 0, h.size() * sizeof(float), h.data());
    return b;
  };
  Pipeline pipe(rt, o, depth.width, depth.height);
  DeviceReceivers rx{false, p.count(), up(p.u), up(p.v), up(p.d), up(p.f)};
  cl::Buffer vis(rt->context(), CL_MEM_READ_WRITE, p.count() * sizeof(float));
  const EventList after{pipe.prefilter(up(depth.data))};
  const EventList done{pipe.reconstruct(rx, vis, &after)};
  std::vector<float> out(p.count());
  rt->queue().enqueueReadBuffer(vis, CL_TRUE, 0, out.size() * sizeof(float), out.data(), &done);
  return out;
}

TEST(Embedding, OpenClErrorsLeaveAsDeviceErrors) {
  // sm copies the depth map as its "basis": a depth buffer smaller than the map makes
  // clEnqueueCopyBuffer fail with CL_INVALID_VALUE inside enqueue_transform.
  FilterOptions o;
  o.method = "sm";
  Pipeline pipe(runtime_ptr(), o, 64, 64);
  const cl::Buffer small = to_device(std::vector<float>(16, 0.5f));
  try {
    pipe.prefilter(small);
    FAIL() << "a depth buffer smaller than the map was accepted";
  } catch (const DeviceError& e) {
    EXPECT_NE(std::string(e.what()).find("CL_INVALID_VALUE"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("enqueue_transform"), std::string::npos) << e.what();
  } catch (const cl::Error& e) {
    FAIL() << "cl::Error escaped the library: " << e.what() << " " << e.err();
  }
}

TEST(Embedding, MessagesNameOptionFields) {
  FilterOptions o = esm_options(Lookup::Bilinear, 0);
  o.esm.c = -1;
  try {
    Pipeline::plan(runtime(), o, 16, 16);
    FAIL() << "esm.c = -1 was accepted";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("FilterOptions::esm.c"), std::string::npos) << m;
    EXPECT_EQ(m.find("--"), std::string::npos) << m;
  }
  o = esm_options(Lookup::Bilinear, 2);
  o.blur.sigma = std::nanf("");
  try {
    Pipeline::plan(runtime(), o, 16, 16);
    FAIL() << "a NaN sigma was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("FilterOptions::blur.sigma"), std::string::npos) << e.what();
  }
  o = esm_options(Lookup::Bilinear, kMaxBlurRadius + 1);
  try {
    Pipeline pipe(runtime_ptr(), o, 16, 16);
    FAIL() << "a blur radius over the limit was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("FilterOptions::blur.radius"), std::string::npos) << e.what();
  }
}

TEST(Embedding, PlanListsWhatThePipelineAllocates) {
  const int W = 200, H = 120;
  {
    const BufferPlan p = Pipeline::plan(runtime(), esm_options(Lookup::Bilinear, 0), W, H);
    ASSERT_EQ(p.buffers.size(), 1u);  // no blur scratch at R = 0
    EXPECT_EQ(p.bytes("basis"), size_t(W) * H * 4);
    Pipeline pipe(runtime_ptr(), esm_options(Lookup::Bilinear, 0), W, H);
    EXPECT_EQ(pipe.device_bytes(), p.total());
  }
  {
    FilterOptions o = esm_options(Lookup::Bilinear, 3);
    o.method = "pcf";  // raw depth: never blurred, so no scratch whatever the radius
    const BufferPlan p = Pipeline::plan(runtime(), o, W, H);
    EXPECT_EQ(p.bytes("blur scratch"), 0u);
    EXPECT_EQ(p.total(), size_t(W) * H * 4);
  }
  {
    FilterOptions o = esm_options(Lookup::Mips, 3);
    o.esm_classify.mode = EsmClassify::ZMax;
    const BufferPlan p = Pipeline::plan(runtime(), o, W, H);
    const MipLayout mips = mip_layout(W, H, 1);
    EXPECT_GE(p.bytes("basis+mips"), (size_t(W) * H + mips.chain_values) * 4);
    EXPECT_EQ(p.bytes("mip level offsets"), mips.levels.size() * 4);
    EXPECT_EQ(p.bytes("blur scratch"), size_t(W) * H * 4);
    EXPECT_EQ(p.bytes("zmax chain"), mips.chain_values * 4);
    EXPECT_EQ(p.bytes_per_receiver, 1u);
    Pipeline pipe(runtime_ptr(), o, W, H);
    EXPECT_EQ(pipe.device_bytes(), p.total());
    EXPECT_EQ(pipe.buffer_plan().buffers.size(), p.buffers.size());
  }
  {
    FilterOptions o = esm_options(Lookup::Sat, 0);
    o.method = "msm";
    const BufferPlan p = Pipeline::plan(runtime(), o, W, H);
    EXPECT_EQ(p.shape.channels, 4);
    EXPECT_EQ(p.bytes("sat"), sat_layout(p.shape).table_floats * 4);
    EXPECT_GT(p.bytes("sat bands"), 0u);
  }
}

// Depth, receivers and visibility inside larger buffers of the caller, at aligned offsets.
TEST(Embedding, SubBuffersGiveTheSameVisibility) {
  auto rt = runtime_ptr();
  const HostImage depth = random_depth(96, 80, 2, 0.2f, 0.9f);
  const Points p = random_points(1000, 3);
  for (Lookup lookup : {Lookup::Bilinear, Lookup::Mips, Lookup::Sat}) {
    const FilterOptions o = esm_options(lookup, 2);
    const std::vector<float> want = pipeline_visibility(rt, o, depth, p);

    const size_t align = rt->device().getInfo<CL_DEVICE_MEM_BASE_ADDR_ALIGN>() / 8;
    const size_t origin = 3 * align;
    auto inside = [&](const std::vector<float>& h, cl::Buffer& parent) {
      const size_t bytes = h.size() * sizeof(float);
      parent = cl::Buffer(rt->context(), CL_MEM_READ_WRITE, origin + bytes + align);
      std::vector<float> poison((origin + bytes + align) / sizeof(float), std::nanf(""));
      rt->queue().enqueueWriteBuffer(parent, CL_TRUE, 0, poison.size() * sizeof(float), poison.data());
      rt->queue().enqueueWriteBuffer(parent, CL_TRUE, origin, bytes, h.data());
      return sub_buffer(*rt, parent, origin, bytes);
    };
    cl::Buffer pd, pu, pv, pdd, pf, pvis;
    Pipeline pipe(rt, o, depth.width, depth.height);
    DeviceReceivers rx{false, p.count(), inside(p.u, pu), inside(p.v, pv), inside(p.d, pdd), inside(p.f, pf)};
    const cl::Buffer vis = inside(std::vector<float>(p.count(), -1.0f), pvis);
    const EventList after{pipe.prefilter(inside(depth.data, pd))};
    const EventList done{pipe.reconstruct(rx, vis, &after)};
    std::vector<float> whole((origin + p.count() * sizeof(float) + align) / sizeof(float));
    rt->queue().enqueueReadBuffer(pvis, CL_TRUE, 0, whole.size() * sizeof(float), whole.data(), &done);
    const size_t first = origin / sizeof(float);
    for (size_t i = 0; i < p.count(); ++i)
      ASSERT_EQ(whole[first + i], want[i]) << "lookup " << int(lookup) << " receiver " << i;
    EXPECT_TRUE(std::isnan(whole[first - 1]) && std::isnan(whole[first + p.count()])) << "wrote outside the sub-buffer";
  }
}

TEST(Embedding, SubBufferRulesAreChecked) {
  auto& rt = runtime();
  cl::Buffer parent(rt.context(), CL_MEM_READ_WRITE, 4096);
  const size_t align = rt.device().getInfo<CL_DEVICE_MEM_BASE_ADDR_ALIGN>() / 8;
  ASSERT_GT(align, 4u);
  try {
    sub_buffer(rt, parent, 4, 64);
    FAIL() << "a misaligned origin was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("CL_DEVICE_MEM_BASE_ADDR_ALIGN"), std::string::npos) << e.what();
  }
  EXPECT_THROW(sub_buffer(rt, parent, align, 4096), InputError);  // past the end
  EXPECT_EQ(sub_buffer(rt, parent, align, 64).getInfo<CL_MEM_SIZE>(), 64u);
}

// Every dependency inside a call is an event: an out-of-order queue gives the same bits.
TEST(Embedding, OutOfOrderQueueGivesTheSameVisibility) {
  auto& rt = runtime();
  const auto props = rt.device().getInfo<CL_DEVICE_QUEUE_PROPERTIES>();
  if (!(props & CL_QUEUE_OUT_OF_ORDER_EXEC_MODE_ENABLE)) GTEST_SKIP() << "no out-of-order queues";
  cl::CommandQueue ooo(rt.context(), rt.device(), CL_QUEUE_OUT_OF_ORDER_EXEC_MODE_ENABLE | CL_QUEUE_PROFILING_ENABLE);
  auto rt_ooo = std::make_shared<Runtime>(rt.context(), ooo);
  const HostImage depth = random_depth(128, 96, 4, 0.2f, 0.9f);
  const Points p = random_points(2000, 5);
  for (Lookup lookup : {Lookup::Mips, Lookup::Sat}) {
    FilterOptions o = esm_options(lookup, 3);
    const std::vector<float> want = pipeline_visibility(runtime_ptr(), o, depth, p);
    for (int run = 0; run < 3; ++run)
      ASSERT_EQ(pipeline_visibility(rt_ooo, o, depth, p), want) << "lookup " << int(lookup) << " run " << run;
  }
  // The host convenience, with the classification's flags read after their kernel.
  FilterOptions o = esm_options(Lookup::Mips, 2);
  o.esm_classify.mode = EsmClassify::ZMax;
  Receivers rx;
  rx.width = int(p.count());
  rx.height = 1;
  rx.u = p.u, rx.v = p.v, rx.d = p.d, rx.f = p.f;
  rx.has_footprint = true;
  const FilterResult a = filter(runtime_ptr(), o, depth, rx), b = filter(rt_ooo, o, depth, rx);
  EXPECT_EQ(a.visibility.data, b.visibility.data);
  EXPECT_EQ(a.flags.data, b.flags.data);
  EXPECT_GT(a.flagged, 0u);
}

// A caller's kernel from kernel_prelude(): sf_lookup + sf_visibility per receiver, as
// embed.hpp describes, against the library's vectorised reconstruction of the same receivers.
const char* kCallerKernel = R"CLC(
__kernel void caller_shade(__global const sf_stored* basis, __global const sf_stored* chain,
                           __global const float* sat, int width, int height,
                           __global const float* u, __global const float* v,
                           __global const float* d, __global const float* f,
                           __global float* out, int count, const sf_method_params P) {
  const int i = get_global_id(0);
  if (i >= count) return;
  if (sf_receiver_outside(u[i], v[i], d[i])) { out[i] = 1.0f; return; }
  float b[SF_CHANNELS];
  sf_lookup(basis, chain, sat, width, height, u[i], v[i], f[i], b);
  out[i] = clamp(sf_visibility(b, clamp(d[i], 0.0f, 1.0f), P), 0.0f, 1.0f);
}
)CLC";

struct PreludeCase {
  const char* method;
  Lookup lookup;
  float tolerance;  // |caller - library|: the same math, scalar against vector code
};

class KernelPreludeCases : public ::testing::TestWithParam<PreludeCase> {};

TEST_P(KernelPreludeCases, CallerKernelMatchesReconstruct) {
  const PreludeCase c = GetParam();
  auto rt = runtime_ptr();
  FilterOptions o = esm_options(c.lookup, 2);
  o.method = c.method;
  const HostImage depth = random_depth(128, 96, 6, 0.2f, 0.9f);
  const Points p = random_points(3000, 7);
  const std::vector<float> want = pipeline_visibility(rt, o, depth, p);

  const KernelPrelude pre = kernel_prelude(o);
  ASSERT_EQ(pre.files.size(), 5u);
  EXPECT_EQ(pre.files.front(), "shared_types.clh");
  cl::Program prog(rt->context(), pre.source + kCallerKernel);
  try {
    prog.build(pre.build_options.c_str());
  } catch (const cl::Error&) {
    FAIL() << prog.getBuildInfo<CL_PROGRAM_BUILD_LOG>(rt->device());
  }
  Pipeline pipe(rt, o, depth.width, depth.height);
  const cl::Buffer dbuf = to_device(depth.data);
  const cl::Buffer u = to_device(p.u), v = to_device(p.v), d = to_device(p.d), f = to_device(p.f);
  const cl::Buffer out(rt->context(), CL_MEM_READ_WRITE, p.count() * sizeof(float));
  const EventList filtered{pipe.prefilter(dbuf)};
  const LookupBuffers t = pipe.lookup_tables();
  cl::Kernel k(prog, "caller_shade");
  k.setArg(0, pipe.basis());
  auto buffer_or_null = [&k](cl_uint i, const cl::Buffer& b) {
    if (b())
      k.setArg(i, b);
    else
      k.setArg(i, sizeof(cl_mem), nullptr);
  };
  buffer_or_null(1, t.chain);
  buffer_or_null(2, t.sat);
  k.setArg(3, depth.width);
  k.setArg(4, depth.height);
  k.setArg(5, u);
  k.setArg(6, v);
  k.setArg(7, d);
  k.setArg(8, f);
  k.setArg(9, out);
  k.setArg(10, int(p.count()));
  k.setArg(11, pre.params.size(), pre.params.data());
  cl::Event shaded;
  rt->queue().enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(p.count()), cl::NullRange, &filtered, &shaded);
  const std::vector<float> got = from_device(out, p.count());
  double worst = 0;
  size_t dark = 0;
  for (size_t i = 0; i < p.count(); ++i) {
    ASSERT_TRUE(std::isfinite(got[i])) << i;
    worst = std::max(worst, double(std::fabs(got[i] - want[i])));
    dark += want[i] < 0.5f;
  }
  EXPECT_LE(worst, c.tolerance) << c.method << " lookup " << int(c.lookup);
  EXPECT_GT(dark, p.count() / 20) << "the comparison should cover shadowed receivers";
}

INSTANTIATE_TEST_SUITE_P(
    MethodsAndLookups, KernelPreludeCases,
    ::testing::Values(PreludeCase{"esm", Lookup::Bilinear, 2e-5f}, PreludeCase{"esm", Lookup::Mips, 2e-5f},
                      PreludeCase{"esm", Lookup::Sat, 2e-5f}, PreludeCase{"vsm", Lookup::Mips, 2e-5f},
                      PreludeCase{"msm", Lookup::Bilinear, 2e-5f}, PreludeCase{"csm", Lookup::Mips, 2e-5f}),
    [](const auto& info) {
      return std::string(info.param.method) + "_" +
             (info.param.lookup == Lookup::Bilinear ? "bilinear"
              : info.param.lookup == Lookup::Mips   ? "mips"
                                                    : "sat");
    });

TEST(Embedding, KernelPreludeRefusesRawDepthMethods) {
  FilterOptions o;
  o.method = "pcf";
  EXPECT_THROW(kernel_prelude(o), InputError);
  const auto files = kernel_files();
  EXPECT_TRUE(std::find(files.begin(), files.end(), "methods/esm.clh") != files.end());
  EXPECT_FALSE(kernel_source("methods/esm.clh").empty());
}

}  // namespace
}  // namespace sf::test

namespace sf::test {
namespace {

// The library's kernels build with -w unless warnings are asked for: drivers such as PoCL print
// compiler warnings to stderr, which would reach every user of the command or an embedding.
TEST(Embedding, CompilerWarningsAreOffUnlessAsked) {
  auto& rt = runtime();
  auto options_of = [&rt](const cl::Program& p) { return p.getBuildInfo<CL_PROGRAM_BUILD_OPTIONS>(rt.device()); };
  const std::string base = "-cl-std=CL1.2 -DSF_TEST_WARNINGS";
  const std::string quiet = options_of(rt.program({"common.clh", "receiver_plane.clh", "pcf.cl"}, base));
  EXPECT_NE(quiet.find(" -w"), std::string::npos) << quiet;
  rt.set_compiler_warnings(true);
  const std::string loud = options_of(rt.program({"common.clh", "receiver_plane.clh", "pcf.cl"}, base));
  rt.set_compiler_warnings(false);
  EXPECT_EQ(loud.find(" -w"), std::string::npos) << loud;
}

// With warnings on, a program built from source hands its build log to the sink (the command's
// -v prints it); off, the sink hears nothing. A macro defined twice in the options warns. The
// disk cache is off meanwhile: a binary from an earlier run has no log.
TEST(Embedding, BuildLogsReachTheSinkOnlyWithWarningsOn) {
  auto& rt = runtime();
  const char* cache = std::getenv("SHADOWFILTER_CACHE_DIR");
  const std::string saved = cache ? cache : "";
  setenv("SHADOWFILTER_CACHE_DIR", "", 1);
  std::vector<std::string> logs;
  rt.set_build_log_sink(
      [&logs](const std::string& files, const std::string& log) { logs.push_back(files + ": " + log); });
  const std::string twice = "-cl-std=CL1.2 -DSF_TEST_TWICE=1 -DSF_TEST_TWICE=2 -DSF_TEST_SINK=";
  rt.program({"common.clh", "receiver_plane.clh", "pcf.cl"}, twice + "0");
  EXPECT_TRUE(logs.empty()) << logs.front();
  rt.set_compiler_warnings(true);
  rt.program({"common.clh", "receiver_plane.clh", "pcf.cl"}, twice + "1");
  rt.set_compiler_warnings(false);
  rt.set_build_log_sink(nullptr);
  if (cache)
    setenv("SHADOWFILTER_CACHE_DIR", saved.c_str(), 1);
  else
    unsetenv("SHADOWFILTER_CACHE_DIR");
  ASSERT_EQ(logs.size(), 1u);
  EXPECT_NE(logs[0].find("pcf.cl: "), std::string::npos) << logs[0];
  EXPECT_NE(logs[0].find("SF_TEST_TWICE"), std::string::npos) << logs[0];
}

}  // namespace
}  // namespace sf::test
