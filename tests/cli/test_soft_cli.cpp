// `shadowfilter soft --lights FILE` (host/cli/options_soft.cpp; docs/soft.md "Several lights"):
// a good list gives the weighted mean of the single-light runs; a malformed line, an unknown key,
// a missing file or a missing map is an input error: exit 2, one line naming the problem, no output;
// rectangular lights (--light-size W,H, size=W,H); --cssm-storage by name; --normal-offset in soft
// and filter; --auto against a soft reference (soft_auto.cpp): its output meets the bound, on the
// test map and on a bundled scene's ray-traced reference, and what it cannot measure is refused.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

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

class SoftCli : public ::testing::Test {
 protected:
  // 32 x 32 map: floor at 0.8, a square occluder at 0.3 over x, y in [10, 22); 8 x 8 receivers on
  // the floor. Map b is the same with the occluder shifted, so the two lights shadow differently.
  void SetUp() override {
    dir_ = temp_dir(std::string("soft_cli_") + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    for (int shift : {0, 6}) {
      HostImage depth(32, 32, 1, 0.8f);
      for (int y = 10; y < 22; ++y)
        for (int x = 10 + shift; x < 22 + shift && x < 32; ++x) depth.at(x, y) = 0.3f;
      io::write_image(path(shift ? "b.exr" : "a.exr"), depth);
    }
    write_receivers("rx.exr", 8);
  }
  // n x n receivers on the floor (d = 0.8) at the centres of an n x n grid over the map.
  void write_receivers(const std::string& name, int n) const {
    HostImage rx(n, n, 4);
    rx.channel_names = {"u", "v", "d", "f"};
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        rx.at(x, y, 0) = (x + 0.5f) / n;
        rx.at(x, y, 1) = (y + 0.5f) / n;
        rx.at(x, y, 2) = 0.8f;
        rx.at(x, y, 3) = 1.0f;
      }
    io::write_image(path(name), rx);
  }
  std::string path(const std::string& name) const { return dir_ + "/" + name; }
  void write(const std::string& name, const std::string& text) const { std::ofstream(path(name)) << text; }
  // The command most tests run: pcss under a 0.2 square light over a map 1 unit wide.
  static constexpr const char* kPcss = "soft --method pcss --light-extent 1 --light-size 0.2 ";
  RunResult run(const std::string& args) const { return run_cli(kPcss + args, dir_); }
  void expect_input_error(const std::string& args, const std::string& expect) const {
    expect_refusal(kPcss + args, expect);
  }
  // The whole command line `command -o out.exr`: exit 2, one line holding `expect`, no output.
  void expect_refusal(const std::string& command, const std::string& expect) const {
    const RunResult r = run_cli(command + " -o " + path("out.exr"), dir_);
    EXPECT_EQ(r.exit_code, 2) << command << "\n" << r.err;
    EXPECT_NE(r.err.find(expect), std::string::npos) << "stderr: " << r.err;
    EXPECT_EQ(count_lines(r.err), 1u) << r.err;
    EXPECT_FALSE(fs::exists(path("out.exr")));
  }
  std::string dir_;
};

TEST_F(SoftCli, LightListIsTheWeightedMeanOfSingleRuns) {
  ASSERT_EQ(run("--shadow-map " + path("a.exr") + " --receivers " + path("rx.exr") + " -o " + path("va.exr") + " -q")
                .exit_code,
            0);
  ASSERT_EQ(run("--shadow-map " + path("b.exr") + " --receivers " + path("rx.exr") + " -o " + path("vb.exr") + " -q")
                .exit_code,
            0);
  // Relative paths (from the list's directory), comments, blank lines, weights 1 and 3.
  write("lights.txt", "# two lights\n\na.exr rx.exr\n  b.exr rx.exr weight=3   # the second\n");
  const RunResult r = run("--lights " + path("lights.txt") + " -o " + path("both.exr"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("2 light(s)"), std::string::npos) << r.out;
  const HostImage a = io::load_depth_map(path("va.exr"), {}), b = io::load_depth_map(path("vb.exr"), {});
  const HostImage both = io::load_depth_map(path("both.exr"), {});
  ASSERT_EQ(both.width, 8);
  ASSERT_EQ(both.height, 8);
  size_t differ = 0;
  for (size_t i = 0; i < both.data.size(); ++i) {
    EXPECT_NEAR(both.data[i], (a.data[i] + 3.0f * b.data[i]) / 4.0f, 1e-6f) << i;
    differ += std::abs(a.data[i] - b.data[i]) > 0.05f;
  }
  EXPECT_GT(differ, 4u) << "the two maps must shadow different receivers";

  // size= overrides the light size of its line only: a larger light widens the penumbra.
  write("sized.txt", "a.exr rx.exr size=0.6\n");
  ASSERT_EQ(run("--lights " + path("sized.txt") + " -o " + path("wide.exr") + " -q").exit_code, 0);
  const HostImage wide = io::load_depth_map(path("wide.exr"), {});
  size_t partial_a = 0, partial_wide = 0;
  for (size_t i = 0; i < a.data.size(); ++i) {
    partial_a += a.data[i] > 0.02f && a.data[i] < 0.98f;
    partial_wide += wide.data[i] > 0.02f && wide.data[i] < 0.98f;
  }
  EXPECT_GT(partial_wide, partial_a);
}

TEST_F(SoftCli, MalformedListsAreOneLineInputErrors) {
  write("one_field.txt", "a.exr rx.exr\nb.exr\n");
  expect_input_error("--lights " + path("one_field.txt"), "one_field.txt:2: expected SHADOWMAP RECEIVERS");
  write("unknown_key.txt", "a.exr rx.exr colour=red\n");
  expect_input_error("--lights " + path("unknown_key.txt"), "unknown_key.txt:1: unknown 'colour=red'");
  write("bad_weight.txt", "a.exr rx.exr weight=heavy\n");
  expect_input_error("--lights " + path("bad_weight.txt"), "bad_weight.txt:1: weight=heavy is not a number");
  write("negative.txt", "a.exr rx.exr weight=-1\n");
  expect_input_error("--lights " + path("negative.txt"), "negative.txt:1: weight=-1 is not a number >= 0");
  write("zero.txt", "a.exr rx.exr weight=0\nb.exr rx.exr weight=0\n");
  expect_input_error("--lights " + path("zero.txt"), "the light weights sum to 0");
  write("empty.txt", "# nothing\n\n");
  expect_input_error("--lights " + path("empty.txt"), "holds no light");
  expect_input_error("--lights " + path("no_such_list.txt"),
                     "light list '" + path("no_such_list.txt") + "': file not found");
  write("missing_map.txt", "no_such_map.exr rx.exr\n");
  expect_input_error("--lights " + path("missing_map.txt"), "no_such_map.exr");
  write("lights.txt", "a.exr rx.exr\n");
  expect_input_error("--lights " + path("lights.txt") + " --shadow-map " + path("a.exr"),
                     "--lights replaces --shadow-map");
}

// --light-size W,H: a rectangular light. The map and the receivers are symmetric about the
// diagonal, so a W x H light's visibility is the H x W light's transposed (every method, the
// mips' anisotropic probes along u against those along v); it differs from the square's; a light
// list's size=W,H is the flag's; malformed sides are one-line input errors.
TEST_F(SoftCli, RectangularLightsByFlagAndList) {
  // 16 x 16 receivers on the floor: rx.exr's lie on the occluder's edges and corners, where a
  // box of any shape centred on them sees the same fraction of it.
  write_receivers("rx16.exr", 16);
  const std::string common =
      "soft --light-extent 1 --shadow-map " + path("a.exr") + " --receivers " + path("rx16.exr") + " -q";
  for (const std::string method : {"pcss", "cssm --lookup sat", "cssm --lookup mips", "ssmm", "ssmm-improved"}) {
    SCOPED_TRACE(method);
    const auto visibility = [&](const std::string& size) {
      const RunResult r =
          run_cli(common + " --method " + method + " --light-size " + size + " -o " + path("v.exr"), dir_);
      EXPECT_EQ(r.exit_code, 0) << r.err;
      return io::load_depth_map(path("v.exr"), {});
    };
    const HostImage wide = visibility("0.4,0.1"), tall = visibility("0.1,0.4"), square = visibility("0.2");
    ASSERT_EQ(wide.data.size(), 256u);
    double differ = 0;
    size_t partial = 0;
    for (int y = 0; y < 16; ++y)
      for (int x = 0; x < 16; ++x) {
        EXPECT_NEAR(wide.at(x, y), tall.at(y, x), 1e-5f) << x << "," << y;
        differ = std::max(differ, double(std::abs(wide.at(x, y) - square.at(x, y))));
        partial += wide.at(x, y) > 0.02f && wide.at(x, y) < 0.98f;
      }
    EXPECT_GT(differ, 0.05) << "a 0.4 x 0.1 light must not shade as the 0.2 square";
    EXPECT_GT(partial, 4u) << "the receivers must cross a penumbra";
  }
  ASSERT_EQ(run_cli(common + " --method pcss --light-size 0.4,0.1 -o " + path("flag.exr"), dir_).exit_code, 0);
  write("rect.txt", "a.exr rx16.exr size=0.4,0.1\n");
  ASSERT_EQ(run_cli(common.substr(0, common.find(" --shadow-map")) + " --method pcss --lights " + path("rect.txt") +
                        " -q -o " + path("list.exr"),
                    dir_)
                .exit_code,
            0);
  const HostImage flag = io::load_depth_map(path("flag.exr"), {}), list = io::load_depth_map(path("list.exr"), {});
  ASSERT_EQ(flag.data.size(), list.data.size());
  for (size_t i = 0; i < flag.data.size(); ++i) EXPECT_EQ(flag.data[i], list.data[i]) << i;
  for (const std::string bad : {"0.4,0.1,0.2", "0.4,-0.1", "0.4,nan", "0.4,x", "0.4,", "-1", "1e39"})
    expect_refusal(common + " --method pcss --light-size " + bad,
                   "--light-size: must be a finite number >= 0 (L) or two (W,H), got '" + bad + "'");
  // A second --light-size is an error, not the rectangle's other side.
  expect_refusal(common + " --method pcss --light-size 0.4 --light-size 0.1", "--light-size");
}

// --cssm-storage: cssm's basis in f16 or unorm16 (mips) gives float32's visibility within their
// rounding; unorm8, the SAT with a narrow basis and unknown names are one-line input errors.
TEST_F(SoftCli, CssmStorageByName) {
  const std::string common = "soft --method cssm --light-extent 1 --light-size 0.2 --shadow-map " + path("a.exr") +
                             " --receivers " + path("rx.exr") + " -q";
  ASSERT_EQ(run_cli(common + " --lookup mips -o " + path("f32.exr"), dir_).exit_code, 0);
  const HostImage f32 = io::load_depth_map(path("f32.exr"), {});
  size_t partial = 0;
  for (float v : f32.data) partial += v > 0.02f && v < 0.98f;
  EXPECT_GT(partial, 4u) << "the receivers must cross a penumbra";
  for (const std::string st : {"f16", "unorm16"}) {
    const RunResult r = run_cli(common + " --lookup mips --cssm-storage " + st + " -o " + path(st + ".exr"), dir_);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const HostImage got = io::load_depth_map(path(st + ".exr"), {});
    ASSERT_EQ(got.data.size(), f32.data.size());
    for (size_t i = 0; i < got.data.size(); ++i) EXPECT_NEAR(got.data[i], f32.data[i], 2e-3f) << st << " " << i;
  }
  const auto refused = [&](const std::string& args, const std::string& expect) {
    expect_refusal(common + " " + args, expect);
  };
  refused("--lookup mips --cssm-storage unorm8", "--cssm-storage unorm8 is refused");
  refused("--lookup sat --cssm-storage f16", "--cssm-storage f16 needs --lookup mips");
  refused("--lookup mips --cssm-storage f64", "--cssm-storage: unknown storage 'f64'");
}

// --auto's output is the chosen configuration's and meets the bound. The reference is pcss's own
// output, so pcss meets a bound of 1e-6 and the written image must too (whichever configuration
// ties with it); on planar receivers (--receiver-depth) as on a receiver image.
TEST_F(SoftCli, AutoMeetsTheBoundAgainstItsReference) {
  const std::string light = " --light-extent 1 --light-size 0.2 --shadow-map " + path("a.exr");
  HostImage plane(32, 32, 1, 0.8f);
  io::write_image(path("plane.exr"), plane);
  for (const std::string& receivers : {" --receivers " + path("rx.exr"), " --receiver-depth " + path("plane.exr")}) {
    ASSERT_EQ(run_cli("soft --method pcss -q" + light + receivers + " -o " + path("ref.exr"), dir_).exit_code, 0);
    const RunResult r = run_cli("soft --auto --reference " + path("ref.exr") +
                                    " --max-error 1e-6 --auto-grid quick --auto-runs 1 --auto-rounds 2" + light +
                                    receivers + " -o " + path("auto.exr"),
                                dir_);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("auto: chose "), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("auto:   tried pcss"), std::string::npos) << r.out;
    const HostImage ref = io::load_depth_map(path("ref.exr"), {}), got = io::load_depth_map(path("auto.exr"), {});
    ASSERT_EQ(got.data.size(), ref.data.size());
    size_t partial = 0;
    for (size_t i = 0; i < got.data.size(); ++i) {
      EXPECT_NEAR(got.data[i], ref.data[i], 1e-6f) << i;
      partial += ref.data[i] > 0.02f && ref.data[i] < 0.98f;
    }
    EXPECT_GT(partial, 4u) << "the receivers must cross a penumbra" << receivers;
  }
}

// On a bundled scene against its ray-traced soft reference: the JSON summary names the choice
// and its error, and the written image has that error over the receivers inside the map that
// face the light (the receivers' ndl > 0), within the bound.
TEST_F(SoftCli, AutoOnABundledSceneMeetsItsRayTracedReference) {
  const std::string scene = data_path("spheres");
  const RunResult r = run_cli(
      "soft --auto --json --auto-grid quick --auto-runs 1 --auto-rounds 1 --max-error 0.05 "
      "--reference " +
          scene + "/reference_soft.exr --shadow-map " + scene + "/shadowmap.exr --receivers " + scene +
          "/receivers.exr -o " + path("auto.exr"),
      dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  ASSERT_TRUE(j.contains("auto")) << r.out;
  EXPECT_EQ(j["auto"]["metric"], "rmse");
  const double reported = j["auto"]["error"];
  EXPECT_LE(reported, 0.05);
  EXPECT_EQ(j["auto"]["tried"], 5);
  const HostImage got = io::load_depth_map(path("auto.exr"), {});
  const HostImage ref = io::load_depth_map(scene + "/reference_soft.exr", {});
  const Receivers rx = io::load_receiver_image(scene + "/receivers.exr");
  ASSERT_EQ(got.data.size(), rx.count());
  ASSERT_TRUE(rx.has_ndl);
  double sum = 0;
  size_t n = 0;
  for (size_t i = 0; i < rx.count(); ++i) {
    if (!std::isfinite(rx.d[i]) || !(rx.u[i] >= 0 && rx.u[i] <= 1 && rx.v[i] >= 0 && rx.v[i] <= 1)) continue;
    if (rx.ndl[i] <= 0.0f) continue;
    const double e = double(got.data[i]) - ref.data[i];
    sum += e * e;
    ++n;
  }
  ASSERT_GT(n, 10000u);
  EXPECT_NEAR(std::sqrt(sum / n), reported, 1e-6);
}

// What --auto cannot measure, or would override, is a one-line input error with no output.
TEST_F(SoftCli, AutoRefusals) {
  const std::string in =
      "soft --light-extent 1 --light-size 0.2 --shadow-map " + path("a.exr") + " --receivers " + path("rx.exr");
  ASSERT_EQ(run_cli("soft --method pcss -q" + in.substr(4) + " -o " + path("ref.exr"), dir_).exit_code, 0);
  HostImage wide(8, 8, 1, 2.0f), half(8, 8, 1, 0.5f);
  io::write_image(path("wide.exr"), wide);
  io::write_image(path("half.exr"), half);
  const std::string ref = " --reference " + path("ref.exr");
  expect_refusal(in + " --auto", "--auto needs --reference FILE");
  expect_refusal(in + ref, "--reference is the target of --auto");
  expect_refusal(in + ref + " --auto --method cssm", "--method excludes --auto");
  expect_refusal(in + ref + " --auto --auto-methods pcss,esm", "'esm' is a method of filter");
  expect_refusal(in + ref + " --auto --auto-grid huge", "huge");
  expect_refusal(in + " --auto --reference " + path("a.exr"), "the receivers need one channel of 8x8");
  expect_refusal(in + " --auto --reference " + path("rx.exr"), "has 4 channels");
  expect_refusal(in + " --auto --reference " + path("wide.exr"), "not a visibility in [0, 1]");
  expect_refusal(in + " --auto --reference " + path("missing.exr"), "missing.exr");
  // No configuration reaches a flat 0.5 exactly: the closest is named.
  expect_refusal(in + " --auto --auto-grid quick --auto-runs 1 --max-error 0 --reference " + path("half.exr"),
                 "no soft configuration meets rmse <= 0");
  write("lights.txt", "a.exr rx.exr\n");
  expect_refusal("soft --light-extent 1 --light-size 0.2 --auto" + ref + " --lights " + path("lights.txt"),
                 "--auto measures one light's map");
  write("frames.txt", "a.exr rx.exr out1.exr\n");
  const RunResult batch =
      run_cli(in.substr(0, in.find(" --shadow-map")) + " --auto" + ref + " --frames " + path("frames.txt"), dir_);
  EXPECT_EQ(batch.exit_code, 2) << batch.err;
  EXPECT_NE(batch.err.find("--auto measures one input"), std::string::npos) << batch.err;
  EXPECT_FALSE(fs::exists(path("out1.exr")));
  const RunResult same = run_cli(in + " --auto" + ref + " -o " + path("ref.exr"), dir_);
  EXPECT_EQ(same.exit_code, 2) << same.err;
  EXPECT_TRUE(fs::exists(path("ref.exr")));
}

// --normal-offset (normal_offset.hpp) in `soft` and `filter`: receivers carrying nx ny nz are
// looked up T texels along them, exactly as the same receivers moved by hand; an offset out of
// range, or normals beside a d the file does not store as normalized depth, is a one-line refusal.
TEST_F(SoftCli, NormalOffsetMovesTheLookupsOfBothCommands) {
  // 8 x 8 receivers on the floor whose normals step one texel along +u and -0.001 in d per
  // texel: moved by 2 texels each receiver's u grows by 2/32, and the column at u = 5/16 (texel
  // 9.5, left of the occluder's edge at texel 10) crosses into its shadow.
  const int n = 8;
  HostImage rx(n, n, 8), moved(n, n, 8);
  rx.channel_names = moved.channel_names = {"u", "v", "d", "f", "ndl", "nx", "ny", "nz"};
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const float u = (x + 0.5f) / n, v = (y + 0.5f) / n;
      const float values[8] = {u, v, 0.8f, 1.0f, 0.5f, 1.0f, 0.0f, -0.001f};
      for (int c = 0; c < 8; ++c) rx.at(x, y, c) = moved.at(x, y, c) = values[c];
      moved.at(x, y, 0) = u + 2.0f * 1.0f / 32.0f;
      moved.at(x, y, 2) = 0.8f + 2.0f * -0.001f;
    }
  io::write_image(path("rx8.exr"), rx);
  io::write_image(path("moved.exr"), moved);
  for (const char* command_text : {kPcss, "filter --method sm "}) {
    const std::string command = command_text;
    SCOPED_TRACE(command);
    const std::string map = " --shadow-map " + path("a.exr") + " -q";
    auto visibility = [&](const std::string& rx_file, const std::string& offset, const std::string& out) {
      const RunResult r = run_cli(
          command + map + " --receivers " + path(rx_file) + " --normal-offset " + offset + " -o " + path(out), dir_);
      EXPECT_EQ(r.exit_code, 0) << r.err;
      return io::load_depth_map(path(out), {}).data;
    };
    const std::vector<float> offset = visibility("rx8.exr", "2", "offset.exr");
    EXPECT_EQ(offset, visibility("moved.exr", "0", "by_hand.exr"));
    EXPECT_NE(offset, visibility("rx8.exr", "0", "plain.exr")) << "the move must cross the occluder's edge";
    expect_refusal(command + map + " --receivers " + path("rx8.exr") + " --normal-offset 9", "--normal-offset");
    expect_refusal(command + map + " --receivers " + path("rx8.exr") + " --receiver-encoding reversed-linear",
                   "nx ny nz need d stored as normalized linear depth");
  }
}

}  // namespace
}  // namespace sf::test
