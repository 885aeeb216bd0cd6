// The launch-shape families (docs/gpu.md, "Launch shapes"; host/src/runtime/schedule_defaults.cpp): the
// Gpu family's blur, SAT and pyramid forced on the test device (PoCL, a CPU) against the scalar
// reference with the tolerances of the Cpu family's tests (test_kernels.cpp, test_sat.cpp,
// test_pyramid.cpp), on sizes that are not multiples of the work-groups (partial groups), and
// against the Cpu family where both compute the same float sequence. Smaller groups (the
// fallbacks for devices with fewer work-items) are run as well.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "lookups.hpp"
#include "reference.hpp"
#include "schedule_defaults.hpp"
#include "sf_test_env.hpp"
#include "shadowfilter/errors.hpp"
#include "shadowfilter/blur.hpp"
#include "shadowfilter/mips.hpp"
#include "shadowfilter/sat.hpp"
#include "test_methods_common.hpp"

namespace sf::test {
namespace {

ScheduleOptions family(ScheduleFamily f, int work_group = 0) {
  ScheduleOptions s;
  s.family = f;
  s.gpu_work_group = work_group;
  return s;
}

std::vector<uint8_t> raw_from(const cl::Buffer& buf, size_t bytes) {
  std::vector<uint8_t> raw(bytes);
  runtime().queue().enqueueReadBuffer(buf, CL_TRUE, 0, bytes, raw.data());
  return raw;
}

// --- the table ----------------------------------------------------------------

TEST(ScheduleDefaults, FamilyByDeviceType) {
  EXPECT_EQ(default_family("CPU"), ScheduleFamily::Cpu);
  EXPECT_EQ(default_family("GPU"), ScheduleFamily::Gpu);
  EXPECT_EQ(default_family("accelerator"), ScheduleFamily::Gpu);
  EXPECT_EQ(default_family("other"), ScheduleFamily::Gpu);
  EXPECT_EQ(resolve_family(runtime(), ScheduleFamily::Auto), default_family(runtime().info().type));
  EXPECT_EQ(resolve_family(runtime(), ScheduleFamily::Gpu), ScheduleFamily::Gpu);
  EXPECT_EQ(resolve_family(runtime(), ScheduleFamily::Cpu), ScheduleFamily::Cpu);
  EXPECT_EQ(launch_defaults(ScheduleFamily::Cpu).blur_group.items(), 1);
  const LaunchDefaults& g = launch_defaults(ScheduleFamily::Gpu);
  EXPECT_GE(g.blur_group.items(), 64);
  EXPECT_LE(g.blur_group.items(), 256);
  EXPECT_GE(g.sat_group, 64);
  EXPECT_GE(g.pyramid_group * g.pyramid_group, 64);
  EXPECT_THROW(launch_defaults(ScheduleFamily::Auto), InputError);
  for (ScheduleFamily f : {ScheduleFamily::Auto, ScheduleFamily::Cpu, ScheduleFamily::Gpu})
    EXPECT_EQ(parse_schedule_family(schedule_family_name(f)), f);
  EXPECT_THROW(parse_schedule_family("tpu"), InputError);
  EXPECT_EQ(gpu_group_items(runtime(), 256, 0), std::min<int>(256, int(runtime().info().max_work_group_size)));
  EXPECT_EQ(gpu_group_items(runtime(), 256, 64), 64);
  for (int bad : {-1, 3, 100, 2048}) EXPECT_THROW(gpu_group_items(runtime(), 256, bad), InputError) << bad;
}

// --- blur ---------------------------------------------------------------------

struct BlurCase {
  Storage storage;
  int width, height, channels, radius;
  int work_group = 0;  // 0: the table's
};

std::string blur_name(const ::testing::TestParamInfo<BlurCase>& i) {
  const BlurCase& c = i.param;
  return std::string(storage_name(c.storage)) + "_" + std::to_string(c.width) + "x" + std::to_string(c.height) + "x" +
         std::to_string(c.channels) + "_R" + std::to_string(c.radius) + "_g" + std::to_string(c.work_group);
}

class GpuBlur : public ::testing::TestWithParam<BlurCase> {};

// Against the reference in double with BlurStorage's bound (f32: BlurShapes' 1e-5 relative),
// the same codes as the Cpu family (the same fma sequence per texel), and in place the same.
TEST_P(GpuBlur, MatchesReferenceAndTheCpuFamily) {
  const BlurCase bc = GetParam();
  const ImageShape shape{bc.width, bc.height, bc.channels, storage_bytes(bc.storage)};
  const size_t n = shape.plane_texels() * shape.channels;
  const StoredImage img = random_stored(n, bc.storage, bc.width * 31 + bc.radius);
  ref::Planes in(bc.width, bc.height, bc.channels);
  double maxabs = 0;
  for (size_t i = 0; i < n; ++i) {
    in.data[i] = img.values[i];
    maxabs = std::max(maxabs, std::fabs(double(img.values[i])));
  }
  cl::Buffer src = stored_buffer(img);
  cl::Buffer tmp(runtime().context(), CL_MEM_READ_WRITE, shape.bytes());
  cl::Buffer gpu(runtime().context(), CL_MEM_READ_WRITE, shape.bytes());
  cl::Buffer cpu(runtime().context(), CL_MEM_READ_WRITE, shape.bytes());
  const BlurOptions blur{bc.radius, 0.0f};
  enqueue_blur(runtime(), blur, family(ScheduleFamily::Gpu, bc.work_group), bc.storage, shape, src, tmp, gpu).wait();
  const auto got = read_stored(gpu, n, bc.storage);
  const auto want = ref::blur(in, bc.radius, 0.0);
  const double e = 1.2e-7 * (bc.radius + 2) * maxabs;
  for (size_t i = 0; i < n; ++i) {
    const double w = want.data[i];
    ASSERT_TRUE(std::isfinite(got[i])) << "index " << i;
    if (bc.storage == Storage::F32)
      ASSERT_NEAR(got[i], w, 1e-5 * std::fabs(w)) << "index " << i;
    else
      ASSERT_LE(std::fabs(got[i] - w), 0.5 * storage_step(std::fabs(w) + e, bc.storage) + e)
          << "index " << i << " want " << w;
  }
  if (bc.work_group == 0 && bc.radius <= 3 && bc.storage != Storage::Unorm16) {
    // One Cpu schedule for every shape (rows fixed: one program per radius and storage; the
    // larger radii's Cpu programs take 5-10 s each to build on PoCL); every Cpu schedule gives
    // the same codes (BlurStorage.SchedulesAreBitIdentical).
    ScheduleOptions cpu_sched = family(ScheduleFamily::Cpu);
    cpu_sched.blur_rows = 16;
    enqueue_blur(runtime(), blur, cpu_sched, bc.storage, shape, src, tmp, cpu).wait();
    EXPECT_EQ(raw_from(gpu, shape.bytes()), raw_from(cpu, shape.bytes())) << "Gpu and Cpu families differ";
  }
  cl::Buffer a = stored_buffer(img);
  enqueue_blur(runtime(), blur, family(ScheduleFamily::Gpu, bc.work_group), bc.storage, shape, a, tmp, a).wait();
  EXPECT_EQ(raw_from(a, shape.bytes()), raw_from(gpu, shape.bytes())) << "in place";
}

std::vector<BlurCase> blur_cases() {
  // Few radii per storage: a program build costs about a second on PoCL. The largest radius
  // (the halo far past the tile and the image), no blur, and smaller groups (32: a tile of 4 rows
  // under a halo of 16; 1: a single item) once each.
  return {{Storage::F32, 1, 1, 1, 3},
          {Storage::F32, 7, 5, 2, 8},
          {Storage::F32, 33, 17, 3, 1},
          {Storage::F32, 129, 257, 1, 3},
          {Storage::F32, 40, 70, 2, kMaxBlurRadius},
          {Storage::F16, 7, 5, 2, 3},
          {Storage::F16, 129, 257, 1, 3},
          {Storage::F16, 33, 17, 1, 0},
          {Storage::Unorm16, 1, 1, 1, 3},
          {Storage::Unorm16, 33, 17, 3, 3},
          {Storage::Unorm8, 7, 5, 2, 3},
          {Storage::Unorm8, 129, 257, 1, 3},
          {Storage::F32, 33, 17, 2, 3, 64},
          {Storage::Unorm8, 33, 17, 1, 8, 32},
          {Storage::F32, 7, 5, 1, 3, 1}};
}
INSTANTIATE_TEST_SUITE_P(Shapes, GpuBlur, ::testing::ValuesIn(blur_cases()), blur_name);

// --- summed-area tables --------------------------------------------------------

struct SatCase {
  Storage storage;
  int w, h, channels;
  SatAccumulator accumulator = SatAccumulator::Auto;
  int work_group = 0;
};

std::string sat_name(const ::testing::TestParamInfo<SatCase>& i) {
  const SatCase& c = i.param;
  return std::string(storage_name(c.storage)) + "_" + std::to_string(c.w) + "x" + std::to_string(c.h) + "x" +
         std::to_string(c.channels) + (c.accumulator == SatAccumulator::FloatFloat ? "_ff" : "") + "_g" +
         std::to_string(c.work_group);
}

class GpuSat : public ::testing::TestWithParam<SatCase> {};

// Every entry hi + lo against the double table: Sat's tolerance, 1e-11 |S| + 1e-12; built twice
// on one scratch (the second build must not depend on what the first left there).
TEST_P(GpuSat, TableMatchesTheReference) {
  const SatCase sc = GetParam();
  const ImageShape shape{sc.w, sc.h, sc.channels, storage_bytes(sc.storage)};
  const StoredImage img = random_stored(size_t(sc.w) * sc.h * sc.channels, sc.storage, sc.w * 13 + sc.h);
  ref::Planes in(sc.w, sc.h, sc.channels);
  for (size_t i = 0; i < img.values.size(); ++i) in.data[i] = img.values[i];
  const SatLayout L = sat_layout(shape);
  cl::Buffer table(runtime().context(), CL_MEM_READ_WRITE, L.table_floats * sizeof(float));
  cl::Buffer bands(runtime().context(), CL_MEM_READ_WRITE, L.band_floats * sizeof(float));
  SatBuild build;
  build.accumulator = sc.accumulator;
  cl::Buffer src = stored_buffer(img);
  for (int i = 0; i < 2; ++i)
    enqueue_sat(runtime(), sc.storage, build, family(ScheduleFamily::Gpu, sc.work_group), shape, src, table, bands)
        .wait();
  // The table's entries (not the rows' padding, which no build writes).
  auto entries = [&](const cl::Buffer& t) {
    const auto all = from_device(t, L.table_floats);
    std::vector<double> out;
    for (int c = 0; c < sc.channels; ++c)
      for (int y = 0; y <= sc.h; ++y)
        for (int x = 0; x <= sc.w; ++x) out.push_back(double(all[L.at(c, false, x, y)]) + all[L.at(c, true, x, y)]);
    return out;
  };
  const auto got = entries(table);
  const ref::Planes want = ref::sat_table(in);
  size_t i = 0;
  for (int c = 0; c < sc.channels; ++c)
    for (int y = 0; y <= sc.h; ++y)
      for (int x = 0; x <= sc.w; ++x, ++i) {
        const double w = want.at(c, x, y);
        ASSERT_NEAR(got[i], w, 1e-11 * w + 1e-12) << "channel " << c << " at " << x << "," << y;
      }
  // The explicit schedule is the same build as the family's Auto.
  SatBuild expl;
  expl.accumulator = sc.accumulator;
  expl.schedule = SatSchedule::WorkGroupScan;
  cl::Buffer table2(runtime().context(), CL_MEM_READ_WRITE, L.table_floats * sizeof(float));
  enqueue_sat(runtime(), sc.storage, expl, family(ScheduleFamily::Auto, sc.work_group), shape, src, table2, bands)
      .wait();
  EXPECT_EQ(entries(table2), got);
}

std::vector<SatCase> sat_cases() {
  std::vector<SatCase> out;
  for (SatAccumulator a : {SatAccumulator::Auto, SatAccumulator::FloatFloat})
    for (SatCase c : {SatCase{Storage::F32, 1, 1, 1}, SatCase{Storage::F32, 7, 5, 2}, SatCase{Storage::F32, 33, 17, 1},
                      SatCase{Storage::F32, 129, 257, 1}, SatCase{Storage::F32, 300, 640, 2}}) {
      c.accumulator = a;
      out.push_back(c);
    }
  for (Storage st : {Storage::F16, Storage::Unorm8}) out.push_back({st, 37, 100, 2});
  out.push_back({Storage::F32, 129, 70, 1, SatAccumulator::Auto, 64});
  return out;
}
INSTANTIATE_TEST_SUITE_P(Shapes, GpuSat, ::testing::ValuesIn(sat_cases()), sat_name);

// --- pyramids -------------------------------------------------------------------

struct PyramidCase {
  Storage storage;
  int w, h, channels;
  int work_group = 0;
  int ops = 7;  // bit op: the reductions to run (1 mean, 2 max, 4 min)
};

std::string pyramid_name(const ::testing::TestParamInfo<PyramidCase>& i) {
  const PyramidCase& c = i.param;
  return std::string(storage_name(c.storage)) + "_" + std::to_string(c.w) + "x" + std::to_string(c.h) + "x" +
         std::to_string(c.channels) + "_g" + std::to_string(c.work_group);
}

class GpuPyramid : public ::testing::TestWithParam<PyramidCase> {};

// Every level of the mean, max and min chains against the reference with Pyramid's (f32:
// 1e-6 relative + 1e-7) and PyramidStorage's (one storage step) tolerances, max / min exact;
// in f32 the same values as the Cpu family (the same float operations; unrounded levels there
// and here are float either way).
TEST_P(GpuPyramid, EveryLevelMatchesTheReference) {
  const PyramidCase pc = GetParam();
  const ImageShape shape{pc.w, pc.h, pc.channels, storage_bytes(pc.storage)};
  const StoredImage img = random_stored(size_t(pc.w) * pc.h * pc.channels, pc.storage, pc.w * 5 + pc.h);
  ref::Planes in(pc.w, pc.h, pc.channels);
  for (size_t i = 0; i < img.values.size(); ++i) in.data[i] = img.values[i];
  const MipLayout L = mip_layout(pc.w, pc.h, pc.channels);
  const size_t values = std::max<size_t>(L.chain_values, 1);
  cl::Buffer level0 = stored_buffer(img);
  for (int op : {0, 1, 2}) {
    if (!(pc.ops >> op & 1)) continue;
    cl::Buffer chain(runtime().context(), CL_MEM_READ_WRITE, values * storage_bytes(pc.storage));
    enqueue_pyramid(runtime(), static_cast<Reduce>(op), pc.storage, family(ScheduleFamily::Gpu, pc.work_group), shape,
                    level0, chain)
        .wait();
    const auto got = read_stored(chain, values, pc.storage);
    const auto want = ref::mip_chain(in, op);
    ASSERT_EQ(int(want.size()) - 1, L.top());
    for (int k = 1; k <= L.top(); ++k)
      for (size_t i = 0; i < want[k].data.size(); ++i) {
        const double w = want[k].data[i];
        const float g = got[L.levels[k].offset + i];
        if (op != 0) {
          ASSERT_EQ(g, float(ref::quantise(w, pc.storage))) << "op " << op << " level " << k << " index " << i;
        } else if (pc.storage == Storage::F32) {
          ASSERT_NEAR(g, w, 1e-6 * std::abs(w) + 1e-7) << "level " << k << " index " << i;
        } else {
          ASSERT_NEAR(g, ref::quantise(w, pc.storage), storage_step(w, pc.storage) + 1e-6 * std::abs(w))
              << "level " << k << " index " << i;
        }
      }
    if (pc.storage == Storage::F32 && L.top() > 0) {
      cl::Buffer cpu(runtime().context(), CL_MEM_READ_WRITE, values * sizeof(float));
      enqueue_pyramid(runtime(), static_cast<Reduce>(op), pc.storage, family(ScheduleFamily::Cpu), shape, level0, cpu)
          .wait();
      EXPECT_EQ(from_device(cpu, values), got) << "op " << op << ": Gpu and Cpu families differ";
    }
  }
}

std::vector<PyramidCase> pyramid_cases() {
  std::vector<PyramidCase> out;
  for (PyramidCase c :
       {PyramidCase{Storage::F32, 1, 1, 1}, PyramidCase{Storage::F32, 7, 5, 1}, PyramidCase{Storage::F32, 1, 9, 1},
        PyramidCase{Storage::F32, 33, 17, 3}, PyramidCase{Storage::F32, 129, 257, 1},
        PyramidCase{Storage::F32, 517, 300, 2}, PyramidCase{Storage::F32, 1000, 37, 1}})
    out.push_back(c);
  // Narrow storages: the mean (rounded per launch) and, in unorm8, max; groups of 64 (8x8, four
  // levels per launch). A program build costs about a second on PoCL.
  for (Storage st : {Storage::F16, Storage::Unorm8}) {
    const int ops = st == Storage::Unorm8 ? 3 : 1;
    out.push_back({st, 33, 17, 1, 0, ops});
    out.push_back({st, 300, 129, 2, 0, ops});
  }
  out.push_back({Storage::F32, 129, 257, 2, 64, 1});
  return out;
}
INSTANTIATE_TEST_SUITE_P(Shapes, GpuPyramid, ::testing::ValuesIn(pyramid_cases()), pyramid_name);

}  // namespace
}  // namespace sf::test
