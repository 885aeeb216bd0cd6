// The on-disk program cache cannot hurt (host/src/runtime/program_cache.hpp): an entry that does not
// verify (truncated, zeroed, of another build, swapped with another entry) is discarded with a
// note and the program rebuilt, never loaded.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "program_cache.hpp"
#include "sf_test_env.hpp"

namespace sf::test {
namespace {

namespace fs = std::filesystem;

TEST(ProgramCache, OnlyAnIntactEntryOfItsKeyUnpacks) {
  std::vector<unsigned char> binary(5000);
  for (size_t i = 0; i < binary.size(); ++i) binary[i] = static_cast<unsigned char>(i * 131 % 251);
  const std::string entry = sf::detail::pack_cache_entry("key A", binary);
  std::vector<unsigned char> out;
  std::string problem;
  ASSERT_TRUE(sf::detail::unpack_cache_entry(entry, "key A", &out, &problem)) << problem;
  EXPECT_EQ(out, binary);

  EXPECT_FALSE(sf::detail::unpack_cache_entry(entry, "key B", &out, &problem));
  EXPECT_EQ(problem, "built for another key");
  EXPECT_FALSE(sf::detail::unpack_cache_entry(entry, "key AB", &out, &problem));
  for (size_t cut : {size_t(0), size_t(7), size_t(20), entry.size() / 2, entry.size() - 1})
    EXPECT_FALSE(sf::detail::unpack_cache_entry(entry.substr(0, cut), "key A", &out, &problem)) << cut;
  EXPECT_FALSE(sf::detail::unpack_cache_entry(std::string(entry.size(), '\0'), "key A", &out, &problem));
  for (size_t at : {size_t(3), size_t(9), size_t(30), entry.size() - 100}) {
    std::string flipped = entry;
    flipped[at] = char(flipped[at] ^ 0x10);
    EXPECT_FALSE(sf::detail::unpack_cache_entry(flipped, "key A", &out, &problem)) << "byte " << at;
  }
  EXPECT_FALSE(sf::detail::unpack_cache_entry(entry + "x", "key A", &out, &problem));
}

class ProgramCacheRuntime : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = temp_dir(std::string("program_cache_") + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    const char* old = std::getenv("SHADOWFILTER_CACHE_DIR");
    saved_ = old ? old : "";
    had_ = old != nullptr;
    ::setenv("SHADOWFILTER_CACHE_DIR", dir_.c_str(), 1);
  }
  void TearDown() override {
    if (had_)
      ::setenv("SHADOWFILTER_CACHE_DIR", saved_.c_str(), 1);
    else
      ::unsetenv("SHADOWFILTER_CACHE_DIR");
  }
  // A fresh Runtime (no in-memory programs) on the shared context: it reads the disk cache.
  std::shared_ptr<Runtime> fresh(std::vector<std::string>* notes) {
    auto rt = std::make_shared<Runtime>(runtime().context(), runtime().queue());
    rt->set_notice_sink([notes](const std::string& n) { notes->push_back(n); });
    return rt;
  }
  std::vector<fs::path> entries() const {
    std::vector<fs::path> out;
    for (const auto& e : fs::directory_iterator(dir_)) out.push_back(e.path());
    std::sort(out.begin(), out.end());
    return out;
  }
  // Builds the two programs and creates one kernel of each (what a swapped binary broke).
  void build_both(Runtime& rt) {
    cl::Kernel a(rt.program({"depth_range.cl"}, ""), "sf_depth_range");
    cl::Kernel b(rt.program({"common.clh", "storage.clh", "methods/esm.clh", "transform.cl"}, "-DSF_STORAGE=0"),
                 "sf_transform");
  }
  std::string dir_, saved_;
  bool had_ = false;
};

TEST_F(ProgramCacheRuntime, DamagedEntriesAreDiscardedAndRebuilt) {
  std::vector<std::string> notes;
  ASSERT_NO_THROW(build_both(*fresh(&notes)));
  const std::vector<fs::path> files = entries();
  ASSERT_EQ(files.size(), 2u);
  EXPECT_TRUE(notes.empty());

  auto damage_and_reload = [&](const char* what, auto damage) {
    SCOPED_TRACE(what);
    damage();
    notes.clear();
    ASSERT_NO_THROW(build_both(*fresh(&notes)));
    EXPECT_EQ(notes.size(), 2u) << "each damaged entry is noted";
    for (const std::string& n : notes) EXPECT_NE(n.find("discarded"), std::string::npos) << n;
    notes.clear();
    ASSERT_NO_THROW(build_both(*fresh(&notes)));  // the rebuilt entries load silently
    EXPECT_TRUE(notes.empty()) << notes.front();
  };
  damage_and_reload("truncated", [&] {
    for (const auto& f : files) fs::resize_file(f, 100);
  });
  damage_and_reload("zeroed", [&] {
    for (const auto& f : files) {
      const auto size = fs::file_size(f);
      std::ofstream(f, std::ios::binary) << std::string(size, '\0');
    }
  });
  damage_and_reload("swapped", [&] {
    fs::rename(files[0], dir_ + "/swap");
    fs::rename(files[1], files[0]);
    fs::rename(dir_ + "/swap", files[1]);
  });
  EXPECT_EQ(entries(), files) << "no temporary file is left in the cache";
}

}  // namespace
}  // namespace sf::test
