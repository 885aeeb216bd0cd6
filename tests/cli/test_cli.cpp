// The `shadowfilter` command: every input error gives exit code 2, a one-line message naming
// the problem, and no output file; success writes exactly the output.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "cli_runner.hpp"
#include "image_io.hpp"
#include "sf_test_env.hpp"

namespace sf::test {
namespace {

namespace fs = std::filesystem;

class Cli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = temp_dir(std::string("cli_") + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    HostImage depth(24, 16, 1);
    for (int y = 0; y < 16; ++y)
      for (int x = 0; x < 24; ++x) depth.at(x, y) = (x > 8 && x < 16 && y > 4 && y < 12) ? 0.2f : 0.7f;
    io::write_image(path("sm.exr"), depth);
    io::write_image(path("rd.exr"), HostImage(24, 16, 1, 0.7f));
    HostImage rx(5, 4, 4);
    rx.channel_names = {"u", "v", "d", "f"};
    for (int y = 0; y < 4; ++y)
      for (int x = 0; x < 5; ++x) {
        rx.at(x, y, 0) = (x + 0.5f) / 5;
        rx.at(x, y, 1) = (y + 0.5f) / 4;
        rx.at(x, y, 2) = 0.7f;
        rx.at(x, y, 3) = 1.0f;
      }
    io::write_image(path("rx.exr"), rx);
  }
  std::string path(const std::string& name) const { return dir_ + "/" + name; }

  // An input error: exit 2, one line on stderr containing `expect`, no output, no temp file.
  void expect_input_error(const std::string& args, const std::string& expect) {
    const size_t files_before = count_files();
    RunResult r = run_cli(args + " -o " + path("out.exr"), dir_);
    EXPECT_EQ(r.exit_code, 2) << args << "\n" << r.err;
    EXPECT_NE(r.err.find(expect), std::string::npos) << "stderr: " << r.err;
    EXPECT_EQ(count_lines(r.err), 1u) << r.err;
    EXPECT_FALSE(fs::exists(path("out.exr")));
    EXPECT_EQ(count_files(), files_before) << "a temporary or partial file was left behind";
  }
  size_t count_files() const {
    size_t n = 0;
    for (auto& e : fs::directory_iterator(dir_)) n += e.is_regular_file();
    return n;
  }
  std::string dir_;
};

TEST_F(Cli, FiltersBothReceiverModesAndPrintsASummary) {
  RunResult r = run_cli("filter --shadow-map " + path("sm.exr") + " --receivers " + path("rx.exr") + " -o " +
                            path("vis.exr") + " --method esm --esm-c 80 --blur-radius 2",
                        dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(count_lines(r.out), 1u) << r.out;
  for (const char* word : {"esm c=80", "R=2", "24x16", "5x4", "transform", "blur", "reconstruct"})
    EXPECT_NE(r.out.find(word), std::string::npos) << word << " missing from: " << r.out;
  HostImage vis = io::load_depth_map(path("vis.exr"), {});
  EXPECT_EQ(vis.width, 5);
  EXPECT_EQ(vis.height, 4);

  r = run_cli(
      "filter --shadow-map " + path("sm.exr") + " --receiver-depth " + path("rd.exr") + " -o " + path("planar.tif"),
      dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  HostImage planar = io::load_depth_map(path("planar.tif"), {});
  EXPECT_EQ(planar.width, 24);
  EXPECT_NEAR(planar.at(12, 8), 0.0f, 1e-6);  // under the 0.2 occluder, receiver at 0.7
  EXPECT_NEAR(planar.at(2, 2), 1.0f, 1e-6);   // lit
}

TEST_F(Cli, MissingShadowMap) {
  expect_input_error("filter --shadow-map " + path("nope.exr") + " --receivers " + path("rx.exr"), "not found");
}

TEST_F(Cli, UnreadableShadowMap) {
  std::ofstream(path("junk.exr")) << "this is not an image\n";
  expect_input_error("filter --shadow-map " + path("junk.exr") + " --receivers " + path("rx.exr"), "junk.exr");
}

TEST_F(Cli, TruncatedShadowMap) {
  HostImage big = random_depth(256, 256, 1);
  io::write_image(path("big.exr"), big);
  fs::resize_file(path("big.exr"), fs::file_size(path("big.exr")) / 2);
  expect_input_error("filter --shadow-map " + path("big.exr") + " --receivers " + path("rx.exr"), "truncated");
}

TEST_F(Cli, EmptyFile) {
  std::ofstream(path("empty.exr")).close();
  expect_input_error("filter --shadow-map " + path("empty.exr") + " --receivers " + path("rx.exr"), "empty.exr");
}

TEST_F(Cli, WrongChannelCount) {
  io::write_image(path("two.exr"), HostImage(8, 8, 2, 0.5f));
  expect_input_error("filter --shadow-map " + path("two.exr") + " --receivers " + path("rx.exr"), "2 channels");
}

// A fifth channel ndl is read: receivers facing away from the light (ndl <= 0) come out 0, every
// other one as from the 4-channel file.
TEST_F(Cli, FiveChannelReceiversFilterLikeFourAndSixAreRefused) {
  HostImage rx(5, 4, 5);
  rx.channel_names = {"u", "v", "d", "f", "ndl"};
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 5; ++x) {
      rx.at(x, y, 0) = (x + 0.5f) / 5;
      rx.at(x, y, 1) = (y + 0.5f) / 4;
      rx.at(x, y, 2) = 0.7f;
      rx.at(x, y, 3) = 1.0f;
      rx.at(x, y, 4) = x == 2 ? -0.5f : 0.8f;
    }
  io::write_image(path("rx5.exr"), rx);
  const std::string args = "filter --shadow-map " + path("sm.exr") + " --method esm --blur-radius 2 --receivers ";
  ASSERT_EQ(run_cli(args + path("rx.exr") + " -o " + path("vis4.exr"), dir_).exit_code, 0);
  RunResult r = run_cli(args + path("rx5.exr") + " -o " + path("vis5.exr"), dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const HostImage v5 = io::load_depth_map(path("vis5.exr"), {}), v4 = io::load_depth_map(path("vis4.exr"), {});
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 5; ++x) EXPECT_EQ(v5.at(x, y), x == 2 ? 0.0f : v4.at(x, y)) << x << "," << y;
  EXPECT_NE(r.out.find("4 facing away"), std::string::npos) << r.out;

  io::write_image(path("rx6.exr"), HostImage(5, 4, 6, 0.5f));
  expect_input_error("filter --shadow-map " + path("sm.exr") + " --receivers " + path("rx6.exr"),
                     "expected 3, 4, 5, 8 or 12 channels");
}

TEST_F(Cli, NonFiniteDepthIsAnErrorUnlessAskedFar) {
  HostImage depth(8, 8, 1, 0.5f);
  depth.at(3, 2) = std::nanf("");
  depth.at(4, 2) = INFINITY;
  io::write_image(path("nan.exr"), depth);
  io::write_image(path("rd8.exr"), HostImage(8, 8, 1, 0.6f));
  expect_input_error("filter --shadow-map " + path("nan.exr") + " --receiver-depth " + path("rd8.exr"),
                     "--nonfinite far");
  RunResult r = run_cli("filter --shadow-map " + path("nan.exr") + " --receiver-depth " + path("rd8.exr") +
                            " --nonfinite far -q -o " + path("ok.exr"),
                        dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  HostImage vis = io::load_depth_map(path("ok.exr"), {});
  for (float v : vis.data) EXPECT_TRUE(std::isfinite(v) && v >= 0 && v <= 1);
  EXPECT_NEAR(vis.at(3, 2), 1.0f, 1e-6);  // the NaN texel became the far plane: lit
  EXPECT_NEAR(vis.at(0, 0), 0.0f, 1e-2);  // receiver 0.6 behind 0.5: exp(-8) = 3e-4
}

TEST_F(Cli, ReceiverImageMustBeFloat) {
  HostImage rx(5, 4, 3, 0.5f);
  io::write_image(path("rx16.png"), rx);
  expect_input_error("filter --shadow-map " + path("sm.exr") + " --receivers " + path("rx16.png"), "float");
}

TEST_F(Cli, ReceiverDepthSizeMustMatch) {
  io::write_image(path("small.exr"), HostImage(12, 16, 1, 0.7f));
  expect_input_error("filter --shadow-map " + path("sm.exr") + " --receiver-depth " + path("small.exr"), "12x16");
}

// A narrow storage format with a prefilter runs (the blur filters every format): csm in unorm8
// and f16, R = 2, on the planar receivers: in [0,1], dark under the occluder, lit beside it.
TEST_F(Cli, NarrowStorageWithBlurRuns) {
  for (const char* storage : {"unorm8", "f16"}) {
    const RunResult r =
        run_cli("filter --shadow-map " + path("sm.exr") + " --receiver-depth " + path("rd.exr") + " -o " +
                    path("narrow.exr") + " --method csm --csm-order 4 --blur-radius 2 --storage " + storage,
                dir_);
    ASSERT_EQ(r.exit_code, 0) << storage << ": " << r.err;
    const HostImage v = io::load_depth_map(path("narrow.exr"), {});
    ASSERT_EQ(v.width, 24);
    for (float x : v.data) ASSERT_TRUE(x >= 0.0f && x <= 1.0f) << storage << ": " << x;
    EXPECT_LT(v.at(12, 8), 0.1f) << storage;  // under the 0.2 occluder
    EXPECT_GT(v.at(2, 2), 1.0f - 1.0f / 255.0f) << storage;
    fs::remove(path("narrow.exr"));
  }
}

TEST_F(Cli, ArgumentErrors) {
  expect_input_error("filter --shadow-map " + path("sm.exr"),
                     "exactly one of --receivers, --receiver-depth or --camera");
  expect_input_error("filter --shadow-map " + path("sm.exr") + " --receivers " + path("rx.exr") + " --method nosuch",
                     "unknown method");
  expect_input_error("filter --shadow-map " + path("sm.exr") + " --receivers " + path("rx.exr") + " --esm-c 500",
                     "174");
  expect_input_error("filter --shadow-map " + path("sm.exr") + " --receivers " + path("rx.exr") + " --blur-radius 1000",
                     "--blur-radius");
  for (const char* sigma : {"nan", "0", "-1", "inf"})
    expect_input_error("filter --shadow-map " + path("sm.exr") + " --receivers " + path("rx.exr") +
                           " --blur-radius 2 --blur-sigma " + sigma,
                       "--blur-sigma");
  // The library names option fields (FilterOptions::csm.order); the command its own flags.
  expect_input_error(
      "filter --shadow-map " + path("sm.exr") + " --receivers " + path("rx.exr") + " --method csm --csm-order 99",
      "--csm-order must be in 1..32, got 99");
  expect_input_error("filter --shadow-map " + path("sm.exr") + " --receivers " + path("rx.exr") + " --encoding weird",
                     "weird");
  expect_input_error(
      "filter --shadow-map " + path("sm.exr") + " --receivers " + path("rx.exr") + " --device no-such-device",
      "no-such-device");
  expect_input_error("filter --shadow-map " + path("sm.exr") + " --receivers " + path("rx.exr") + " --bogus-flag",
                     "bogus");
}

// Lookups that cannot hold the map (docs/numerics.md, "Lookup limits") are refused before
// anything runs: exit 2, one line naming the limit and what to use instead, no output. At the
// limit the same lookup runs. sm.exr holds depths 0.2 and 0.7 on 24 x 16 texels, where the table
// holds esm's c (zmax - zmin) up to 16.9.
TEST_F(Cli, RefusedLookupsExitTwoAndWriteNothing) {
  const std::string in = "filter --shadow-map " + path("sm.exr") + " --receivers " + path("rx.exr");
  expect_input_error(in + " --method esm --esm-c 80 --lookup sat", "--lookup sat cannot hold esm with --esm-c 80");
  expect_input_error(in + " --method esm --lookup sat", "exp(60); use --lookup mips or --esm-c <= 33.");
  expect_input_error(in + " --method evsm2 --evsm-pos 40 --lookup sat",
                     "--lookup sat cannot hold evsm2 with --evsm-pos 40");
  expect_input_error(in + " --method evsm4 --lookup sat --evsm-pos 1 --evsm-neg 42", "with --evsm-neg 42");
  // Depths up to 1 at c = 174: the table's float32 sums would overflow.
  HostImage far(24, 16, 1, 1.0f);
  far.at(3, 3) = 0.95f;
  io::write_image(path("far.exr"), far);
  expect_input_error(
      "filter --shadow-map " + path("far.exr") + " --receiver-depth " + path("rd.exr") + " --esm-c 174 --lookup sat",
      "float32 entries would overflow");
  const RunResult r = run_cli(in + " --method esm --esm-c 33 --lookup sat -o " + path("limit.exr"), dir_);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::exists(path("limit.exr")));
}

// Every number option of every command must be finite (and --blur-sigma positive, above): NaN,
// infinities and values past the float range are input errors, never a silent default.
TEST_F(Cli, NonFiniteNumbersAreInputErrors) {
  const std::string filter = "filter --shadow-map " + path("sm.exr") + " --receivers " + path("rx.exr") + " ";
  for (const char* option : {"--esm-c nan", "--esm-c inf", "--lbr -inf", "--bias nan", "--esm-zmax-offset nan",
                             "--esm-threshold-eps inf", "--csm-alpha 1e50", "--near nan", "--vsm-min-variance nan",
                             "--receiver-plane-max-slope inf", "--max-error nan", "--sref-bias nan"})
    expect_input_error(filter + option,
                       std::string(option).substr(0, std::string(option).find(' ')) + ": must be a finite number");
  expect_input_error(filter + "--esm-c -5", "--esm-c must be a positive number");
  expect_input_error("soft --shadow-map " + path("sm.exr") + " --receivers " + path("rx.exr") + " --light-size nan",
                     "--light-size: must be a finite number");
  expect_input_error("evaluate " + dir_ + " --max-error inf", "--max-error: must be a finite number");
  expect_input_error("scene spheres --light-size nan", "--light-size: must be a finite number");
  expect_input_error("scene spheres --light-dir 1,nan,0", "--light-dir: must be a finite number");
}

// The OpenCL compiler's warnings reach the terminal only with -v: a run that builds every
// program afresh (an empty cache, PoCL's own kernel cache off) prints no warning on stderr (the
// driver may still say things of its own, such as PoCL on a POCL_WORK_GROUP_METHOD it does not
// know); -v runs too.
TEST_F(Cli, CompilerWarningsOnlyWithVerbose) {
  const std::string run = "filter --shadow-map " + path("sm.exr") + " --receivers " + path("rx.exr") +
                          " --method vsm -q -o " + path("vis.exr");
  RunResult r = run_cli_process(run, dir_, "SHADOWFILTER_CACHE_DIR=" + path("fresh_cache") + " POCL_KERNEL_CACHE=0");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  for (const char* word : {"warning", "generated", "build log"})
    EXPECT_EQ(r.err.find(word), std::string::npos) << r.err;
  r = run_cli(run + " -v", dir_);
  EXPECT_EQ(r.exit_code, 0) << r.err;
}

TEST_F(Cli, NeverOverwritesAnInput) {
  const auto before = fs::file_size(path("sm.exr"));
  RunResult r = run_cli(
      "filter --shadow-map " + path("sm.exr") + " --receiver-depth " + path("rd.exr") + " -o " + path("rd.exr"), dir_);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("refusing"), std::string::npos) << r.err;
  EXPECT_EQ(fs::file_size(path("sm.exr")), before);
  HostImage rd = io::load_depth_map(path("rd.exr"), {});
  EXPECT_EQ(rd.at(0, 0), 0.7f);
}

TEST_F(Cli, UnwritableOutputLeavesNothing) {
  RunResult r = run_cli(
      "filter --shadow-map " + path("sm.exr") + " --receivers " + path("rx.exr") + " -o " + path("no/such/dir/out.exr"),
      dir_);
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_EQ(count_lines(r.err), 1u) << r.err;
}

TEST_F(Cli, HelpAndDevices) {
  for (const char* cmd : {"--help", "filter --help", "devices --help", "methods --help"}) {
    RunResult r = run_cli(cmd, dir_);
    EXPECT_EQ(r.exit_code, 0) << cmd;
    EXPECT_NE(r.out.find("Usage"), std::string::npos) << cmd << ": " << r.out;
  }
  RunResult r = run_cli("devices", dir_);
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_NE(r.out.find("(default)"), std::string::npos) << r.out;
  r = run_cli("methods", dir_);
  EXPECT_NE(r.out.find("esm"), std::string::npos) << r.out;
}

// Values that used to pass (or end the process on an uncaught exception or an Embree assertion):
// each is refused with exit 2 and one line, before anything is written.
TEST_F(Cli, ValuesOutsideTheirBoundsAreRefusedInEveryCommand) {
  const std::string run =
      "filter --shadow-map " + path("sm.exr") + " --receivers " + path("rx.exr") + " -o " + path("out.exr") + " ";
  const std::string scene = "scene spheres -o " + path("scene") + " --size 32 --receivers 16x16 --samples 1 -q ";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {run + "--receiver-plane maybe", "--receiver-plane"},
      {run + "--storage f64", "storage 'f64'"},
      {run + "--vector-width 0", "--vector-width"},
      {run + "--vector-width 3", "--vector-width"},
      {run + "--vector-width 1024", "--vector-width"},
      {run + "--auto --auto-runs 0", "--auto-runs"},
      {run + "--auto --auto-rounds 0", "--auto-rounds"},
      {run + "--auto --max-error -1", "--max-error"},
      {scene + "--camera-pos 0,0,1e30", "--camera-pos"},
      {scene + "--camera-fov 1e-30", "--camera-fov"},
      {scene + "--light perspective --fov 0", "--fov"},
      {scene + "--threads -1", "--threads"},
      {"coherent sky -o " + path("sky.exr") + " --sun-elevation 100", "--sun-elevation"},
      {"coherent build box -o " + path("box.csm") + " --threads -1", "--threads"},
      {"evaluate " + data_path("spheres") + " -o " + path("eval") + " --methods ''", "names no method"},
  };
  for (const auto& [args, expect] : cases) {
    const RunResult r = run_cli(args, dir_);
    EXPECT_EQ(r.exit_code, 2) << args << "\n" << r.err;
    EXPECT_EQ(count_lines(r.err), 1u) << args << "\n" << r.err;
    EXPECT_NE(r.err.find(expect), std::string::npos) << args << "\n" << r.err;
  }
  for (const char* name : {"out.exr", "scene", "sky.exr", "box.csm", "eval"})
    EXPECT_FALSE(fs::exists(path(name))) << name;
}

}  // namespace
}  // namespace sf::test
