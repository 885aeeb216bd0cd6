#include "ray_tracer.hpp"

#include <embree3/rtcore.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace sf::scene {
namespace {

void check_device(RTCDevice device, const char* what) {
  const RTCError error = rtcGetDeviceError(device);
  if (error != RTC_ERROR_NONE)
    throw std::runtime_error(std::string("Embree error ") + std::to_string(int(error)) + " in " + what);
}

void fill_ray(RTCRay& r, const Ray& ray, double t_min, double t_max, unsigned mask) {
  r.org_x = float(ray.origin.x);
  r.org_y = float(ray.origin.y);
  r.org_z = float(ray.origin.z);
  r.dir_x = float(ray.direction.x);
  r.dir_y = float(ray.direction.y);
  r.dir_z = float(ray.direction.z);
  r.tnear = float(t_min);
  r.tfar = std::isfinite(t_max) ? float(t_max) : std::numeric_limits<float>::infinity();
  r.time = 0.0f;
  r.mask = mask;
  r.id = 0;
  r.flags = 0;
}

}  // namespace

struct RayTracer::Impl {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
};

RayTracer::RayTracer(const SceneGeometry& geometry) : impl_(std::make_unique<Impl>()) {
  impl_->device = rtcNewDevice(nullptr);
  if (!impl_->device) throw std::runtime_error("cannot create an Embree device");
  impl_->scene = rtcNewScene(impl_->device);
  rtcSetSceneFlags(impl_->scene, RTC_SCENE_FLAG_ROBUST);
  rtcSetSceneBuildQuality(impl_->scene, RTC_BUILD_QUALITY_HIGH);
  unsigned id = 0;
  for (const TriMesh& mesh : geometry.meshes) {
    RTCGeometry g = rtcNewGeometry(impl_->device, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                          3 * sizeof(float), mesh.vertices.size()));
    auto* t = static_cast<unsigned*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                             3 * sizeof(unsigned), mesh.triangles.size()));
    check_device(impl_->device, "allocating a mesh");
    for (size_t k = 0; k < mesh.vertices.size(); ++k) {
      v[3 * k] = float(mesh.vertices[k].x);
      v[3 * k + 1] = float(mesh.vertices[k].y);
      v[3 * k + 2] = float(mesh.vertices[k].z);
    }
    for (size_t k = 0; k < mesh.triangles.size(); ++k)
      for (int c = 0; c < 3; ++c) t[3 * k + c] = mesh.triangles[k][c];
    rtcSetGeometryMask(g, mesh.ground ? kMaskGround : kMaskOccluders);
    rtcCommitGeometry(g);
    rtcAttachGeometryByID(impl_->scene, g, id++);
    rtcReleaseGeometry(g);
  }
  for (const Sphere& sphere : geometry.spheres) {
    RTCGeometry g = rtcNewGeometry(impl_->device, RTC_GEOMETRY_TYPE_SPHERE_POINT);
    auto* p = static_cast<float*>(
        rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, 4 * sizeof(float), 1));
    check_device(impl_->device, "allocating a sphere");
    p[0] = float(sphere.center.x);
    p[1] = float(sphere.center.y);
    p[2] = float(sphere.center.z);
    p[3] = float(sphere.radius);
    rtcSetGeometryMask(g, kMaskOccluders);
    rtcCommitGeometry(g);
    rtcAttachGeometryByID(impl_->scene, g, id++);
    rtcReleaseGeometry(g);
  }
  rtcCommitScene(impl_->scene);
  check_device(impl_->device, "building the scene");
}

RayTracer::~RayTracer() {
  if (impl_->scene) rtcReleaseScene(impl_->scene);
  if (impl_->device) rtcReleaseDevice(impl_->device);
}

std::optional<Hit> RayTracer::closest(const Ray& ray, double t_min, double t_max, unsigned mask) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit rh;
  fill_ray(rh.ray, ray, t_min, t_max, mask);
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(impl_->scene, &context, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return std::nullopt;
  Vec3 n{rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z};
  const double len = length(n);
  if (!(len > 0.0))
    n = -1.0 * ray.direction;
  else
    n = (1.0 / len) * n;
  if (dot(n, ray.direction) > 0.0) n = -n;
  return Hit{rh.ray.tfar, n, rh.hit.geomID};
}

bool RayTracer::occluded(const Ray& ray, double t_min, double t_max, unsigned mask) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRay r;
  fill_ray(r, ray, t_min, t_max, mask);
  rtcOccluded1(impl_->scene, &context, &r);
  return r.tfar == -std::numeric_limits<float>::infinity();
}

void RayTracer::hits_along(const Ray* rays, size_t count, int hits, double gap, double* t) const {
  constexpr size_t kLanes = 16;
  constexpr float kInf = std::numeric_limits<float>::infinity();
  for (size_t first = 0; first < count; first += kLanes) {
    const size_t lanes = std::min(kLanes, count - first);
    alignas(64) int valid[kLanes];
    alignas(64) RTCRayHit16 rh;
    float tnear[kLanes];
    for (size_t l = 0; l < kLanes; ++l) {
      valid[l] = l < lanes ? -1 : 0;
      tnear[l] = 0.0f;
    }
    for (int h = 0; h < hits; ++h) {
      RTCIntersectContext context;
      rtcInitIntersectContext(&context);
      context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
      for (size_t l = 0; l < kLanes; ++l) {
        const Ray& ray = rays[first + std::min(l, lanes - 1)];
        rh.ray.org_x[l] = float(ray.origin.x);
        rh.ray.org_y[l] = float(ray.origin.y);
        rh.ray.org_z[l] = float(ray.origin.z);
        rh.ray.dir_x[l] = float(ray.direction.x);
        rh.ray.dir_y[l] = float(ray.direction.y);
        rh.ray.dir_z[l] = float(ray.direction.z);
        rh.ray.tnear[l] = tnear[l];
        rh.ray.tfar[l] = kInf;
        rh.ray.time[l] = 0.0f;
        rh.ray.mask[l] = kMaskAll;
        rh.ray.id[l] = 0;
        rh.ray.flags[l] = 0;
        rh.hit.geomID[l] = RTC_INVALID_GEOMETRY_ID;
        rh.hit.instID[0][l] = RTC_INVALID_GEOMETRY_ID;
      }
      rtcIntersect16(valid, impl_->scene, &context, &rh);
      bool any = false;
      for (size_t l = 0; l < lanes; ++l) {
        if (!valid[l]) {
          t[(first + l) * hits + h] = std::numeric_limits<double>::infinity();
          continue;
        }
        if (rh.hit.geomID[l] == RTC_INVALID_GEOMETRY_ID) {
          valid[l] = 0;
          t[(first + l) * hits + h] = std::numeric_limits<double>::infinity();
          continue;
        }
        t[(first + l) * hits + h] = rh.ray.tfar[l];
        tnear[l] = float(rh.ray.tfar[l] + gap);
        any = true;
      }
      if (!any) {
        for (int k = h + 1; k < hits; ++k)
          for (size_t l = 0; l < lanes; ++l) t[(first + l) * hits + k] = std::numeric_limits<double>::infinity();
        break;
      }
    }
  }
}

}  // namespace sf::scene
