// Inputs are read within bounds: only regular files, declared sizes checked against the memory
// budget and the file's size before anything is allocated, list lines and counts bounded,
// non-finite mesh vertices and odd environment maps refused. Each refusal is one line naming the
// role and the path.
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <initializer_list>
#include <limits>
#include <new>
#include <sstream>
#include <string>
#include <vector>

#include "cli_runner.hpp"
#include "expect_input_error.hpp"
#include "coherent_file.hpp"
#include "envmap.hpp"
#include "frame_list.hpp"
#include "image_io.hpp"
#include "input_file.hpp"
#include "light_list.hpp"
#include "list_lines.hpp"
#include "mesh_file.hpp"
#include "sf_test_env.hpp"

namespace sf::test {
namespace {

namespace fs = std::filesystem;

// Sets (or, with nullptr, removes) an environment variable for one scope.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const char* value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old, had_ = true;
    value ? ::setenv(name, value, 1) : ::unsetenv(name);
  }
  ~ScopedEnv() { had_ ? ::setenv(name_.c_str(), old_.c_str(), 1) : ::unsetenv(name_.c_str()); }
  ScopedEnv(const ScopedEnv&) = delete;
  ScopedEnv& operator=(const ScopedEnv&) = delete;

 private:
  std::string name_, old_;
  bool had_ = false;
};

void write_bytes(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary | std::ios::trunc).write(bytes.data(), std::streamsize(bytes.size()));
}

std::string read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

class InputBounds : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = temp_dir(std::string("input_bounds_") + ::testing::UnitTest::GetInstance()->current_test_info()->name());
  }
  std::string path(const std::string& name) const { return dir_ + "/" + name; }
  std::string dir_;
};

// The command must exit 2 with one line on stderr holding `expect`.
void expect_cli_refusal(const std::string& args, const std::string& dir, const std::string& expect,
                        const std::string& env = "") {
  const RunResult r = run_cli(args, dir, env);
  EXPECT_EQ(r.exit_code, 2) << args << "\n" << r.err;
  EXPECT_EQ(count_lines(r.err), 1u) << r.err;
  EXPECT_NE(r.err.find(expect), std::string::npos) << r.err;
}

// --- only regular files ----------------------------------------------------------------------

struct Reader {
  const char* role;
  std::function<void(const std::string&)> read;
};

std::vector<Reader> every_reader() {
  return {
      {"shadow map", [](const std::string& p) { io::load_depth_map(p, {}); }},
      {"receiver image", [](const std::string& p) { io::load_receiver_image(p); }},
      {"coherent shadow map", [](const std::string& p) { io::read_coherent(p); }},
      {"frame list", [](const std::string& p) { cli::read_frame_list(p); }},
      {"light list", [](const std::string& p) { cli::read_light_list(p); }},
      {"environment map", [](const std::string& p) { scene::load_envmap(p); }},
      {"mesh", [](const std::string& p) { scene::read_mesh_file(p); }},
  };
}

TEST_F(InputBounds, EveryReaderRefusesWhatIsNotARegularFile) {
  ASSERT_EQ(::mkfifo(path("fifo").c_str(), 0600), 0) << std::strerror(errno);
  fs::create_symlink("loop_b", path("loop_a"));
  fs::create_symlink("loop_a", path("loop_b"));
  fs::create_directories(path("folder"));
  const std::vector<std::pair<std::string, std::string>> cases = {
      {path("absent"), "file not found"},
      {path("folder"), "is a directory"},
      {path("fifo"), "is a FIFO (named pipe)"},
      {path("loop_a"), "too many levels of symbolic links"},
      {"/dev/zero", "is a character device"},
      {path("folder") + "/../absent/x", "file not found"},
      {"", "no file named"},
  };
  for (const Reader& reader : every_reader())
    for (const auto& [file, problem] : cases) {
      SCOPED_TRACE(std::string(reader.role) + " " + file);
      const auto start = std::chrono::steady_clock::now();
      expect_input_error([&] { reader.read(file); }, {std::string(reader.role) + " '" + file + "': " + problem});
      // A FIFO with no writer would block an open() for reading: the type is known before.
      EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(5));
    }
}

// The refusal of `read` as the user running the test, or, for root (who reads any file), in a
// child process that has become the unprivileged user 65534 (nobody).
std::string refusal_without_root(const std::function<void()>& read) {
  const auto message = [&]() -> std::string {
    try {
      read();
    } catch (const InputError& e) {
      return e.what();
    }
    return "no refusal";
  };
  if (::geteuid() != 0) return message();
  int fds[2];
  if (::pipe(fds) != 0) return "no pipe";
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::close(fds[0]);
    const std::string text = ::setgid(65534) == 0 && ::setuid(65534) == 0 ? message() : "cannot drop root";
    const ssize_t written = ::write(fds[1], text.data(), text.size());
    ::_exit(written == ssize_t(text.size()) ? 0 : 1);
  }
  ::close(fds[1]);
  std::string text;
  char buffer[512];
  for (ssize_t n; (n = ::read(fds[0], buffer, sizeof buffer)) > 0;) text.append(buffer, size_t(n));
  ::close(fds[0]);
  int status = 0;
  ::waitpid(pid, &status, 0);
  return text;
}

TEST_F(InputBounds, UnreadableFileIsPermissionDenied) {
  write_bytes(path("locked.exr"), "x");
  fs::permissions(path("locked.exr"), fs::perms::none);
  EXPECT_EQ(refusal_without_root([&] { io::load_depth_map(path("locked.exr"), {}); }),
            "shadow map '" + path("locked.exr") + "': permission denied");
}

TEST_F(InputBounds, RegularFileCheckReturnsTheSize) {
  write_bytes(path("seven"), "1234567");
  EXPECT_EQ(io::require_regular_file(path("seven"), "thing"), 7u);
  fs::create_symlink("seven", path("link"));  // a link to a regular file is that file
  EXPECT_EQ(io::require_regular_file(path("link"), "thing"), 7u);
}

// --- the memory budget -----------------------------------------------------------------------

TEST(ImageMemoryBudget, IsAQuarterOfPhysicalMemoryUnlessSet) {
  {
    const ScopedEnv unset(io::kImageBudgetVariable, nullptr);
    const uint64_t memory = uint64_t(::sysconf(_SC_PHYS_PAGES)) * uint64_t(::sysconf(_SC_PAGESIZE));
    EXPECT_EQ(io::image_memory_budget(), memory / 4);
  }
  {
    const ScopedEnv set(io::kImageBudgetVariable, "123456789");
    EXPECT_EQ(io::image_memory_budget(), 123456789u);
  }
  for (const char* bad : {"", "0", "-5", "+5", "1e9", "12 GB", "99999999999999999999999"}) {
    SCOPED_TRACE(bad);
    const ScopedEnv set(io::kImageBudgetVariable, bad);
    expect_input_error([] { io::image_memory_budget(); },
                       {std::string(io::kImageBudgetVariable) + "='" + bad + "' is not a positive whole number"});
  }
}

TEST(ImageMemoryBudget, OutOfMemoryNamesTheFile) {
  expect_input_error(
      [] { io::with_out_of_memory_named("big.exr", "shadow map", []() -> int { throw std::bad_alloc(); }); },
      {"shadow map 'big.exr': out of memory while reading it"});
  EXPECT_EQ(io::with_out_of_memory_named("a", "b", [] { return 42; }), 42);
}

// --- declared image sizes ---------------------------------------------------------------------

// The PFM: 4 KB claiming 2^32 + 1 by 2 (OIIO reads the width as 2^31 - 1, 3 channels).
std::string huge_pfm() { return "PF\n4294967297 2\n-1\n" + std::string(4000, '\0'); }

TEST_F(InputBounds, HugePfmIsRefusedByTheBudgetAndByItsSize) {
  write_bytes(path("huge.pfm"), huge_pfm());
  {
    const ScopedEnv budget(io::kImageBudgetVariable, "1073741824");
    expect_input_error([&] { io::load_depth_map(path("huge.pfm"), {}); },
                       {"shadow map '" + path("huge.pfm") + "'", "2147483647x2 image of 3 channels",
                        "takes 51539607528 bytes as float, over the memory budget of 1073741824 bytes",
                        "set by SHADOWFILTER_MAX_IMAGE_BYTES"});
  }
  const ScopedEnv budget(io::kImageBudgetVariable, "4611686018427387904");  // 2^62: only the size speaks
  expect_input_error([&] { io::load_depth_map(path("huge.pfm"), {}); },
                     {"truncated or corrupt", "needs at least 51539607528 bytes as pnm, the file holds 4019"});
}

// A scanline zip EXR of one half channel whose header claims 65536 x 65536 with a complete
// offset table (4096 chunks of 16 lines) pointing at the one chunk of the 16 x 16 original.
std::string huge_zip_exr(const std::string& scratch) {
  OIIO::ImageSpec spec(16, 16, 1, OIIO::TypeDesc::HALF);
  spec.attribute("compression", "zip");
  auto out = OIIO::ImageOutput::create(scratch);
  std::vector<float> pixels(256, 0.5f);
  EXPECT_TRUE(out && out->open(scratch, spec) && out->write_image(OIIO::TypeDesc::FLOAT, pixels.data()) &&
              out->close());
  const std::string small = read_bytes(scratch);
  size_t header_end = 0;  // the single offset entry: the chunk right after it
  for (size_t p = 8; p + 8 <= small.size() && header_end == 0; ++p) {
    uint64_t entry = 0;
    std::memcpy(&entry, small.data() + p, 8);
    if (small[p - 1] == '\0' && entry == p + 8) header_end = p;
  }
  EXPECT_GT(header_end, 0u);
  std::string header = small.substr(0, header_end);
  for (const std::string name : {"dataWindow", "displayWindow"}) {
    const size_t at = header.find(name + std::string("\0box2i\0", 7));
    EXPECT_NE(at, std::string::npos);
    const int32_t box[4] = {0, 0, 65535, 65535};
    header.replace(at + name.size() + 7 + 4, 16, reinterpret_cast<const char*>(box), 16);
  }
  const uint64_t chunk_at = header.size() + 8 * 4096;
  std::string table;
  for (int i = 0; i < 4096; ++i) table.append(reinterpret_cast<const char*>(&chunk_at), 8);
  return header + table + small.substr(header_end + 8);
}

TEST_F(InputBounds, HugeExrHeaderIsRefusedBeforeAllocating) {
  const std::string exr = huge_zip_exr(path("small.exr"));
  write_bytes(path("huge.exr"), exr);
  {
    const ScopedEnv budget(io::kImageBudgetVariable, "1073741824");
    expect_input_error([&] { io::load_depth_map(path("huge.exr"), {}); },
                       {"65536x65536 image of 1 channel takes 17179869184 bytes as float, over the memory budget"});
  }
  // 65536^2 half pixels are 8 GiB; zip shrinks by 1032 at most.
  const ScopedEnv budget(io::kImageBudgetVariable, "4611686018427387904");
  const auto start = std::chrono::steady_clock::now();
  expect_input_error([&] { io::load_receiver_image(path("huge.exr")); },
                     {"receiver image",
                      "needs at least 8323580 bytes as openexr (zip), the file holds " + std::to_string(exr.size())});
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(5));
}

// Sizes a header states and its reader allocates before it reads: a PNG chunk's length (libpng
// allocates a text chunk's declared length) and an OpenEXR attribute of a fixed-size type whose
// declared size differs from the type's (OpenEXR reads the value whole and goes on out of step,
// then allocates the string size it misreads). Both took 1.9 GB and a second before they were
// checked (found by the fuzzer).
TEST_F(InputBounds, DeclaredSizesThatReadersAllocateAreChecked) {
  OIIO::ImageSpec spec(8, 8, 1, OIIO::TypeDesc::UINT16);
  std::vector<uint16_t> pixels(64, 30000);
  for (const char* name : {"p.png", "e.exr"}) {
    auto out = OIIO::ImageOutput::create(path(name));
    ASSERT_TRUE(out && out->open(path(name), spec) && out->write_image(OIIO::TypeDesc::UINT16, pixels.data()) &&
                out->close());
  }
  std::string png = read_bytes(path("p.png"));
  const size_t after_ihdr = 8 + 12 + 13;  // signature, IHDR (length, type, 13 bytes, CRC)
  png = png.substr(0, after_ihdr) + std::string("\x6e\x00\x00\x75tEXtSoftware", 16) + std::string(20, 'x');
  write_bytes(path("text.png"), png);
  const auto start = std::chrono::steady_clock::now();
  expect_input_error([&] { io::load_depth_map(path("text.png"), {}); },
                     {"shadow map '" + path("text.png") + "'", "PNG chunk 'tEXt' declares 1845493877 bytes"});

  std::string exr = read_bytes(path("e.exr"));
  const std::string key("pixelAspectRatio\0float\0\x04\0\0\0", 27);
  const size_t at = exr.find(key);
  ASSERT_NE(at, std::string::npos);
  exr[at + 23] = '\0';  // declares 0 bytes
  write_bytes(path("float0.exr"), exr);
  expect_input_error([&] { io::load_depth_map(path("float0.exr"), {}); },
                     {"attribute 'pixelAspectRatio' of type float declares 0 bytes, the type has 4"});
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(5));
  EXPECT_NO_THROW(io::load_depth_map(path("p.png"), {}));  // the files as written still read
  EXPECT_NO_THROW(io::load_depth_map(path("e.exr"), {}));
}

TEST_F(InputBounds, HugeHdrHeadersAreRefused) {
  const std::string header = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n";
  write_bytes(path("flat.hdr"), header + "-Y 100000 +X 100000\n" + std::string(4000, '\x01'));
  write_bytes(path("rle.hdr"), header + "-Y 1000 +X 1000\n" + std::string(4000, '\x01'));
  {
    const ScopedEnv budget(io::kImageBudgetVariable, "1073741824");
    expect_input_error([&] { io::load_depth_map(path("flat.hdr"), {}); },
                       {"100000x100000 image of 3 channels takes 120000000000 bytes as float"});
  }
  const ScopedEnv budget(io::kImageBudgetVariable, "4611686018427387904");
  // Widths over 32767 are flat (4 bytes a pixel); run-length scanlines hold at least 4 bytes and
  // 4 runs of 2 bytes per 127 pixels: 1000 x (4 + 8 x 8).
  expect_input_error([&] { io::load_depth_map(path("flat.hdr"), {}); }, {"needs at least 40000000000 bytes as hdr"});
  expect_input_error([&] { io::load_depth_map(path("rle.hdr"), {}); }, {"needs at least 68000 bytes as hdr"});
}

TEST_F(InputBounds, UncompressedTiffIsCheckedAgainstItsSize) {
  OIIO::ImageSpec spec(64, 64, 1, OIIO::TypeDesc::FLOAT);
  spec.attribute("compression", "none");
  auto out = OIIO::ImageOutput::create(path("t.tif"));
  std::vector<float> pixels(64 * 64, 0.25f);
  ASSERT_TRUE(out && out->open(path("t.tif"), spec) && out->write_image(OIIO::TypeDesc::FLOAT, pixels.data()) &&
              out->close());
  EXPECT_EQ(io::load_depth_map(path("t.tif"), {}).data[100], 0.25f);
  fs::resize_file(path("t.tif"), 8000);
  expect_input_error([&] { io::load_depth_map(path("t.tif"), {}); },
                     {"truncated or corrupt", "needs at least 16384 bytes as tiff (none), the file holds 8000"});
}

// --- the .csm file ----------------------------------------------------------------------------

uint32_t crc32(const std::string& bytes) {
  uint32_t crc = 0xffffffffu;
  for (unsigned char b : bytes) {
    crc ^= b;
    for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xedb88320u & (0u - (crc & 1u)));
  }
  return ~crc;
}

TEST_F(InputBounds, CsmSegmentCountThatOverflowsIsTruncation) {
  io::CoherentFile file;
  file.stack.layout.resolution = 1;
  file.stack.layout.views_theta = 1;
  file.stack.layout.views_phi = 1;
  file.stack.offsets = {0, 1};
  file.stack.last = {0};
  file.stack.depth = {0};
  io::write_coherent(path("one.csm"), file);
  std::string bytes = read_bytes(path("one.csm"));
  ASSERT_EQ(io::read_coherent(path("one.csm")).stack.segment_count(), 1u);
  // The count at byte 68 (magic 8, version 4, six u32, centre and radius), plus 2^63: 4 bytes
  // (a 16-bit index and a depth) x count wraps to the true size in 64 bits, and a fresh CRC makes
  // the file otherwise valid.
  const uint64_t count = 1 + (uint64_t(1) << 63);
  std::memcpy(&bytes[68], &count, 8);
  const uint32_t crc = crc32(bytes.substr(0, bytes.size() - 4));
  std::memcpy(&bytes[bytes.size() - 4], &crc, 4);
  write_bytes(path("overflow.csm"), bytes);
  expect_input_error([&] { io::read_coherent(path("overflow.csm")); },
                     {"coherent shadow map '" + path("overflow.csm") + "'", "truncated",
                      "announces 9223372036854775809 segments for 1 texels"});
}

// --- lists ------------------------------------------------------------------------------------

std::vector<cli::LightListEntry> lights_of(const std::string& text) {
  std::istringstream in(text);
  return cli::parse_light_list(in, "lists/lights.txt");
}

TEST(LightList, ParsesFilesWeightsAndSizes) {
  const auto lights = lights_of("a.exr rx.exr weight=2.5 size=0.125  # key light\n\n# fill\nb.exr /abs/rx.exr\n");
  ASSERT_EQ(lights.size(), 2u);
  EXPECT_EQ(lights[0].where, "lists/lights.txt:1");
  EXPECT_EQ(lights[0].shadow_map, "lists/a.exr");
  EXPECT_EQ(lights[0].receivers, "lists/rx.exr");
  EXPECT_EQ(lights[0].weight, 2.5);
  EXPECT_EQ(lights[0].size, 0.125);
  EXPECT_EQ(lights[1].where, "lists/lights.txt:4");
  EXPECT_EQ(lights[1].receivers, "/abs/rx.exr");
  EXPECT_EQ(lights[1].weight, 1.0);
  EXPECT_TRUE(std::isnan(lights[1].size));
}

TEST(LightList, RectangularSizes) {
  const auto lights = lights_of("a.exr rx.exr size=0.4,0.125\nb.exr rx.exr size=0.2\n");
  ASSERT_EQ(lights.size(), 2u);
  EXPECT_EQ(lights[0].size, 0.4);
  EXPECT_EQ(lights[0].height, 0.125);
  EXPECT_EQ(lights[1].size, 0.2);
  EXPECT_LT(lights[1].height, 0.0) << "size=L is a square";
  for (const std::string item : {"size=0.4,", "size=0.4,x", "size=0.4,0.1,0.2", "size=0.4,-1", "size=0.4,nan"}) {
    SCOPED_TRACE(item);
    expect_input_error([&] { lights_of("a.exr rx.exr " + item + "\n"); },
                       {"lists/lights.txt:1: " + item + " is not two numbers >= 0 that a float holds"});
  }
  expect_input_error([] { lights_of("a.exr rx.exr size=,0.1\n"); }, {"size=,0.1 is not a number >= 0"});
}

TEST(LightList, RefusesValuesThatAreNotFiniteFloats) {
  for (const std::string item : {"weight=1e39", "weight=nan", "weight=inf", "weight=-1", "size=1e39", "size=-0.5",
                                 "weight=heavy", "weight=", "weight=1x"}) {
    SCOPED_TRACE(item);
    expect_input_error([&] { lights_of("a.exr rx.exr " + item + "\n"); },
                       {"lists/lights.txt:1: " + item + " is not a number >= 0 that a float holds"});
  }
  expect_input_error([] { lights_of("a.exr rx.exr weight=1 weight=2\n"); }, {"lights.txt:1: weight is given twice"});
  expect_input_error([] { lights_of("a.exr rx.exr colour=red\n"); }, {"lights.txt:1: unknown 'colour=red'"});
  expect_input_error([] { lights_of("\na.exr\n"); }, {"lights.txt:2: expected SHADOWMAP RECEIVERS"});
  expect_input_error([] { lights_of("# none\n"); }, {"the light list 'lists/lights.txt' holds no light"});
}

TEST(LightList, LinesAndLightsAreBounded) {
  std::string many;
  for (size_t i = 0; i <= cli::kMaxLights; ++i) many += "a.exr rx.exr\n";
  EXPECT_EQ(lights_of(many.substr(0, many.size() - 13)).size(), cli::kMaxLights);
  expect_input_error([&] { lights_of(many); }, {"lights.txt:257: more than 256 lights; a list holds at most 256"});
  expect_input_error([] { lights_of("a.exr rx.exr\n" + std::string(cli::kMaxListLineBytes + 1, 'x') + "\n"); },
                     {"lights.txt:2: a line longer than 65536 bytes"});
  expect_input_error([] { lights_of(std::string("a.exr\0b rx.exr\n", 15)); }, {"lights.txt:1: a NUL byte"});
}

std::vector<cli::FrameSpec> frames_of(const std::string& text) {
  std::istringstream in(text);
  return cli::parse_frame_list(in, "lists/frames.txt");
}

TEST(FrameList, LinesAndFramesAreBounded) {
  std::string many;
  for (size_t i = 0; i <= cli::kMaxFrames; ++i) many += "m.exr r.exr o.exr\n";
  const std::string one_line_less = many.substr(0, many.size() - 18);
  EXPECT_EQ(frames_of(one_line_less).size(), cli::kMaxFrames);
  expect_input_error([&] { frames_of(many); }, {"frames.txt:100001: more than 100000 frames"});
  const std::string longest(cli::kMaxListLineBytes - 12, 'm');  // exactly the bound with " r.exr o.exr"
  EXPECT_EQ(frames_of(longest + " r.exr o.exr\n").at(0).shadow_map, "lists/" + longest);
  expect_input_error([&] { frames_of("m.exr r.exr o.exr\n" + longest + "x r.exr o.exr\n"); },
                     {"frames.txt:2: a line longer than 65536 bytes"});
  expect_input_error([] { frames_of(std::string("m.exr r.exr o\0.exr\n", 19)); }, {"frames.txt:1: a NUL byte"});
}

// --- meshes and environment maps ---------------------------------------------------------------

TEST_F(InputBounds, MeshWithNonFiniteVerticesIsRefused) {
  // Binary STL: 80-byte header, a count, then per triangle a normal, 3 vertices and 2 bytes.
  auto stl = [](float y) {
    const float t[12] = {0, 0, 1, 0, 0, 0, 1, 0, 0, 0, y, 1};
    const uint32_t count = 1;
    std::string bytes(80, '\0');
    bytes.append(reinterpret_cast<const char*>(&count), 4);
    bytes.append(reinterpret_cast<const char*>(t), sizeof t);
    return bytes + std::string(2, '\0');
  };
  write_bytes(path("nan.stl"), stl(std::numeric_limits<float>::quiet_NaN()));
  write_bytes(path("ok.stl"), stl(1.0f));
  write_bytes(path("inf.obj"), "v 0 0 0\nv 1 0 0\nv 0 inf 1\nf 1 2 3\n");
  write_bytes(path("nan.ply"),
              "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
              "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\nnan 0 1\n3 0 1 2\n");
  EXPECT_EQ(scene::read_mesh_file(path("ok.stl")).triangles.size(), 1u);
  expect_input_error([&] { scene::read_mesh_file(path("nan.stl")); },
                     {"mesh '" + path("nan.stl") + "': vertex 2 of mesh 0 is not finite (0, nan, 1)"});
  expect_input_error([&] { scene::read_mesh_file(path("inf.obj")); }, {"vertex 2 of mesh 0 is not finite (0, inf, 1)"});
  expect_input_error([&] { scene::read_mesh_file(path("nan.ply")); }, {"vertex 2 of mesh 0 is not finite (nan, 0, 1)"});
  write_bytes(path("junk.ply"), "ply\nformat binary_little_endian 1.0\nelement vertex 99999999\nend_header\n");
  expect_input_error([&] { scene::read_mesh_file(path("junk.ply")); }, {"mesh '" + path("junk.ply") + "': "});
}

// Inputs the fuzz harnesses found (tests/fuzz/regressions): assimp 5.2 loops for ever on PLY
// headers it does not expect (no end_header, a character before it), aborts (an ai_assert in its
// triangulation) on faces without indices and crashes on a damaged OFF file; OpenEXR allocates a
// string attribute of the size the header states.
std::string regression(const std::string& harness, const std::string& name) {
  return std::string(SF_FUZZ_DIR) + "/regressions/" + harness + "/" + name;
}

TEST(FuzzRegressions, MeshesThatHungOrAbortedAssimpAreRefused) {
  const auto start = std::chrono::steady_clock::now();
  const std::string hang = regression("mesh", "ply_header_without_end_header.ply");
  expect_input_error([&] { scene::read_mesh_file(hang); },
                     {"mesh '" + hang + "': PLY header line 7: unexpected 'elemev 0nt face 4'"});
  expect_input_error([&] { scene::read_mesh_file(regression("mesh", "ply_end_header_after_a_bracket.ply")); },
                     {"PLY header line 9: unexpected '[end_header'"});
  expect_input_error([&] { scene::read_mesh_file(regression("mesh", "ply_faces_without_indices.ply")); },
                     {"PLY header line 6: expected 'property TYPE NAME' or 'property list TYPE TYPE NAME', found "
                      "'property floa????"});
  expect_input_error([&] { scene::read_mesh_file(regression("mesh", "ply_face_of_zero_vertices.ply")); },
                     {"face 0 of mesh 0 has no vertices"});
  // assimp's OFF importer dereferences a face it never filled: the crash stays in the child.
  const std::string off = regression("mesh", "off_that_crashes_assimp.off");
  expect_input_error([&] { scene::read_mesh_file(off); },
                     {"mesh '" + off + "': assimp crashed reading it (Segmentation fault)"});
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(5));
}

TEST(PlyHeader, TheGrammarIsChecked) {
  const std::string dir = temp_dir("ply_header");
  const std::string start = "ply\nformat ascii 1.0\n";
  const std::string tail =
      "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  const auto header = [&](const std::string& text) {
    write_bytes(dir + "/m.ply", text);
    return dir + "/m.ply";
  };
  EXPECT_EQ(scene::read_mesh_file(header(start + "comment made by hand\r\n" + tail)).triangles.size(), 1u);
  expect_input_error([&] { scene::read_mesh_file(header("plx\n" + tail)); }, {"line 1: expected 'ply'"});
  expect_input_error([&] { scene::read_mesh_file(header("ply\nformat text 1.0\n" + tail)); },
                     {"line 2: expected 'format ascii|binary_little_endian|binary_big_endian VERSION'"});
  expect_input_error([&] { scene::read_mesh_file(header(start + "property float x\n" + tail)); },
                     {"line 3: a property before any element"});
  expect_input_error([&] { scene::read_mesh_file(header(start + "element vertex -3\n" + tail)); },
                     {"line 3: expected 'element NAME COUNT'"});
  expect_input_error([&] { scene::read_mesh_file(header(start + "\n" + tail)); }, {"line 3: an empty line"});
  expect_input_error([&] { scene::read_mesh_file(header(start + " comment\n" + tail)); }, {"line 3: blanks before"});
  expect_input_error([&] { scene::read_mesh_file(header(start + "element vertex 3\nproperty quad x\n")); },
                     {"line 4: expected 'property TYPE NAME'"});
  expect_input_error([&] { scene::read_mesh_file(header(start + "element vertex 3\nend_header now\n")); },
                     {"line 4: expected 'end_header' alone"});
  expect_input_error([&] { scene::read_mesh_file(header(start + "element vertex 3\n")); },
                     {"line 4: no end_header within the first 1048576 bytes"});
}

TEST(FuzzRegressions, ExrAttributeLargerThanTheFileIsRefusedBeforeOpenExrReadsIt) {
  const std::string exr = regression("image", "exr_attribute_of_1886220163_bytes.exr");
  expect_input_error([&] { io::load_depth_map(exr, {}); },
                     {"shadow map '" + exr +
                      "': truncated or corrupt: header attribute 'Exif:ImaSoftware' declares "
                      "1886220163 bytes, the file holds 740 after it"});
}

TEST_F(InputBounds, SoftReadsTheLightFromACheckedHeader) {
  // soft reads the map's header for its light before its pixels: the same checks come first.
  const std::string exr = regression("image", "exr_attribute_of_1886220163_bytes.exr");
  expect_cli_refusal("soft --method pcss --shadow-map " + exr + " --receiver-depth " + exr + " -o " + path("o.exr"),
                     dir_, "declares 1886220163 bytes");
  expect_cli_refusal("soft --method pcss --shadow-map /dev/zero --receiver-depth " + exr + " -o " + path("o.exr"), dir_,
                     "shadow map '/dev/zero': is a character device");
}

TEST_F(InputBounds, EnvironmentMapChannelsAreOneThreeOrFour) {
  for (int channels : {1, 2, 3, 4, 5, 6}) {
    SCOPED_TRACE(channels);
    const std::string file = path("env" + std::to_string(channels) + ".exr");
    io::write_image(file, HostImage(8, 4, channels, 0.5f));
    if (channels == 1 || channels == 3 || channels == 4) {
      EXPECT_EQ(scene::load_envmap(file).texel(2, 1)[2], 0.5f);
    } else {
      expect_input_error([&] { scene::load_envmap(file); },
                         {"environment map '" + file + "': has " + std::to_string(channels) +
                          " channels; needs 1 (grey), 3 (RGB) or 4 (RGBA)"});
    }
  }
}

// --- the command line: exit 2, one line --------------------------------------------------------

TEST_F(InputBounds, CliRefusesNonFilesHugeHeadersAndBadLists) {
  io::write_image(path("map.exr"), HostImage(8, 8, 1, 0.5f));
  expect_cli_refusal("filter --shadow-map /dev/zero --receiver-depth " + path("map.exr") + " -o " + path("o.exr"), dir_,
                     "shadow map '/dev/zero': is a character device, not a regular file");
  expect_cli_refusal("filter --frames /dev/zero", dir_, "frame list '/dev/zero': is a character device");
  expect_cli_refusal("filter --shadow-map " + path("map.exr") + " --receiver-depth " + dir_ + " -o " + path("o.exr"),
                     dir_, "receiver depth '" + dir_ + "': is a directory");
  write_bytes(path("huge.pfm"), huge_pfm());
  expect_cli_refusal(
      "filter --shadow-map " + path("huge.pfm") + " --receiver-depth " + path("map.exr") + " -o " + path("o.exr"), dir_,
      "over the memory budget of 1000000 bytes (set by SHADOWFILTER_MAX_IMAGE_BYTES)",
      "SHADOWFILTER_MAX_IMAGE_BYTES=1000000");
  write_bytes(path("lights.txt"), "map.exr map.exr weight=1e39\n");
  expect_cli_refusal("soft --method pcss --lights " + path("lights.txt") + " -o " + path("o.exr"), dir_,
                     "lights.txt:1: weight=1e39 is not a number >= 0 that a float holds");
  write_bytes(path("nan.obj"), "v 0 0 0\nv 1 0 0\nv 0 nan 1\nf 1 2 3\n");
  expect_cli_refusal("scene " + path("nan.obj") + " -o " + path("scene"), dir_,
                     "vertex 2 of mesh 0 is not finite (0, nan, 1)");
  EXPECT_FALSE(fs::exists(path("o.exr")));
  EXPECT_FALSE(fs::exists(path("scene")));
}

TEST_F(InputBounds, CliNamesANonFiniteLightSizeInTheHeader) {
  HostImage map(8, 8, 1, 0.5f);
  map.attributes = {{"light_type", "ortho"}, {"ortho_extents", "[0, 2, 0, 2]"}, {"light_size", "nan"}};
  io::write_image(path("map.exr"), map);
  const std::string run = "soft --method pcss --shadow-map " + path("map.exr") + " --receiver-depth " +
                          path("map.exr") + " -o " + path("o.exr");
  expect_cli_refusal(run, dir_,
                     "shadow map '" + path("map.exr") +
                         "': header light_size='nan' is not a finite number; give "
                         "--light-size");
  map.attributes["light_size"] = "0.1";
  map.attributes["ortho_extents"] = "[0, 2, nan, 2]";
  io::write_image(path("map.exr"), map);
  expect_cli_refusal(run, dir_, "header ortho_extents='[0, 2, nan, 2]' is not four finite numbers");
  // A rectangle's height must be a side: negative would read as "square".
  map.attributes["ortho_extents"] = "[0, 2, 0, 2]";
  for (const char* bad : {"-0.5", "nan"}) {
    map.attributes["light_height"] = bad;
    io::write_image(path("map.exr"), map);
    expect_cli_refusal(run, dir_, std::string("header light_height='") + bad + "' is not");
  }
  map.attributes.erase("light_height");
  map.attributes.erase("light_size");
  io::write_image(path("map.exr"), map);
  expect_cli_refusal(run, dir_, "has no light_size attribute: give --light-size");
}

}  // namespace
}  // namespace sf::test
