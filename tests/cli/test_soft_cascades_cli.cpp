// `shadowfilter soft --cascades DIR --view VIEW` (host/cli/soft_layered.cpp; docs/cascades.md
// "Soft shadows per layer"): on a scene the generator made, the command reads the light's sides
// and plane from the layer headers and gives exactly what the library's filter_layered gives with
// that light, no further from the scene's ray-traced soft reference than the single map; --light-size and --light-plane
// override the headers; what a layered run cannot take is refused in one line with exit 2.
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <string>

#include "cascade_io.hpp"
#include "cli_runner.hpp"
#include "image_io.hpp"
#include "io_detail.hpp"
#include "sf_test_env.hpp"
#include "shadowfilter/layered.hpp"

namespace sf::test {
namespace {

namespace fs = std::filesystem;

class SoftCascadesCli : public ::testing::Test {
 protected:
  // city at 256² per layer, pssm with 2 layers, 128 x 72 view pixels, 16 light samples (about 1 s),
  // in a directory of the test's own (ctest runs the tests side by side).
  void SetUp() override {
    dir_ =
        temp_dir(std::string("soft_cascades_cli_") + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    const RunResult r = run_cli("scene city -o " + dir_ +
                                    "/city --size 256 --receivers 128x72 --samples 16 -q "
                                    "--layout pssm --cascades 2",
                                dir_);
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  std::string path(const std::string& name) const { return dir_ + "/" + name; }
  std::string in() const { return " --cascades " + path("city") + " --view " + path("city/view.exr"); }
  static std::vector<float> pixels(const std::string& file) { return io::detail::read_raw(file, "test").pixels; }
  void expect_refusal(const std::string& args, const std::string& expect) const {
    const RunResult r = run_cli("soft " + args + " -o " + path("refused.exr"), dir_);
    EXPECT_EQ(r.exit_code, 2) << args << "\n" << r.err;
    EXPECT_NE(r.err.find(expect), std::string::npos) << args << "\nstderr: " << r.err;
    EXPECT_EQ(count_lines(r.err), 1u) << r.err;
    EXPECT_FALSE(fs::exists(path("refused.exr")));
  }
  std::string dir_;
};

TEST_F(SoftCascadesCli, HeadersLightIsTheLibrarysAndMeetsTheRayTracedReference) {
  const io::detail::RawImage layer0 = io::detail::read_raw(path("city/cascade_0.exr"), "layer");
  const double size = std::stod(layer0.attributes.at("light_size"));
  const double plane = std::stod(layer0.attributes.at("light_plane"));
  const io::detail::RawImage map = io::detail::read_raw(path("city/shadowmap.exr"), "map");
  EXPECT_EQ(plane, std::stod(map.attributes.at("near"))) << "the light lies where the single map's reference has it";

  const io::LayeredMaps set = io::load_cascade_set(io::cascade_files(path("city")));
  const ViewReceivers view = io::load_view_receivers(path("city/view.exr"));
  const std::vector<float> want = pixels(path("city/reference_soft.exr"));
  ASSERT_EQ(want.size(), view.count());
  for (const char* method : {"pcss", "ssmm"}) {
    const std::string out = path(std::string(method) + ".exr");
    const RunResult r = run_cli(std::string("soft --json --method ") + method + in() + " -o " + out, dir_);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const nlohmann::json j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["light"]["size"].get<double>(), size);
    EXPECT_EQ(j["light"]["plane"].get<double>(), plane);
    EXPECT_EQ(j["layers"].get<int>(), 2);

    SoftOptions o;
    o.method = find_soft_method(method);
    o.light.size = size;
    const LayeredResult lib = filter_layered(runtime_ptr(), o, set.set, plane, set.maps, view);
    const std::vector<float> got = pixels(out);
    ASSERT_EQ(got.size(), lib.visibility.data.size());
    double sum = 0;
    size_t counted = 0, differ = 0;
    for (size_t i = 0; i < got.size(); ++i) {
      differ += !(got[i] == lib.visibility.data[i] || (std::isnan(got[i]) && std::isnan(lib.visibility.data[i])));
      if (!std::isfinite(view.depth[i]) || !(view.ndl[i] > 0.0f) || !std::isfinite(got[i])) continue;
      sum += (got[i] - want[i]) * (got[i] - want[i]);
      ++counted;
    }
    EXPECT_EQ(differ, 0u) << method << ": the command and the library differ";
    const double rmse = std::sqrt(sum / double(counted));
    // The single map of the same scene (one 256² map, half the layers' texels) over the same
    // receivers: the layers may not be worse.
    const std::string single = path(std::string(method) + "_single.exr");
    ASSERT_EQ(run_cli(std::string("soft -q --method ") + method + " --shadow-map " + path("city/shadowmap.exr") +
                          " --receivers " + path("city/receivers.exr") + " -o " + single,
                      dir_)
                  .exit_code,
              0);
    const std::vector<float> one = pixels(single);
    double sum_single = 0;
    for (size_t i = 0; i < got.size(); ++i)
      if (std::isfinite(view.depth[i]) && view.ndl[i] > 0.0f && std::isfinite(got[i]))
        sum_single += (one[i] - want[i]) * (one[i] - want[i]);
    const double rmse_single = std::sqrt(sum_single / double(counted));
    std::printf("  %s: RMSE against reference_soft.exr per layer %.4f, single map %.4f (%zu lit-facing receivers)\n",
                method, rmse, rmse_single, counted);
    EXPECT_GT(counted, 4000u);
    EXPECT_LE(rmse, rmse_single * 1.05) << method;
    EXPECT_LT(rmse, 0.2) << method;
  }
  // The command line's light replaces the header's: another size or plane, another image.
  const std::vector<float> pcss = pixels(path("pcss.exr"));
  for (const std::string& over :
       {std::string(" --light-size ") + std::to_string(size * 3), " --light-plane " + std::to_string(plane - 5000)}) {
    ASSERT_EQ(run_cli("soft -q --method pcss" + in() + over + " -o " + path("over.exr"), dir_).exit_code, 0);
    const std::vector<float> other = pixels(path("over.exr"));
    double moved = 0;
    for (size_t i = 0; i < other.size(); ++i)
      if (std::isfinite(other[i]) && std::isfinite(pcss[i])) moved += std::abs(other[i] - pcss[i]);
    EXPECT_GT(moved, 10.0) << over;
  }
}

TEST_F(SoftCascadesCli, WhatALayeredRunCannotTakeIsRefused) {
  const std::string pcss = "--method pcss" + in();
  expect_refusal(pcss + " --shadow-map " + path("city/shadowmap.exr"),
                 "--cascades cannot be combined with --shadow-map");
  expect_refusal(pcss + " --receivers " + path("city/receivers.exr"), "--receivers");
  expect_refusal(pcss + " --light-extent 3", "--light-extent");
  expect_refusal(pcss + " --encoding d3d --near 1 --far 100", "--encoding");
  expect_refusal(pcss + " --auto --reference " + path("city/reference_soft.exr"), "--auto");
  expect_refusal(pcss + " --cascade-blend 1", "--cascade-blend must lie in [0, 1)");
  expect_refusal(pcss + " --light-size 0,0,1", "--light-size");
  expect_refusal(pcss + " --light-plane 1e6", "of the view's receivers lie before the light's plane");
  expect_refusal("--method pcss --cascades " + path("city"), "--cascades needs --view");
  expect_refusal("--method pcss --view " + path("city/view.exr"), "need --cascades");
  expect_refusal("--method pcss --light-plane 3 --shadow-map " + path("city/shadowmap.exr"), "need --cascades");
  expect_refusal("--method pcss --cascades " + path("nowhere") + " --view " + path("city/view.exr"), "nowhere");
  // Layer files without the scene's light: the sides and the plane must be given.
  const io::LayeredMaps set = io::load_cascade_set(io::cascade_files(path("city")));
  fs::create_directories(path("bare"));
  for (int k = 0; k < 2; ++k) {
    const std::string file = path("bare/cascade_" + std::to_string(k) + ".exr");
    auto out = OIIO::ImageOutput::create(file);
    ASSERT_TRUE(out);
    OIIO::ImageSpec spec(set.set.width, set.set.height, 1, OIIO::TypeDesc::FLOAT);
    spec.channelnames = {"Z"};
    for (const auto& [key, value] : io::cascade_layer_attributes(set.set, k)) spec.attribute(key, value);
    ASSERT_TRUE(out->open(file, spec));
    ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, set.maps[k].data.data()));
    ASSERT_TRUE(out->close());
  }
  const std::string bare = "--method pcss --cascades " + path("bare") + " --view " + path("city/view.exr");
  expect_refusal(bare, "has no light_size attribute: give --light-size");
  expect_refusal(bare + " --light-size 4", "has no light_plane attribute: give --light-plane");
  ASSERT_EQ(run_cli("soft -q " + bare + " --light-size 4 --light-plane -2000 -o " + path("bare.exr"), dir_).exit_code,
            0);
  // The output is never an input: the view file stays as it was.
  const std::string before = slurp(path("city/view.exr"));
  const RunResult same = run_cli("soft --method pcss" + in() + " -o " + path("city/view.exr"), dir_);
  EXPECT_EQ(same.exit_code, 2) << same.err;
  EXPECT_EQ(slurp(path("city/view.exr")), before);
}

}  // namespace
}  // namespace sf::test
