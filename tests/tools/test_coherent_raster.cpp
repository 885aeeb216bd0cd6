// The views of a coherent stack rasterised on the device (kernels/coherent/raster.cl,
// host/scene/view_raster_device.hpp): the host rasteriser's maps byte for byte, over depth pairs,
// far planes and meshes with deep crossing lists (whose views fall back to the host), and the
// device's compression of them equal to the host's fit.
#include <gtest/gtest.h>

#include <vector>

#include "coherent_reference.hpp"
#include "coherent_stack.hpp"
#include "sf_test_env.hpp"
#include "shadowfilter/coherent_device.hpp"
#include "shadowfilter/errors.hpp"
#include "view_raster_device.hpp"

namespace sf::test {
namespace {

using namespace sf::scene;
namespace co = sf::coherent;

// Prisms, a thin slab and a stack of nine plates: a steep ray through the stack crosses 18 faces,
// more than a texel's list holds, so the views near the poles are the host's and those near the
// equator the device's; the slab's top face and the lowest plate's bottom share a plane.
SceneGeometry soup() {
  SceneGeometry g;
  g.name = "soup";
  TriMesh m;
  m.name = "soup";
  add_prism(m, {-0.8, -0.6, 0.2}, {0.7, 0.5, -0.3}, 0.25, 0.1, 7);
  add_prism(m, {0.3, -0.7, -0.6}, {-0.2, 0.8, 0.5}, 0.15, 0.3, 5);
  for (int k = 0; k < 9; ++k) append_box(m, {-0.5, 0.1 * k, -0.5}, {0.5, 0.1 * k + 0.02, 0.5});
  append_box(m, {-1.0, -0.05, -1.0}, {1.0, 0.0, 1.0});  // a thin slab under all of them
  g.meshes.push_back(m);
  return g;
}

std::vector<uint16_t> download(const cl::Buffer& b, size_t count) {
  std::vector<uint16_t> v(count);
  runtime().queue().enqueueReadBuffer(b, CL_TRUE, 0, count * sizeof(uint16_t), v.data());
  return v;
}

TEST(CoherentRaster, DeviceViewsEqualTheHostRasteriser) {
  if (!runtime().info().fp64) GTEST_SKIP() << "the device lacks cl_khr_fp64";
  struct Case {
    const char* object;
    int views, resolution;
    co::DepthPair pair;
    co::FarPlane far;
    co::Ordering ordering;
  };
  const Case cases[] = {
      {"box", 8, 32, co::DepthPair::FirstSecond, co::FarPlane::Sphere, co::Ordering::Hilbert},
      {"soup", 16, 48, co::DepthPair::FirstSecond, co::FarPlane::Sphere, co::Ordering::Hilbert},
      {"soup", 6, 40, co::DepthPair::FirstThird, co::FarPlane::Infinite, co::Ordering::ZigZag},
  };
  for (const Case& c : cases) {
    const SceneGeometry object = std::string(c.object) == "soup" ? soup() : load_coherent_object(c.object);
    co::StackLayout l;
    l.views_theta = l.views_phi = c.views;
    l.resolution = c.resolution;
    l.ordering = c.ordering;
    l.depth_pair = c.pair;
    l.far_plane = c.far;
    fit_bounding_sphere(object, l);
    const co::DualDepthStack host = render_stack(object, l, 2);
    DeviceRasterStats stats;
    const co::DeviceDualDepth device = render_stack_on_device(runtime(), object, l, &stats);
    const size_t values = size_t(l.views()) * l.texels();
    const std::vector<uint16_t> z1 = download(device.z1, values), z2 = download(device.z2, values);
    size_t surfaces = 0;
    for (uint16_t z : host.z1) surfaces += z != co::kNoSurface;
    std::printf("%s: %d x %d views of %d^2, %zu views a batch, %zu on the host, %zu of %zu texels on a surface\n",
                c.object, c.views, c.views, c.resolution, stats.batch_views, stats.host_views, surfaces, values);
    EXPECT_GT(surfaces, values / 10) << c.object;
    EXPECT_EQ(z1, host.z1) << c.object;
    EXPECT_EQ(z2, host.z2) << c.object;
    if (std::string(c.object) == "soup") {
      EXPECT_GT(stats.host_views, 0u);  // the row of boxes outgrew the lists
      EXPECT_LT(stats.host_views, size_t(l.views()));
    } else {
      EXPECT_EQ(stats.host_views, 0u);
    }
    // The maps never leave the device for the compression: the host's fit, byte for byte.
    const co::CompressedStack fitted = co::download(runtime(), co::compress_on_device(runtime(), device));
    const co::CompressedStack expected = ref::coherent::compress(host);
    EXPECT_EQ(fitted.offsets, expected.offsets) << c.object;
    EXPECT_EQ(fitted.last, expected.last) << c.object;
    EXPECT_EQ(fitted.depth, expected.depth) << c.object;
  }
  // Analytic spheres are not rasterised.
  co::StackLayout l;
  l.views_theta = l.views_phi = 4;
  l.resolution = 8;
  const SceneGeometry sphere = load_coherent_object("sphere");
  fit_bounding_sphere(sphere, l);
  EXPECT_THROW(render_stack_on_device(runtime(), sphere, l), InputError);
}

}  // namespace
}  // namespace sf::test
