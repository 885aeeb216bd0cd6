// `filter --frames LIST` and `filter --shadow-map A B ... --output-dir DIR`: a batch writes the
// same bytes as single runs of its frames; a bad frame is named by its line, stops the batch
// (or, with --keep-going, is skipped and counted in the exit code) and leaves nothing partial;
// --preview writes a PNG beside each output, or nothing when the run fails.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "cli_runner.hpp"
#include "image_io.hpp"
#include "sf_test_env.hpp"

namespace sf::test {
namespace {

namespace fs = std::filesystem;

class BatchCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = temp_dir(std::string("batch_") + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    // Maps of two sizes (the batch reallocates between them) with a block occluder each.
    for (int i = 0; i < 4; ++i) {
      const int w = i == 2 ? 40 : 24, h = i == 2 ? 12 : 16;
      HostImage depth(w, h, 1, 0.7f);
      for (int y = 3; y < 10; ++y)
        for (int x = 4 + 3 * i; x < 12 + 3 * i && x < w; ++x) depth.at(x, y) = 0.2f;
      io::write_image(path("map" + std::to_string(i) + ".exr"), depth);
    }
    io::write_image(path("rd.exr"), HostImage(24, 16, 1, 0.6f));
    HostImage rx(9, 7, 5);
    rx.channel_names = {"u", "v", "d", "f", "ndl"};
    for (int y = 0; y < 7; ++y)
      for (int x = 0; x < 9; ++x) {
        rx.at(x, y, 0) = (x + 0.5f) / 9;
        rx.at(x, y, 1) = (y + 0.5f) / 7;
        rx.at(x, y, 2) = 0.6f;
        rx.at(x, y, 3) = 2.0f;
        rx.at(x, y, 4) = x == 8 ? -1.0f : 1.0f;
      }
    io::write_image(path("rx.exr"), rx);
    fs::create_directories(path("out"));
  }
  std::string path(const std::string& name) const { return dir_ + "/" + name; }
  void write_list(const std::string& name, const std::string& text) const { std::ofstream(path(name)) << text; }
  static std::string bytes(const std::string& file) { return slurp(file); }
  std::vector<std::string> files_in(const std::string& sub) const {
    std::vector<std::string> names;
    for (auto& e : fs::directory_iterator(path(sub))) names.push_back(e.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
  }
  // The bytes a single run writes for one frame.
  std::string single_run(const std::string& map, const std::string& receivers_flag, const std::string& options) {
    const std::string out = path("single.exr");
    const RunResult r =
        run_cli("filter --shadow-map " + path(map) + " " + receivers_flag + " -o " + out + " -q " + options, dir_);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    std::string b = bytes(out);
    fs::remove(out);
    return b;
  }
  std::string dir_;
};

TEST_F(BatchCli, ListFramesEqualSingleRunsByteForByte) {
  // Paths relative to the list's directory, a comment, a blank line, a quoted field, both
  // receiver kinds, and a size change in the middle (map2 is 40 x 12).
  write_list("frames.txt",
             "# frame list\n"
             "map0.exr rx.exr out/f0.exr\n"
             "\n"
             "map1.exr depth=rd.exr out/f1.exr   # planar receivers\n"
             "map2.exr \"rx.exr\" out/f2.exr\n"
             "map3.exr rx.exr out/f3.exr\n");
  const std::string options = "--method evsm2 --blur-radius 2 --lookup mips";
  const RunResult r = run_cli("filter --frames " + path("frames.txt") + " " + options, dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(count_lines(r.out), 1u) << r.out;
  for (const char* word : {"batch of 4 frames, 4 written, 0 failed", "evsm2", "4 allocations", "frames/s"})
    EXPECT_NE(r.out.find(word), std::string::npos) << word << " missing from: " << r.out;
  EXPECT_EQ(bytes(path("out/f0.exr")), single_run("map0.exr", "--receivers " + path("rx.exr"), options));
  EXPECT_EQ(bytes(path("out/f1.exr")), single_run("map1.exr", "--receiver-depth " + path("rd.exr"), options));
  EXPECT_EQ(bytes(path("out/f2.exr")), single_run("map2.exr", "--receivers " + path("rx.exr"), options));
  EXPECT_EQ(bytes(path("out/f3.exr")), single_run("map3.exr", "--receivers " + path("rx.exr"), options));
  // The frames differ (each map moves its occluder): the comparison is not of one image.
  EXPECT_NE(bytes(path("out/f0.exr")), bytes(path("out/f3.exr")));
  const HostImage f0 = io::load_depth_map(path("out/f0.exr"), {});
  EXPECT_EQ(f0.width, 9);
  EXPECT_EQ(f0.at(8, 3), 0.0f);  // facing away
}

TEST_F(BatchCli, OutputDirFramesShareTheReceivers) {
  const RunResult r =
      run_cli("filter --shadow-map " + path("map0.exr") + " " + path("map1.exr") + " " + path("map3.exr") +
                  " --receivers " + path("rx.exr") + " --output-dir " + path("dir/sub") + " --preview -q",
              dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(files_in("dir/sub"),
            (std::vector<std::string>{"map0.exr", "map0.png", "map1.exr", "map1.png", "map3.exr", "map3.png"}));
  EXPECT_EQ(bytes(path("dir/sub/map1.exr")), single_run("map1.exr", "--receivers " + path("rx.exr"), ""));
}

// --shard K/N: N processes write what one run writes, byte for byte (frames K, K + N, ...), each
// checks the whole list first, and a bad K/N or a shard outside a batch is refused.
TEST_F(BatchCli, ShardsTogetherWriteWhatOneRunWrites) {
  std::string list;
  for (int i = 0; i < 5; ++i)
    list += "map" + std::to_string(i % 4) + ".exr rx.exr out/f" + std::to_string(i) + ".exr\n";
  write_list("frames.txt", list);
  const std::string options = " --method vsm --blur-radius 1 -q";
  ASSERT_EQ(run_cli("filter --frames " + path("frames.txt") + options, dir_).exit_code, 0);
  std::vector<std::string> whole;
  for (int i = 0; i < 5; ++i) whole.push_back(bytes(path("out/f" + std::to_string(i) + ".exr")));
  fs::remove_all(path("out"));
  fs::create_directories(path("out"));
  for (const char* shard : {"1/2", "2/2"}) {
    const RunResult r = run_cli("filter --frames " + path("frames.txt") + options + " --shard " + shard, dir_);
    ASSERT_EQ(r.exit_code, 0) << shard << ": " << r.err;
    if (std::string(shard) == "1/2") {  // frames 0, 2, 4 only
      EXPECT_EQ(files_in("out"), (std::vector<std::string>{"f0.exr", "f2.exr", "f4.exr"}));
    }
  }
  for (int i = 0; i < 5; ++i) EXPECT_EQ(bytes(path("out/f" + std::to_string(i) + ".exr")), whole[i]) << i;

  for (const char* bad : {"0/2", "3/2", "2", "1/0", "a/b", "1/-2", "1/2/3"}) {
    const RunResult r = run_cli("filter --frames " + path("frames.txt") + " --shard " + bad, dir_);
    EXPECT_EQ(r.exit_code, 2) << bad;
    EXPECT_NE(r.err.find("--shard must be K/N"), std::string::npos) << r.err;
    EXPECT_EQ(count_lines(r.err), 1u) << r.err;
  }
  const RunResult single = run_cli("filter --shadow-map " + path("map0.exr") + " --receivers " + path("rx.exr") +
                                       " -o " + path("one.exr") + " --shard 1/2",
                                   dir_);
  EXPECT_EQ(single.exit_code, 2);
  EXPECT_NE(single.err.find("--shard is for a batch"), std::string::npos) << single.err;
  // A shard refuses what the whole list refuses, even where the clash is in another shard's frames.
  write_list("clash.txt", "map0.exr rx.exr out/a.exr\nmap1.exr rx.exr out/b.exr\nmap2.exr rx.exr out/a.exr\n");
  const RunResult clash = run_cli("filter --frames " + path("clash.txt") + " --shard 2/2", dir_);
  EXPECT_EQ(clash.exit_code, 2) << clash.err;
  EXPECT_FALSE(fs::exists(path("out/b.exr")));
}

// map1 is missing: without --keep-going the batch stops at its line, with the frame before it
// written in full and nothing after; with it, every other frame is written and the exit code
// counts the failures.
TEST_F(BatchCli, BadFrameStopsOrIsSkippedWithItsLineNamed) {
  fs::remove(path("map1.exr"));
  HostImage nan_map(24, 16, 1, std::numeric_limits<float>::quiet_NaN());
  io::write_image(path("nan.exr"), nan_map);
  write_list("frames.txt",
             "map0.exr rx.exr out/f0.exr\n"
             "# the next frame's map is missing\n"
             "map1.exr rx.exr out/f1.exr\n"
             "map2.exr rx.exr out/f2.exr\n"
             "nan.exr rx.exr out/f3.exr\n"
             "map3.exr depth=rd.exr out/f4.exr\n");
  RunResult r = run_cli("filter --frames " + path("frames.txt"), dir_);
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_EQ(count_lines(r.err), 1u) << r.err;
  EXPECT_NE(r.err.find("frames.txt:3: shadow map"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("1 frame before it written"), std::string::npos) << r.err;
  EXPECT_EQ(files_in("out"), std::vector<std::string>{"f0.exr"});
  EXPECT_EQ(bytes(path("out/f0.exr")), single_run("map0.exr", "--receivers " + path("rx.exr"), ""));

  fs::remove(path("out/f0.exr"));
  r = run_cli("filter --frames " + path("frames.txt") + " --keep-going -q", dir_);
  EXPECT_EQ(r.exit_code, 2) << r.err;  // two frames failed
  EXPECT_EQ(count_lines(r.err), 2u) << r.err;
  EXPECT_NE(r.err.find("frames.txt:3: shadow map"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("frames.txt:5: shadow map"), std::string::npos) << r.err;
  EXPECT_EQ(files_in("out"), (std::vector<std::string>{"f0.exr", "f2.exr", "f4.exr"}));
  EXPECT_EQ(bytes(path("out/f4.exr")), single_run("map3.exr", "--receiver-depth " + path("rd.exr"), ""));
}

// A frame that cannot be written (its directory is missing) fails like a frame that cannot be
// read: the frames before it stay, the frames after it are not written.
TEST_F(BatchCli, UnwritableFrameStopsTheBatch) {
  write_list("frames.txt",
             "map0.exr rx.exr out/f0.exr\n"
             "map1.exr rx.exr out/missing/f1.exr\n"
             "map2.exr rx.exr out/f2.exr\n");
  const RunResult r = run_cli("filter --frames " + path("frames.txt") + " --preview", dir_);
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("frames.txt:2: "), std::string::npos) << r.err;
  EXPECT_EQ(files_in("out"), (std::vector<std::string>{"f0.exr", "f0.png"}));
}

// Lists and batches that cannot run are refused before any frame: exit 2, one line, nothing written.
TEST_F(BatchCli, BadListsAreRefusedBeforeAnyFrame) {
  const auto refused = [&](const std::string& list, const std::string& args, const std::string& expect) {
    write_list("frames.txt", list);
    const RunResult r = run_cli("filter --frames " + path("frames.txt") + " " + args, dir_);
    EXPECT_EQ(r.exit_code, 2) << list << r.err;
    EXPECT_EQ(count_lines(r.err), 1u) << r.err;
    EXPECT_NE(r.err.find(expect), std::string::npos) << r.err;
    EXPECT_TRUE(files_in("out").empty()) << list;
  };
  refused("map0.exr rx.exr out/f0.exr\nmap1.exr out/f1.exr\n", "", "frames.txt:2: expected 'SHADOWMAP RECEIVERS");
  refused("map0.exr rx.exr out/f0.exr\nmap1.exr rx.exr out/f0.exr\n", "", "frames.txt:2: output");
  refused("map0.exr rx.exr out/f0.exr\nmap1.exr rx.exr map0.exr\n", "", "refusing to overwrite an input");
  refused("map0.exr rx.exr out/f0.exr\nmap1.exr rx.exr out/f0.tif\n", "--preview", "frames.txt:1 too");
  refused("map0.exr rx.exr out/f0.exr\nmap1.exr rx.exr out/f1.png\n", "--preview", "frames.txt:2: output image");
  refused("map0.exr depth= out/f0.exr\n", "", "'depth=' names no file");
  refused("map0.exr \"rx.exr out/f0.exr\n", "", "quote is not closed");
  refused("# nothing\n\n", "", "holds no frames");
  refused("map0.exr rx.exr out/f0.exr\n", "--flags-out " + path("flags.exr"), "--flags-out");
  refused("map0.exr rx.exr out/f0.exr\n", "--esm-c nan", "--esm-c: must be a finite number");
  const RunResult r = run_cli("filter --frames " + path("nosuch.txt"), dir_);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("frame list '" + path("nosuch.txt") + "': file not found"), std::string::npos) << r.err;
  const RunResult two = run_cli("filter --shadow-map " + path("map0.exr") + " " + path("map1.exr") + " --receivers " +
                                    path("rx.exr") + " -o " + path("out/x.exr"),
                                dir_);
  EXPECT_EQ(two.exit_code, 2);
  EXPECT_NE(two.err.find("need --output-dir"), std::string::npos) << two.err;
}

// soft --frames: each map's light from its header, the same bytes as single runs; a bad frame
// is named by its line.
TEST_F(BatchCli, SoftFramesEqualSingleRuns) {
  const std::string spheres = data_path("spheres"), thin = data_path("thin");
  write_list("soft.txt", spheres + "/shadowmap.exr " + spheres + "/receivers.exr out/s0.exr\n" + thin +
                             "/shadowmap.exr depth=" + thin + "/receiver_depth.exr out/s1.exr\n");
  RunResult r = run_cli("soft --method pcss --frames " + path("soft.txt"), dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("batch of 2 frames, 2 written, 0 failed"), std::string::npos) << r.out;
  const auto single = [&](const std::string& dir, const std::string& rx) {
    const RunResult one = run_cli(
        "soft --method pcss -q --shadow-map " + dir + "/shadowmap.exr " + rx + " -o " + path("single.exr"), dir_);
    EXPECT_EQ(one.exit_code, 0) << one.err;
    return bytes(path("single.exr"));
  };
  EXPECT_EQ(bytes(path("out/s0.exr")), single(spheres, "--receivers " + spheres + "/receivers.exr"));
  EXPECT_EQ(bytes(path("out/s1.exr")), single(thin, "--receiver-depth " + thin + "/receiver_depth.exr"));
  EXPECT_NE(bytes(path("out/s0.exr")), bytes(path("out/s1.exr")));

  write_list("soft.txt", spheres + "/shadowmap.exr " + spheres + "/receivers.exr out/s2.exr\n" + "nosuch.exr " +
                             spheres + "/receivers.exr out/s3.exr\n");
  r = run_cli("soft --frames " + path("soft.txt") + " --keep-going -q", dir_);
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("soft.txt:2: "), std::string::npos) << r.err;
  EXPECT_TRUE(fs::exists(path("out/s2.exr")));
  EXPECT_FALSE(fs::exists(path("out/s3.exr")));
}

// --preview: the PNG beside the EXR, decodable, of the output's size, with the visibility in
// [0,1] as 16-bit grey; a run that fails leaves neither file.
TEST_F(BatchCli, PreviewBesideTheOutputOrNothing) {
  const std::string run = "filter --receivers " + path("rx.exr") + " -q --preview -o " + path("out/vis.exr");
  RunResult r = run_cli(run + " --shadow-map " + path("map0.exr"), dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const HostImage vis = io::load_depth_map(path("out/vis.exr"), {});
  const HostImage png = io::load_depth_map(path("out/vis.png"), {});
  ASSERT_EQ(png.width, vis.width);
  ASSERT_EQ(png.height, vis.height);
  for (size_t i = 0; i < vis.data.size(); ++i) EXPECT_NEAR(png.data[i], vis.data[i], 0.5 / 65535 + 1e-7) << i;
  fs::remove(path("out/vis.exr"));
  fs::remove(path("out/vis.png"));

  r = run_cli(run + " --shadow-map " + path("nosuch.exr"), dir_);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(files_in("out").empty());
  r = run_cli("filter --receivers " + path("rx.exr") + " --shadow-map " + path("map0.exr") + " --preview -o " +
                  path("out/vis.png"),
              dir_);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("is a PNG already"), std::string::npos) << r.err;
  EXPECT_TRUE(files_in("out").empty());
}

}  // namespace
}  // namespace sf::test
