// Image I/O layer: format round trips, depth encodings, receivers, error messages, atomic writes.
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <initializer_list>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "expect_input_error.hpp"
#include "image_io.hpp"

namespace fs = std::filesystem;
using sf::HostImage;
using sf::InputError;
using sf::Receivers;
using sf::io::DepthEncoding;
using sf::io::DepthLoadOptions;
using sf::io::NonFinitePolicy;
using sf::test::expect_input_error;

namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

// A per-test scratch directory under SF_TEST_TMP, emptied before and removed after the test.
class ImageIoTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::path(SF_TEST_TMP) / "io" /
           (std::string(info->test_suite_name()) + "." + info->name() + "." + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ignored;
    fs::remove_all(dir_, ignored);
  }
  std::string file(const std::string& name) const { return (dir_ / name).string(); }
  std::vector<std::string> files_in_dir() const {
    std::vector<std::string> names;
    for (const auto& entry : fs::directory_iterator(dir_)) names.push_back(entry.path().filename().string());
    return names;
  }

  fs::path dir_;
};

// Depth-like test pattern in [0,1], different in every texel and not symmetric in x/y.
HostImage ramp(int w, int h, int channels = 1) {
  HostImage img(w, h, channels);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < channels; ++c) img.at(x, y, c) = static_cast<float>((x + 3 * y + 7 * c) % 17) / 16.0f;
  return img;
}

HostImage constant_image(int w, int h, int channels, float value) { return HostImage(w, h, channels, value); }

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void write_text(const std::string& path, const std::string& text) { std::ofstream(path, std::ios::binary) << text; }

void expect_same_depth(const HostImage& expected, const HostImage& actual, float tolerance) {
  ASSERT_EQ(actual.width, expected.width);
  ASSERT_EQ(actual.height, expected.height);
  ASSERT_EQ(actual.channels, 1);
  for (int y = 0; y < expected.height; ++y)
    for (int x = 0; x < expected.width; ++x)
      ASSERT_NEAR(actual.at(x, y), expected.at(x, y), tolerance) << "at " << x << "," << y;
}

DepthLoadOptions encoded(DepthEncoding encoding, double near_plane, double far_plane) {
  DepthLoadOptions opt;
  opt.encoding = encoding;
  opt.near_plane = near_plane;
  opt.far_plane = far_plane;
  return opt;
}

OIIO::ImageSpec read_spec(const std::string& path) {
  auto input = OIIO::ImageInput::open(path);
  EXPECT_TRUE(input) << OIIO::geterror();
  return input ? input->spec() : OIIO::ImageSpec();
}

// Writes an image with OIIO directly (formats or channel layouts write_image doesn't produce).
void write_with_oiio(const std::string& path, const HostImage& img, OIIO::TypeDesc type,
                     const std::vector<std::string>& channel_names = {}) {
  OIIO::ImageSpec spec(img.width, img.height, img.channels, type);
  if (!channel_names.empty()) spec.channelnames = channel_names;
  auto output = OIIO::ImageOutput::create(path);
  ASSERT_TRUE(output) << OIIO::geterror();
  ASSERT_TRUE(output->open(path, spec)) << output->geterror();
  ASSERT_TRUE(output->write_image(OIIO::TypeDesc::FLOAT, img.data.data())) << output->geterror();
  ASSERT_TRUE(output->close()) << output->geterror();
}

// --- round trips ---------------------------------------------------------------------------

TEST_F(ImageIoTest, FloatFormatsRoundTripExactly) {
  const HostImage depth = ramp(13, 7);
  for (const std::string name : {"d.exr", "d.tif", "d.tiff", "d.pfm", "D.EXR"}) {
    SCOPED_TRACE(name);
    sf::io::write_image(file(name), depth);
    expect_same_depth(depth, sf::io::load_depth_map(file(name), {}), 0.0f);
  }
}

TEST_F(ImageIoTest, PngRoundTripsWithin16BitQuantisation) {
  const HostImage depth = ramp(13, 7);
  sf::io::write_image(file("d.png"), depth);
  EXPECT_EQ(read_spec(file("d.png")).format, OIIO::TypeDesc::UINT16);
  expect_same_depth(depth, sf::io::load_depth_map(file("d.png"), {}), 1.0f / 65535.0f);
}

TEST_F(ImageIoTest, PngWriteClampsToUnitRange) {
  HostImage img(4, 1);
  img.data = {-0.5f, 1.5f, kNaN, 0.25f};
  sf::io::write_image(file("c.png"), img);
  const HostImage back = sf::io::load_depth_map(file("c.png"), {});
  EXPECT_EQ(back.data[0], 0.0f);
  EXPECT_EQ(back.data[1], 1.0f);
  EXPECT_EQ(back.data[2], 0.0f);
  EXPECT_NEAR(back.data[3], 0.25f, 1.0f / 65535.0f);
}

TEST_F(ImageIoTest, FourChannelFloatImagesRoundTripThroughReceivers) {
  HostImage img = ramp(5, 4, 4);
  img.at(2, 1, 3) = 0.0f;  // a zero "alpha" must not premultiply or unpremultiply anything
  for (const std::string name : {"r.exr", "r.tif"}) {
    SCOPED_TRACE(name);
    sf::io::write_image(file(name), img);
    const Receivers rec = sf::io::load_receiver_image(file(name));
    ASSERT_EQ(rec.count(), img.texels());
    for (size_t t = 0; t < rec.count(); ++t) {
      EXPECT_EQ(rec.u[t], img.data[4 * t + 0]);
      EXPECT_EQ(rec.v[t], img.data[4 * t + 1]);
      EXPECT_EQ(rec.d[t], img.data[4 * t + 2]);
      EXPECT_EQ(rec.f[t], img.data[4 * t + 3]);
    }
  }
}

TEST_F(ImageIoTest, PfmStoresRowsBottomUpAndThreeChannels) {
  HostImage img = ramp(3, 2, 3);
  sf::io::write_image(file("r.pfm"), img);
  const std::string bytes = read_text(file("r.pfm"));
  EXPECT_EQ(bytes.rfind("PF\n3 2\n", 0), 0u);
  // The last image row comes first in the file.
  const size_t header = bytes.size() - img.data.size() * sizeof(float);
  float first_in_file = 0.0f;
  std::memcpy(&first_in_file, bytes.data() + header, sizeof(float));
  EXPECT_EQ(first_in_file, img.at(0, 1, 0));
  const Receivers rec = sf::io::load_receiver_image(file("r.pfm"));
  EXPECT_EQ(rec.u[4], img.at(1, 1, 0));
  EXPECT_EQ(rec.d[4], img.at(1, 1, 2));
}

TEST_F(ImageIoTest, ExrHonoursHalfChannelsNamesAndAttributes) {
  HostImage img = ramp(4, 3, 2);
  img.at(0, 0, 0) = 0.1f;
  img.channel_names = {"mean", "mask"};
  img.channel_formats = {"float", "half"};
  img.attributes = {{"shadowfilter:near", "0.5"}, {"shadowfilter:method", "esm"}};
  sf::io::write_image(file("m.exr"), img);

  const OIIO::ImageSpec spec = read_spec(file("m.exr"));
  ASSERT_EQ(spec.nchannels, 2);
  // OpenEXR sorts channels by name on disk.
  const int mean = spec.channelindex("mean");
  const int mask = spec.channelindex("mask");
  ASSERT_GE(mean, 0);
  ASSERT_GE(mask, 0);
  EXPECT_EQ(spec.channelformat(mean), OIIO::TypeDesc::FLOAT);
  EXPECT_EQ(spec.channelformat(mask), OIIO::TypeDesc::HALF);
  EXPECT_EQ(spec.get_string_attribute("shadowfilter:near"), "0.5");
  EXPECT_EQ(spec.get_string_attribute("shadowfilter:method"), "esm");
  EXPECT_EQ(spec.get_string_attribute("compression"), "zip");
}

TEST_F(ImageIoTest, AllHalfExrIsHalfOnDisk) {
  HostImage img = constant_image(2, 2, 1, 0.1f);
  img.channel_formats = {"half"};
  sf::io::write_image(file("h.exr"), img);
  EXPECT_EQ(read_spec(file("h.exr")).format, OIIO::TypeDesc::HALF);
  const HostImage back = sf::io::load_depth_map(file("h.exr"), {});
  EXPECT_NE(back.data[0], 0.1f);
  EXPECT_NEAR(back.data[0], 0.1f, 1e-4f);
}

TEST_F(ImageIoTest, UnknownChannelFormatIsRejected) {
  HostImage img = constant_image(2, 2, 1, 0.1f);
  img.channel_formats = {"int8"};
  expect_input_error([&] { sf::io::write_image(file("h.exr"), img); }, {"int8", "half"});
  EXPECT_TRUE(files_in_dir().empty());
}

// --- depth encodings -------------------------------------------------------------------------

TEST(ImageIoEncodingTest, ParsesNamesAndRejectsUnknownOnes) {
  EXPECT_EQ(sf::io::parse_depth_encoding("linear"), DepthEncoding::Linear);
  EXPECT_EQ(sf::io::parse_depth_encoding("perspective"), DepthEncoding::Perspective);
  EXPECT_EQ(sf::io::parse_depth_encoding("perspective-ndc"), DepthEncoding::PerspectiveNdc);
  EXPECT_EQ(sf::io::parse_depth_encoding("reversed"), DepthEncoding::Reversed);
  EXPECT_EQ(sf::io::parse_depth_encoding("reversed-infinite"), DepthEncoding::ReversedInfinite);
  EXPECT_EQ(sf::io::parse_depth_encoding("reversed-linear"), DepthEncoding::ReversedLinear);
  expect_input_error([] { sf::io::parse_depth_encoding("log"); }, {"log", "linear", "perspective", "reversed"});
}

// linearize_depth decodes without clamping: the loaders check the range instead (below).
TEST(ImageIoEncodingTest, LinearIsTheStoredValueOrWorldUnits) {
  const DepthLoadOptions opt;
  EXPECT_EQ(sf::io::linearize_depth(0.25, opt), 0.25);
  EXPECT_EQ(sf::io::linearize_depth(1.5, opt), 1.5);
  EXPECT_NEAR(sf::io::linearize_depth(7.0, encoded(DepthEncoding::Linear, 4.0, 16.0)), 0.25, 1e-15);
  EXPECT_NEAR(sf::io::linearize_depth(0.25, encoded(DepthEncoding::ReversedLinear, NAN, NAN)), 0.75, 1e-15);
}

// N = 1, F = 3: z_view = 2 is linear depth 0.5; hardware depth F(z_view - N)/(z_view(F - N)) =
// 3/4, reversed-Z N(F - z_view)/(z_view(F - N)) = 1/4.
TEST(ImageIoEncodingTest, PerspectiveMatchesHandComputedValues) {
  const DepthLoadOptions opt = encoded(DepthEncoding::Perspective, 1.0, 3.0);
  EXPECT_NEAR(sf::io::linearize_depth(0.0, opt), 0.0, 1e-12);
  EXPECT_NEAR(sf::io::linearize_depth(1.0, opt), 1.0, 1e-12);
  EXPECT_NEAR(sf::io::linearize_depth(0.75, opt), 0.5, 1e-12);
  // N = 0.5, F = 10, z = 0.5: z_view = 5 / 5.25 = 20/21, linear = (20/21 - 1/2) / 9.5 = 1/21.
  EXPECT_NEAR(sf::io::linearize_depth(0.5, encoded(DepthEncoding::Perspective, 0.5, 10.0)), 1.0 / 21.0, 1e-12);
  // OpenGL NDC z: window depth 0.75 is NDC 0.5.
  EXPECT_NEAR(sf::io::linearize_depth(0.5, encoded(DepthEncoding::PerspectiveNdc, 1.0, 3.0)), 0.5, 1e-12);
}

// Reversed-Z with an infinite far plane, N = 1 and d = 1 at F = 5: z_view = N / w, so w = 1/3 is
// z_view 3, d = (3 - 1) / 4 = 1/2; w = 0 is infinitely far: nothing hit, d = 1.
TEST(ImageIoEncodingTest, ReversedInfiniteMatchesHandComputedValues) {
  const DepthLoadOptions opt = encoded(DepthEncoding::ReversedInfinite, 1.0, 5.0);
  EXPECT_NEAR(sf::io::linearize_depth(1.0, opt), 0.0, 1e-12);
  EXPECT_NEAR(sf::io::linearize_depth(1.0 / 3.0, opt), 0.5, 1e-12);
  EXPECT_NEAR(sf::io::linearize_depth(0.2, opt), 1.0, 1e-12);
  EXPECT_EQ(sf::io::linearize_depth(0.0, opt), 1.0);
}

TEST(ImageIoEncodingTest, ReversedMatchesHandComputedValues) {
  const DepthLoadOptions opt = encoded(DepthEncoding::Reversed, 1.0, 3.0);
  EXPECT_NEAR(sf::io::linearize_depth(1.0, opt), 0.0, 1e-12);  // near
  EXPECT_NEAR(sf::io::linearize_depth(0.0, opt), 1.0, 1e-12);  // far
  EXPECT_NEAR(sf::io::linearize_depth(0.25, opt), 0.5, 1e-12);
  // N = 0.5, F = 10, z_rev = 0.25: z_view = 5 / 2.875 = 40/23, linear = (40/23 - 1/2) / 9.5 = 3/23.
  EXPECT_NEAR(sf::io::linearize_depth(0.25, encoded(DepthEncoding::Reversed, 0.5, 10.0)), 3.0 / 23.0, 1e-12);
}

TEST_F(ImageIoTest, DepthMapIsDecodedWithItsEncoding) {
  HostImage stored(3, 1);
  stored.data = {0.0f, 0.75f, 1.0f};
  sf::io::write_image(file("p.exr"), stored);
  const HostImage depth = sf::io::load_depth_map(file("p.exr"), encoded(DepthEncoding::Perspective, 1.0, 3.0));
  EXPECT_NEAR(depth.data[0], 0.0f, 1e-6f);
  EXPECT_NEAR(depth.data[1], 0.5f, 1e-6f);
  EXPECT_NEAR(depth.data[2], 1.0f, 1e-6f);
}

TEST_F(ImageIoTest, InvalidPlanesAreRejected) {
  sf::io::write_image(file("p.exr"), ramp(2, 2));
  for (const auto& [near_plane, far_plane] :
       std::vector<std::pair<double, double>>{{0.0, 1.0}, {-1.0, 1.0}, {2.0, 2.0}, {3.0, 1.0}}) {
    for (DepthEncoding encoding : {DepthEncoding::Perspective, DepthEncoding::Reversed}) {
      expect_input_error([&] { sf::io::load_depth_map(file("p.exr"), encoded(encoding, near_plane, far_plane)); },
                         {"p.exr", "DepthDecoding::near_plane", "got near="});
    }
  }
  // Perspective encodings need both planes: no silent defaults.
  expect_input_error([&] { sf::io::load_depth_map(file("p.exr"), encoded(DepthEncoding::Perspective, NAN, NAN)); },
                     {"p.exr", "perspective", "needs both"});
  // Linear depth takes both planes (world units) or neither ([0, 1]).
  expect_input_error([&] { sf::io::load_depth_map(file("p.exr"), encoded(DepthEncoding::Linear, 0.0, 0.0)); },
                     {"p.exr", "near=0, far=0"});
  expect_input_error([&] { sf::io::load_depth_map(file("p.exr"), encoded(DepthEncoding::Linear, 1.0, NAN)); },
                     {"p.exr", "needs both"});
}

// Out of the encoding's range beyond rounding: refused with the range found and the fix, never
// clamped; within rounding (1e-6 of the range) clamped.
TEST_F(ImageIoTest, OutOfRangeDepthIsRefusedNotClamped) {
  HostImage stored(2, 1);
  stored.data = {-0.25f, 7.0f};
  sf::io::write_image(file("c.exr"), stored);
  expect_input_error([&] { sf::io::load_depth_map(file("c.exr"), {}); },
                     {"c.exr", "depths span [-0.25, 7]", "outside [0, 1]", "--near N --far F"});
  stored.data = {-1e-7f, 1.0000005f};
  sf::io::write_image(file("r.exr"), stored);
  const HostImage depth = sf::io::load_depth_map(file("r.exr"), {});
  EXPECT_EQ(depth.data[0], 0.0f);
  EXPECT_EQ(depth.data[1], 1.0f);
}

// --- shadow map channels ---------------------------------------------------------------------

TEST_F(ImageIoTest, ThreeIdenticalChannelsAreAccepted) {
  HostImage rgb(4, 3, 3);
  const HostImage depth = ramp(4, 3);
  for (size_t t = 0; t < depth.texels(); ++t)
    for (int c = 0; c < 3; ++c) rgb.data[3 * t + c] = depth.data[t];
  sf::io::write_image(file("rgb.exr"), rgb);
  expect_same_depth(depth, sf::io::load_depth_map(file("rgb.exr"), {}), 0.0f);
}

TEST_F(ImageIoTest, RadianceHdrGreyImageIsAccepted) {
  HostImage rgb = constant_image(4, 2, 3, 0.5f);  // 0.5 is exact in RGBE
  write_with_oiio(file("g.hdr"), rgb, OIIO::TypeDesc::FLOAT);
  const HostImage depth = sf::io::load_depth_map(file("g.hdr"), {});
  ASSERT_EQ(depth.texels(), 8u);
  EXPECT_EQ(depth.data[5], 0.5f);
}

TEST_F(ImageIoTest, ThreeDifferingChannelsAreRejected) {
  HostImage rgb = constant_image(4, 3, 3, 0.5f);
  rgb.at(2, 1, 1) = 0.25f;
  sf::io::write_image(file("rgb.exr"), rgb);
  expect_input_error([&] { sf::io::load_depth_map(file("rgb.exr"), {}); },
                     {"rgb.exr", "channel", "differ", "x=2, y=1"});
}

TEST_F(ImageIoTest, WrongDepthChannelCountIsRejected) {
  sf::io::write_image(file("two.exr"), ramp(3, 3, 2));
  expect_input_error([&] { sf::io::load_depth_map(file("two.exr"), {}); },
                     {"two.exr", "expected 1 channel", "found 2 channels"});
}

// --- non-finite depth ------------------------------------------------------------------------

TEST_F(ImageIoTest, NonFiniteDepthIsAnErrorWithCountAndFirstTexel) {
  HostImage img = ramp(5, 4);
  img.at(3, 1) = kNaN;
  img.at(0, 2) = kInf;
  img.at(4, 3) = -kInf;
  sf::io::write_image(file("nan.exr"), img);
  expect_input_error([&] { sf::io::load_depth_map(file("nan.exr"), {}); },
                     {"nan.exr", "3 non-finite", "x=3, y=1", "--nonfinite far"});
}

TEST_F(ImageIoTest, NonFiniteDepthBecomesFarOnRequest) {
  HostImage img = ramp(5, 4);
  img.at(3, 1) = kNaN;
  img.at(0, 2) = kInf;
  sf::io::write_image(file("nan.exr"), img);
  DepthLoadOptions opt = encoded(DepthEncoding::Perspective, 1.0, 3.0);
  opt.nonfinite = NonFinitePolicy::Far;
  const HostImage depth = sf::io::load_depth_map(file("nan.exr"), opt);
  EXPECT_EQ(depth.at(3, 1), 1.0f);
  EXPECT_EQ(depth.at(0, 2), 1.0f);
  EXPECT_NEAR(depth.at(1, 0), sf::io::linearize_depth(img.at(1, 0), opt), 1e-6);
}

// --- unreadable inputs -----------------------------------------------------------------------

TEST_F(ImageIoTest, MissingFileIsReported) {
  expect_input_error([&] { sf::io::load_depth_map(file("absent.exr"), {}); },
                     {"shadow map", "absent.exr", "not found"});
  expect_input_error([&] { sf::io::load_receiver_image(file("absent.exr")); },
                     {"receiver image", "absent.exr", "not found"});
  expect_input_error([&] { sf::io::load_receiver_depth(file("absent.exr"), 2, 2, {}); },
                     {"receiver depth", "absent.exr", "not found"});
}

TEST_F(ImageIoTest, NonImagesAreReported) {
  write_text(file("notes.txt"), "not an image\n");
  write_text(file("fake.exr"), "not an image either\n");
  write_text(file("empty.png"), "");
  for (const std::string name : {"notes.txt", "fake.exr", "empty.png"})
    expect_input_error([&] { sf::io::load_depth_map(file(name), {}); }, {name, "not a readable image"});
  expect_input_error([&] { sf::io::load_depth_map(dir_.string(), {}); }, {"directory"});
}

TEST_F(ImageIoTest, TruncatedFilesAreReported) {
  const HostImage depth = ramp(64, 64);
  for (const std::string name : {"t.exr", "t.png", "t.tif", "t.pfm"}) {
    SCOPED_TRACE(name);
    sf::io::write_image(file(name), depth);
    fs::resize_file(file(name), fs::file_size(file(name)) / 2);
    expect_input_error([&] { sf::io::load_depth_map(file(name), {}); }, {name, "truncated"});
  }
}

TEST_F(ImageIoTest, ZeroSizeImageIsReported) {
  write_text(file("zero.pfm"), "Pf\n0 0\n-1.0\n");
  expect_input_error([&] { sf::io::load_depth_map(file("zero.pfm"), {}); }, {"zero.pfm", "zero size"});
}

// --- receivers -------------------------------------------------------------------------------

TEST_F(ImageIoTest, ReceiverChannelsAreMatchedByName) {
  HostImage img(3, 2, 4);  // file order d, u, v, f
  for (size_t t = 0; t < img.texels(); ++t) {
    img.data[4 * t + 0] = 0.1f + 0.01f * t;  // d
    img.data[4 * t + 1] = 0.2f + 0.01f * t;  // u
    img.data[4 * t + 2] = 0.3f + 0.01f * t;  // v
    img.data[4 * t + 3] = 2.0f + t;          // f
  }
  img.channel_names = {"d", "u", "v", "f"};
  sf::io::write_image(file("rec.exr"), img);
  const Receivers rec = sf::io::load_receiver_image(file("rec.exr"));
  EXPECT_EQ(rec.width, 3);
  EXPECT_EQ(rec.height, 2);
  EXPECT_FALSE(rec.grid);
  EXPECT_TRUE(rec.has_footprint);
  for (size_t t = 0; t < img.texels(); ++t) {
    EXPECT_EQ(rec.d[t], img.data[4 * t + 0]);
    EXPECT_EQ(rec.u[t], img.data[4 * t + 1]);
    EXPECT_EQ(rec.v[t], img.data[4 * t + 2]);
    EXPECT_EQ(rec.f[t], img.data[4 * t + 3]);
  }
}

TEST_F(ImageIoTest, ThreeChannelReceiversArePositionalWithUnitFootprint) {
  HostImage img(2, 2, 3);
  img.data = {0.1f, 0.2f, 0.3f, 0.4f, 0.5f, 0.6f, 0.7f, 0.8f, 0.9f, 0.15f, 0.25f, 0.35f};
  sf::io::write_image(file("rec.tif"), img);
  const Receivers rec = sf::io::load_receiver_image(file("rec.tif"));
  EXPECT_FALSE(rec.has_footprint);
  EXPECT_EQ(rec.u, (std::vector<float>{0.1f, 0.4f, 0.7f, 0.15f}));
  EXPECT_EQ(rec.v, (std::vector<float>{0.2f, 0.5f, 0.8f, 0.25f}));
  EXPECT_EQ(rec.d, (std::vector<float>{0.3f, 0.6f, 0.9f, 0.35f}));
  EXPECT_EQ(rec.f, (std::vector<float>(4, 1.0f)));
}

TEST_F(ImageIoTest, HalfReceiversAreAccepted) {
  HostImage img = constant_image(2, 2, 3, 0.5f);
  img.channel_formats = {"half", "half", "half"};
  sf::io::write_image(file("rec.exr"), img);
  EXPECT_EQ(sf::io::load_receiver_image(file("rec.exr")).d[3], 0.5f);
}

TEST_F(ImageIoTest, OddReceiversBecomeBackgroundOrAreRefused) {
  HostImage img(5, 1, 3, 0.5f);
  img.at(0, 0, 2) = kNaN;        // d non-finite: background
  img.at(1, 0, 0) = kNaN;        // u non-finite: background
  img.at(2, 0, 1) = kInf;        // v non-finite: background
  img.at(3, 0, 2) = 1.0000004f;  // d past 1 within rounding: clamped
  img.at(4, 0, 0) = 1.5f;        // u outside [0,1] is kept (outside the frustum, handled later)
  sf::io::write_image(file("odd.exr"), img);
  const Receivers rec = sf::io::load_receiver_image(file("odd.exr"));
  EXPECT_TRUE(std::isnan(rec.d[0]));
  EXPECT_TRUE(std::isnan(rec.d[1]));
  EXPECT_TRUE(std::isnan(rec.d[2]));
  EXPECT_EQ(rec.d[3], 1.0f);
  EXPECT_EQ(rec.u[4], 1.5f);
  img.at(3, 0, 2) = 1.75f;  // beyond rounding: refused, never clamped
  sf::io::write_image(file("far.exr"), img);
  expect_input_error([&] { sf::io::load_receiver_image(file("far.exr")); },
                     {"receiver image", "far.exr", "depths span [0.5, 1.75]", "outside [0, 1]"});
  EXPECT_EQ(rec.d[4], 0.5f);
}

TEST_F(ImageIoTest, IntegerReceiverImageIsRejected) {
  sf::io::write_image(file("rec.png"), ramp(3, 3, 3));
  expect_input_error([&] { sf::io::load_receiver_image(file("rec.png")); },
                     {"receiver image", "rec.png", "uint16", "float"});
  write_with_oiio(file("rec8.png"), ramp(3, 3, 3), OIIO::TypeDesc::UINT8);
  expect_input_error([&] { sf::io::load_receiver_image(file("rec8.png")); }, {"rec8.png", "uint8", "float"});
}

TEST_F(ImageIoTest, FiveChannelReceiversCarryNdlByName) {
  HostImage img(3, 1, 5);  // file order ndl, d, u, v, f
  for (int x = 0; x < 3; ++x) {
    img.at(x, 0, 0) = 0.5f - 0.5f * x;  // ndl: 0.5, 0 (facing away), -0.5
    img.at(x, 0, 1) = 0.4f;             // d
    img.at(x, 0, 2) = 0.1f * x;         // u
    img.at(x, 0, 3) = 0.2f;             // v
    img.at(x, 0, 4) = 3.0f;             // f
  }
  img.at(2, 0, 0) = kNaN;  // ndl unknown: the receiver stays defined
  img.channel_names = {"ndl", "d", "u", "v", "f"};
  img.channel_formats = {"half", "float", "float", "float", "half"};
  sf::io::write_image(file("rec5.exr"), img);
  const Receivers rec = sf::io::load_receiver_image(file("rec5.exr"));
  EXPECT_TRUE(rec.has_footprint);
  ASSERT_TRUE(rec.has_ndl);
  ASSERT_EQ(rec.ndl.size(), 3u);
  EXPECT_EQ(rec.ndl[0], 0.5f);
  EXPECT_EQ(rec.ndl[1], 0.0f);
  EXPECT_TRUE(std::isnan(rec.ndl[2]));
  EXPECT_EQ(rec.d, (std::vector<float>(3, 0.4f)));
  EXPECT_EQ(rec.u, (std::vector<float>{0.0f, 0.1f, 0.2f}));
  EXPECT_EQ(rec.f, (std::vector<float>(3, 3.0f)));
}

TEST_F(ImageIoTest, FiveChannelReceiversArePositionalWithoutNames) {
  HostImage img(2, 1, 5);
  img.data = {0.1f, 0.2f, 0.3f, 2.0f, -0.25f, 0.4f, 0.5f, 0.6f, 4.0f, 0.75f};
  sf::io::write_image(file("rec5.tif"), img);
  const Receivers rec = sf::io::load_receiver_image(file("rec5.tif"));
  ASSERT_TRUE(rec.has_ndl);
  EXPECT_EQ(rec.u, (std::vector<float>{0.1f, 0.4f}));
  EXPECT_EQ(rec.d, (std::vector<float>{0.3f, 0.6f}));
  EXPECT_EQ(rec.f, (std::vector<float>{2.0f, 4.0f}));
  EXPECT_EQ(rec.ndl, (std::vector<float>{-0.25f, 0.75f}));
}

TEST_F(ImageIoTest, FourChannelReceiversHaveNoNdl) {
  sf::io::write_image(file("rec4.exr"), ramp(3, 2, 4));
  const Receivers rec = sf::io::load_receiver_image(file("rec4.exr"));
  EXPECT_TRUE(rec.has_footprint);
  EXPECT_FALSE(rec.has_ndl);
  EXPECT_TRUE(rec.ndl.empty());
}

TEST_F(ImageIoTest, WrongReceiverChannelCountIsRejected) {
  sf::io::write_image(file("one.exr"), ramp(3, 3, 1));
  expect_input_error([&] { sf::io::load_receiver_image(file("one.exr")); },
                     {"one.exr", "expected 3, 4, 5, 8 or 12 channels", "found 1 channel"});
  sf::io::write_image(file("two.exr"), ramp(3, 3, 2));
  expect_input_error([&] { sf::io::load_receiver_image(file("two.exr")); },
                     {"two.exr", "expected 3, 4, 5, 8 or 12 channels", "found 2 channels"});
  sf::io::write_image(file("six.exr"), ramp(3, 3, 6));
  expect_input_error([&] { sf::io::load_receiver_image(file("six.exr")); },
                     {"six.exr", "expected 3, 4, 5, 8 or 12 channels", "found 6 channels"});
}

TEST_F(ImageIoTest, ReceiverDepthIsDecodedOnTheShadowMapGrid) {
  HostImage img(3, 2);
  img.data = {0.0f, 0.75f, 1.0f, kNaN, 1.0f, -kInf};
  sf::io::write_image(file("rd.exr"), img);
  const Receivers rec = sf::io::load_receiver_depth(file("rd.exr"), 3, 2, encoded(DepthEncoding::Perspective, 1, 3));
  EXPECT_TRUE(rec.grid);
  EXPECT_FALSE(rec.has_footprint);
  EXPECT_EQ(rec.width, 3);
  EXPECT_EQ(rec.height, 2);
  EXPECT_TRUE(rec.u.empty());
  EXPECT_TRUE(rec.v.empty());
  EXPECT_TRUE(rec.f.empty());
  ASSERT_EQ(rec.d.size(), 6u);
  EXPECT_NEAR(rec.d[0], 0.0f, 1e-6f);
  EXPECT_NEAR(rec.d[1], 0.5f, 1e-6f);
  EXPECT_NEAR(rec.d[2], 1.0f, 1e-6f);
  EXPECT_TRUE(std::isnan(rec.d[3]));
  EXPECT_EQ(rec.d[4], 1.0f);
  EXPECT_TRUE(std::isnan(rec.d[5]));
}

TEST_F(ImageIoTest, ReceiverDepthSizeMustMatchTheShadowMap) {
  sf::io::write_image(file("rd.exr"), ramp(4, 3));
  expect_input_error([&] { sf::io::load_receiver_depth(file("rd.exr"), 8, 6, {}); },
                     {"receiver depth", "rd.exr", "4x3", "8x6"});
}

TEST_F(ImageIoTest, ReceiverDepthNeedsOneChannel) {
  sf::io::write_image(file("rd.exr"), ramp(4, 3, 2));
  expect_input_error([&] { sf::io::load_receiver_depth(file("rd.exr"), 4, 3, {}); },
                     {"rd.exr", "expected 1 channel", "found 2"});
}

// --- atomic writes ---------------------------------------------------------------------------

TEST_F(ImageIoTest, SuccessfulWriteLeavesOnlyTheOutput) {
  sf::io::write_image(file("out.exr"), ramp(8, 8));
  sf::io::write_image(file("out.exr"), ramp(8, 8));  // overwrite
  EXPECT_EQ(files_in_dir(), std::vector<std::string>{"out.exr"});
}

TEST_F(ImageIoTest, UnsupportedExtensionWritesNothing) {
  expect_input_error([&] { sf::io::write_image(file("out.jpg"), ramp(4, 4)); },
                     {"out.jpg", ".jpg", ".exr", ".tif", ".pfm", ".png"});
  expect_input_error([&] { sf::io::write_image(file("noext"), ramp(4, 4)); }, {"noext", ".exr"});
  EXPECT_TRUE(files_in_dir().empty());
}

TEST_F(ImageIoTest, MissingDirectoryIsNotCreated) {
  for (const std::string name : {"no/such/dir/out.exr", "no/out.pfm", "no/out.png"})
    expect_input_error([&] { sf::io::write_image(file(name), ramp(4, 4)); }, {name});
  EXPECT_TRUE(files_in_dir().empty());
}

TEST_F(ImageIoTest, FailedWriteKeepsTheExistingFile) {
  write_text(file("keep.pfm"), "old contents");
  expect_input_error([&] { sf::io::write_image(file("keep.pfm"), ramp(4, 4, 4)); }, {"keep.pfm", "PFM", "4"});
  HostImage inconsistent(4, 4);
  inconsistent.data.resize(3);
  expect_input_error([&] { sf::io::write_image(file("keep.pfm"), inconsistent); }, {"keep.pfm"});
  EXPECT_EQ(read_text(file("keep.pfm")), "old contents");
  EXPECT_EQ(files_in_dir(), std::vector<std::string>{"keep.pfm"});
}

TEST_F(ImageIoTest, FailedRenameRemovesTheTemporaryFile) {
  // The output path is an existing non-empty directory: the image is written to the temporary
  // file, then the rename fails.
  fs::create_directories(dir_ / "out.exr" / "inside");
  expect_input_error([&] { sf::io::write_image(file("out.exr"), ramp(4, 4)); }, {"out.exr"});
  EXPECT_EQ(files_in_dir(), std::vector<std::string>{"out.exr"});
  EXPECT_TRUE(fs::is_directory(dir_ / "out.exr" / "inside"));
}

}  // namespace
