// The one writer (host/io/output_file.hpp, host/src/runtime/atomic_file.hpp): outputs appear whole or not
// at all, a failed write names the file and the reason and leaves the earlier file, and no output
// replaces an input, whatever path names it; every command goes through it.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "atomic_file.hpp"
#include "cli_runner.hpp"
#include "image_io.hpp"
#include "output_file.hpp"
#include "sf_test_env.hpp"

namespace sf::test {
namespace {

namespace fs = std::filesystem;

std::string read_all(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

void write_all(const std::string& path, const std::string& text) { std::ofstream(path, std::ios::binary) << text; }

class OutputFile : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = temp_dir(std::string("output_file_") + ::testing::UnitTest::GetInstance()->current_test_info()->name());
  }
  std::string path(const std::string& name) const { return dir_ + "/" + name; }
  std::vector<std::string> names() const {
    std::vector<std::string> out;
    for (const auto& e : fs::directory_iterator(dir_)) out.push_back(e.path().filename().string());
    std::sort(out.begin(), out.end());
    return out;
  }
  std::string dir_;
};

// The file size limit (RLIMIT_FSIZE) stands in for a full disk: writes past it fail with EFBIG
// the way they fail with ENOSPC (test_fault_injection.cpp fills a real tmpfs through the CLI).
class FileSizeLimit {
 public:
  explicit FileSizeLimit(rlim_t bytes) {
    ::getrlimit(RLIMIT_FSIZE, &saved_);
    previous_ = std::signal(SIGXFSZ, SIG_IGN);
    rlimit limit = saved_;
    limit.rlim_cur = bytes;
    ::setrlimit(RLIMIT_FSIZE, &limit);
  }
  ~FileSizeLimit() {
    ::setrlimit(RLIMIT_FSIZE, &saved_);
    std::signal(SIGXFSZ, previous_);
  }

 private:
  rlimit saved_{};
  void (*previous_)(int) = nullptr;
};

TEST_F(OutputFile, AFailedWriteNamesTheFileAndKeepsTheEarlierOne) {
  write_all(path("out.exr"), "the earlier output");
  const HostImage big = random_depth(256, 256, 11);  // noise: no format compresses it under the limit
  for (const char* name : {"out.exr", "out.png", "out.pfm", "out.tif"}) {
    if (std::string(name) != "out.exr") write_all(path(name), "the earlier output");
    FileSizeLimit limit(4096);
    try {
      io::write_image(path(name), big);
      ADD_FAILURE() << name << " was written past the file size limit";
    } catch (const InputError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(name), std::string::npos) << what;
      EXPECT_NE(what.find("File too large"), std::string::npos) << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
  }
  for (const char* name : {"out.exr", "out.png", "out.pfm", "out.tif"})
    EXPECT_EQ(read_all(path(name)), "the earlier output") << name;
  EXPECT_EQ(names(), (std::vector<std::string>{"out.exr", "out.pfm", "out.png", "out.tif"}))
      << "a temporary file was left behind";
}

TEST_F(OutputFile, EveryFormatIsWrittenWholeAndReadsBack) {
  HostImage img(37, 23, 1);
  for (size_t i = 0; i < img.data.size(); ++i) img.data[i] = float(i) / float(img.data.size());
  for (const char* name : {"a.exr", "a.tif", "a.pfm", "a.png"}) {
    io::write_image(path(name), img);
    const HostImage back = io::load_depth_map(path(name), {});
    ASSERT_EQ(back.width, 37) << name;
    ASSERT_EQ(back.height, 23) << name;
    const float tolerance = std::string(name) == "a.png" ? 1.0f / 65535 : 0.0f;
    for (size_t i = 0; i < img.data.size(); ++i) ASSERT_NEAR(back.data[i], img.data[i], tolerance) << name << " " << i;
  }
}

TEST_F(OutputFile, AnOutputSetAppearsWholeOrNotAtAll) {
  const std::string a = "first", b = "second";
  {
    io::OutputSet set;
    set.add(path("a.txt"), "test file", a.data(), a.size());
    EXPECT_THROW(set.add(path("missing/b.txt"), "test file", b.data(), b.size()), InputError);
  }  // never committed: nothing appears
  EXPECT_TRUE(names().empty());
  io::OutputSet set;
  set.add(path("a.txt"), "test file", a.data(), a.size());
  set.add(path("b.txt"), "test file", b.data(), b.size());
  EXPECT_THROW(set.add(path("a.txt"), "test file", b.data(), b.size()), InputError);  // one file twice
  set.commit();
  EXPECT_EQ(read_all(path("a.txt")), a);
  EXPECT_EQ(read_all(path("b.txt")), b);
  EXPECT_EQ(names(), (std::vector<std::string>{"a.txt", "b.txt"}));
}

TEST_F(OutputFile, DirectoriesAndDevicesAreNeverReplaced) {
  fs::create_directory(path("dir.exr"));
  const std::string text = "x";
  try {
    io::write_file(path("dir.exr"), "output image", text.data(), text.size());
    ADD_FAILURE() << "a directory was replaced";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("is a directory"), std::string::npos) << e.what();
  }
  try {
    io::write_file("/dev/null", "output image", text.data(), text.size());
    ADD_FAILURE() << "/dev/null was replaced";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("not a regular file"), std::string::npos) << e.what();
  }
  struct stat st {};
  ASSERT_EQ(::stat("/dev/null", &st), 0);
  EXPECT_TRUE(S_ISCHR(st.st_mode));
}

TEST_F(OutputFile, ASymbolicLinkKeepsPointingAtTheFileItNames) {
  write_all(path("target.txt"), "old");
  fs::create_symlink("target.txt", path("link.txt"));
  io::write_text(path("link.txt"), "test file", "new");
  EXPECT_TRUE(fs::is_symlink(path("link.txt")));
  EXPECT_EQ(read_all(path("target.txt")), "new");
}

TEST_F(OutputFile, NoOutputIsAnInputWhateverPathNamesIt) {
  write_all(path("in.exr"), "input");
  fs::create_directory(path("real"));
  write_all(path("real/in2.exr"), "input 2");
  fs::create_directory_symlink("real", path("linked"));
  fs::create_symlink("in.exr", path("symlink.exr"));
  fs::create_hard_link(path("in.exr"), path("hardlink.exr"));
  const std::vector<std::string> inputs{path("in.exr"), path("real/in2.exr")};
  for (const std::string& out : {path("in.exr"), path("symlink.exr"), path("hardlink.exr"), path("linked/in2.exr"),
                                 path("real/../in.exr"), dir_ + "/./real/in2.exr"}) {
    try {
      io::check_outputs({out}, inputs);
      ADD_FAILURE() << out << " passed as an output";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("refusing to overwrite an input"), std::string::npos) << e.what();
    }
  }
  // Two outputs that are one file, before either exists.
  EXPECT_THROW(io::check_outputs({path("new.exr"), path("linked/../new.exr")}, inputs), InputError);
  EXPECT_NO_THROW(io::check_outputs({path("new.exr"), path("new.png")}, inputs));
}

TEST_F(OutputFile, TheWriterRefusesAFileThisProcessRead) {
  HostImage img(4, 4, 1, 0.5f);
  io::write_image(path("read.exr"), img);
  fs::create_symlink("read.exr", path("alias.exr"));
  (void)io::load_depth_map(path("read.exr"), {});  // the guard is off: not recorded
  io::write_image(path("read.exr"), img);          // a library user may rewrite what it read
  io::guard_inputs_read(true);                     // as the CLI runs
  (void)io::load_depth_map(path("read.exr"), {});
  const std::string before = read_all(path("read.exr"));
  for (const std::string& out : {path("read.exr"), path("alias.exr")})
    EXPECT_THROW(io::write_image(out, HostImage(4, 4, 1, 0.25f)), InputError) << out;
  io::guard_inputs_read(false);
  EXPECT_EQ(read_all(path("read.exr")), before);
  EXPECT_NO_THROW(io::write_image(path("read.exr"), img));
}

TEST_F(OutputFile, UnfinishedFilesAreListedUntilTheyAreInPlace) {
  const std::string text(1000, 'x');
  {
    sf::detail::StagedFile staged(path("a.bin"), text.data(), text.size());
    EXPECT_TRUE(fs::exists(staged.temporary()));
    EXPECT_FALSE(fs::exists(path("a.bin")));
    staged.commit();
  }
  EXPECT_EQ(names(), std::vector<std::string>{"a.bin"});
  {
    sf::detail::StagedFile staged(path("b.bin"), text.data(), text.size());
    io::mark_unfinished_directory(path("partial"));
    fs::create_directories(path("partial/frame_000"));
    write_all(path("partial/frame_000/x.exr"), "x");
    // What an interrupted process removes: the staged file and the partial directory.
    EXPECT_EQ(sf::detail::remove_unfinished_files(sf::detail::AfterRemoval::Continuing), 2u);
  }
  EXPECT_EQ(names(), std::vector<std::string>{"a.bin"});
}

// Through the CLI: every command that writes refuses an output that is one of its inputs, before
// it reads or computes anything, and leaves the input as it was.
class OutputOverInput : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ =
        temp_dir(std::string("output_over_input_") + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    io::write_image(path("map.exr"), random_depth(32, 32, 7, 0.3f, 0.9f));
    HostImage rx(8, 6, 4);
    rx.channel_names = {"u", "v", "d", "f"};
    for (int y = 0; y < 6; ++y)
      for (int x = 0; x < 8; ++x) {
        rx.at(x, y, 0) = (x + 0.5f) / 8;
        rx.at(x, y, 1) = (y + 0.5f) / 6;
        rx.at(x, y, 2) = 0.8f;
        rx.at(x, y, 3) = 1.0f;
      }
    io::write_image(path("rx.exr"), rx);
    io::write_image(path("rd.exr"), HostImage(32, 32, 1, 0.8f));
    write_all(path("lights.txt"), "map.exr rx.exr\n");
    write_all(path("mesh.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 2 4\nf 1 3 4\nf 2 3 4\n");
    write_all(path("frames.txt"), "map.exr rx.exr frames.txt\n");
  }
  std::string path(const std::string& name) const { return dir_ + "/" + name; }
  void expect_refused(const std::string& args, const std::string& input) {
    const std::string before = read_all(path(input));
    const RunResult r = run_cli(args, dir_);
    EXPECT_EQ(r.exit_code, 2) << args << "\n" << r.err;
    EXPECT_EQ(count_lines(r.err), 1u) << r.err;
    EXPECT_NE(r.err.find("refusing to overwrite an input"), std::string::npos) << r.err;
    EXPECT_EQ(read_all(path(input)), before) << input << " changed";
  }
  std::string dir_;
};

TEST_F(OutputOverInput, EveryCommandRefusesIt) {
  const std::string soft = "soft --method pcss --light-extent 1 --light-size 0.1 -q ";
  expect_refused(soft + "--shadow-map " + path("map.exr") + " --receivers " + path("rx.exr") + " -o " + path("rx.exr"),
                 "rx.exr");
  expect_refused(
      soft + "--shadow-map " + path("map.exr") + " --receiver-depth " + path("rd.exr") + " -o " + path("rd.exr"),
      "rd.exr");
  expect_refused(soft + "--lights " + path("lights.txt") + " -o " + path("lights.txt"), "lights.txt");
  expect_refused("filter --frames " + path("frames.txt") + " -q", "frames.txt");
  expect_refused("coherent build " + path("mesh.obj") + " -o " + path("mesh.obj") + " --views 4x4 --res 16 -q",
                 "mesh.obj");
  expect_refused(
      "filter --shadow-map " + path("map.exr") + " --receivers " + path("rx.exr") + " -o " + path("map.exr") + " -q",
      "map.exr");
}

TEST_F(OutputOverInput, RenderRefusesItsEnvironmentMap) {
  ASSERT_EQ(run_cli("coherent build box -o " + path("box.csm") + " --views 4x4 --res 16 -q", dir_).exit_code, 0);
  ASSERT_EQ(run_cli("coherent sky -o " + path("sky.exr") + " --width 16 --height 8", dir_).exit_code, 0);
  expect_refused("coherent render " + path("box.csm") + " --envmap " + path("sky.exr") + " -o " + path("sky.exr") +
                     " --width 8 --height 8 --samples 1 -q",
                 "sky.exr");
  expect_refused("coherent render " + path("box.csm") + " --envmap " + path("sky.exr") + " -o " + path("box.csm") +
                     " --width 8 --height 8 --samples 1 -q",
                 "box.csm");
}

TEST_F(OutputOverInput, TwoOutputsOfOneRunAreRefused) {
  const RunResult r = run_cli("filter --shadow-map " + path("map.exr") + " --receivers " + path("rx.exr") + " -o " +
                                  path("same.exr") + " --flags-out " + path("same.exr") + " -q",
                              dir_);
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("named twice"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(path("same.exr")));
}

}  // namespace
}  // namespace sf::test
