// One kernel per program (kernels/common.clh, BuildOptions::only_kernel): a program built for
// one kernel of a file holds that kernel alone, the file's other kernels compiled out, while the
// file built whole still holds every kernel. (Their binaries' sizes are not asked: on PoCL that
// compiles every kernel of the program once more.)
#include <gtest/gtest.h>

#include <algorithm>
#include <sstream>
#include <string>
#include <vector>

#include "launch.hpp"
#include "sf_test_env.hpp"

namespace sf::test {
namespace {

std::vector<std::string> kernel_names(const cl::Program& p) {
  std::vector<std::string> names;
  std::stringstream s(p.getInfo<CL_PROGRAM_KERNEL_NAMES>());
  for (std::string n; std::getline(s, n, ';');)
    if (!n.empty()) names.push_back(n);
  std::sort(names.begin(), names.end());
  return names;
}

struct GuardedFile {
  std::vector<std::string> files;
  std::string options;
  std::vector<std::string> kernels;  // sorted
};

TEST(OneKernelPrograms, HoldTheirKernelAlone) {
  const std::vector<GuardedFile> guarded = {
      {{"common.clh", "storage.clh", "methods/esm.clh", "lookup.clh", "transform.cl"},
       "-cl-std=CL1.2 -DSF_METHOD_esm -DSF_STORAGE=0",
       {"sf_transform", "sf_transformv"}},
      {{"common.clh", "storage.clh", "methods/esm.clh", "lookup.clh", "reconstruct.cl"},
       "-cl-std=CL1.2 -DSF_METHOD_esm -DSF_STORAGE=0 -DSF_RX_VEC=16",
       {"sf_reconstruct_grid", "sf_reconstruct_points"}},
      {{"common.clh", "storage.clh", "methods/esm.clh", "lookup.clh", "receiver_plane.clh", "esm_classify.cl"},
       "-cl-std=CL1.2 -DSF_METHOD_esm -DSF_STORAGE=0 -DSF_LOOKUP=0 -DSF_RX_VEC=16",
       {"sf_esm_classify_grid", "sf_esm_classify_points", "sf_esm_classify_points_vec"}},
  };
  Runtime& rt = runtime();
  for (const GuardedFile& g : guarded) {
    SCOPED_TRACE(g.files.back());
    const cl::Program whole = rt.program(g.files, g.options);
    EXPECT_EQ(kernel_names(whole), g.kernels);
    for (const std::string& k : g.kernels) {
      SCOPED_TRACE(k);
      detail::BuildOptions b = detail::BuildOptions::without_standard();
      const cl::Program one = rt.program(g.files, b.append(g.options).only_kernel(k).str());
      EXPECT_EQ(kernel_names(one), std::vector<std::string>{k});
      EXPECT_NO_THROW(cl::Kernel(one, k.c_str()));
    }
  }
}

}  // namespace
}  // namespace sf::test
