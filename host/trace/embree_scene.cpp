#include "trace/embree_scene.h"

#include <chrono>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include <embree3/rtcore.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include "scene/alpha_mask.h"

namespace rtpg {
namespace {

// What an alpha-tested mesh needs in its filter callbacks.
struct AlphaMask {
  const Mesh* mesh = nullptr;
  const Texture* texture = nullptr;
  float cutoff = 0.5f;
};

// One callback for closest-hit and occlusion queries: rejects hits on transparent texels.
void alpha_filter(const RTCFilterFunctionNArguments* args) {
  const auto* mask = static_cast<const AlphaMask*>(args->geometryUserPtr);
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] != -1) continue;
    const std::uint32_t prim = RTCHitN_primID(args->hit, args->N, i);
    const float u = RTCHitN_u(args->hit, args->N, i);
    const float v = RTCHitN_v(args->hit, args->N, i);
    if (!passes_alpha_test(*mask->mesh, *mask->texture, mask->cutoff, prim, u, v))
      args->valid[i] = 0;
  }
}

const char* embree_error_name(RTCError code) {
  switch (code) {
    case RTC_ERROR_NONE:
      return "RTC_ERROR_NONE";
    case RTC_ERROR_UNKNOWN:
      return "RTC_ERROR_UNKNOWN";
    case RTC_ERROR_INVALID_ARGUMENT:
      return "RTC_ERROR_INVALID_ARGUMENT";
    case RTC_ERROR_INVALID_OPERATION:
      return "RTC_ERROR_INVALID_OPERATION";
    case RTC_ERROR_OUT_OF_MEMORY:
      return "RTC_ERROR_OUT_OF_MEMORY";
    case RTC_ERROR_UNSUPPORTED_CPU:
      return "RTC_ERROR_UNSUPPORTED_CPU";
    case RTC_ERROR_CANCELLED:
      return "RTC_ERROR_CANCELLED";
  }
  return "RTC_ERROR_?";
}

void check(RTCDevice device, const char* call) {
  const RTCError code = rtcGetDeviceError(device);
  if (code != RTC_ERROR_NONE) throw EmbreeError(std::string(call) + ": " + embree_error_name(code));
}

constexpr std::size_t kGrain = 1024;
constexpr std::size_t kStreamChunk = 256;  // rays handed to rtcIntersect1M / rtcOccluded1M at once

}  // namespace

struct EmbreeScene::Impl {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  std::vector<AlphaMask> masks;  // stable addresses: reserved before geometry creation
};

EmbreeScene::EmbreeScene(const Scene& scene) : impl_(std::make_unique<Impl>()) {
  const auto start = std::chrono::steady_clock::now();
  impl_->device = rtcNewDevice(nullptr);
  if (!impl_->device)
    throw EmbreeError("rtcNewDevice: " +
                      std::string(embree_error_name(rtcGetDeviceError(nullptr))));
  impl_->scene = rtcNewScene(impl_->device);
  rtcSetSceneBuildQuality(impl_->scene, RTC_BUILD_QUALITY_HIGH);
  impl_->masks.reserve(scene.meshes.size());
  for (std::size_t m = 0; m < scene.meshes.size(); ++m) {
    const Mesh& mesh = scene.meshes[m];
    RTCGeometry geom = rtcNewGeometry(impl_->device, RTC_GEOMETRY_TYPE_TRIANGLE);
    // Embree reads vertices as 16-byte vectors: allocate through Embree, which pads.
    auto* vertices = static_cast<float*>(
        rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                3 * sizeof(float), mesh.positions.size()));
    auto* indices = static_cast<unsigned*>(
        rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                3 * sizeof(unsigned), mesh.triangles.size()));
    check(impl_->device, "rtcSetNewGeometryBuffer");
    for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
      vertices[3 * i + 0] = mesh.positions[i].x;
      vertices[3 * i + 1] = mesh.positions[i].y;
      vertices[3 * i + 2] = mesh.positions[i].z;
    }
    for (std::size_t i = 0; i < mesh.triangles.size(); ++i) {
      indices[3 * i + 0] = mesh.triangles[i].x;
      indices[3 * i + 1] = mesh.triangles[i].y;
      indices[3 * i + 2] = mesh.triangles[i].z;
    }
    const Material& material = scene.materials.at(mesh.material);
    if (has_alpha_mask(scene, mesh)) {
      impl_->masks.push_back(
          {&mesh, &scene.textures.at(material.alpha_texture), material.alpha_cutoff});
      rtcSetGeometryUserData(geom, &impl_->masks.back());
      rtcSetGeometryIntersectFilterFunction(geom, alpha_filter);
      rtcSetGeometryOccludedFilterFunction(geom, alpha_filter);
    }
    rtcCommitGeometry(geom);
    rtcAttachGeometryByID(impl_->scene, geom, static_cast<unsigned>(m));
    rtcReleaseGeometry(geom);
    check(impl_->device, "rtcAttachGeometryByID");
  }
  rtcCommitScene(impl_->scene);
  check(impl_->device, "rtcCommitScene");
  build_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

EmbreeScene::~EmbreeScene() {
  if (impl_->scene) rtcReleaseScene(impl_->scene);
  if (impl_->device) rtcReleaseDevice(impl_->device);
}

namespace {

void to_embree(const Ray& r, RTCRay& out) {
  out.org_x = r.origin.x;
  out.org_y = r.origin.y;
  out.org_z = r.origin.z;
  out.tnear = r.tmin;
  out.dir_x = r.direction.x;
  out.dir_y = r.direction.y;
  out.dir_z = r.direction.z;
  out.time = 0.0f;
  out.tfar = r.tmax;
  out.mask = 0xffffffffu;
  out.id = 0;
  out.flags = 0;
}

// Lane `lane` of an Embree packet of N rays (RTCRay8, RTCRay16).
template <class RTCRayN>
void set_ray_n(RTCRayN& packet, int lane, const Ray& r) {
  packet.org_x[lane] = r.origin.x;
  packet.org_y[lane] = r.origin.y;
  packet.org_z[lane] = r.origin.z;
  packet.tnear[lane] = r.tmin;
  packet.dir_x[lane] = r.direction.x;
  packet.dir_y[lane] = r.direction.y;
  packet.dir_z[lane] = r.direction.z;
  packet.time[lane] = 0.0f;
  packet.tfar[lane] = r.tmax;
  packet.mask[lane] = 0xffffffffu;
  packet.id[lane] = 0;
  packet.flags[lane] = 0;
}

// A query context with the given coherence hint (rtcInitIntersectContext sets INCOHERENT).
RTCIntersectContext intersect_context(RTCIntersectContextFlags flags) {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  context.flags = flags;
  return context;
}

// Lane `lane` of an Embree packet's answer (RTCRayHit8, RTCRayHit16) as a Hit.
template <class RTCRayHitN>
Hit hit_of_lane(const RTCRayHitN& rh, int lane) {
  Hit h;
  h.mesh = rh.hit.geomID[lane] == RTC_INVALID_GEOMETRY_ID ? kNoHit : rh.hit.geomID[lane];
  h.triangle = rh.hit.primID[lane];
  h.t = rh.ray.tfar[lane];
  h.u = rh.hit.u[lane];
  h.v = rh.hit.v[lane];
  return h;
}

// A closest-hit query of one ray, and its answer as a Hit.
void start_query(const Ray& r, RTCRayHit& rh) {
  to_embree(r, rh.ray);
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
}

Hit hit_of(const RTCRayHit& rh) {
  Hit h;
  h.mesh = rh.hit.geomID == RTC_INVALID_GEOMETRY_ID ? kNoHit : rh.hit.geomID;
  h.triangle = rh.hit.primID;
  h.t = rh.ray.tfar;
  h.u = rh.hit.u;
  h.v = rh.hit.v;
  return h;
}

// EmbreeScene::intersect for the span rays[0..count) on the calling thread.
void intersect_span(RTCScene scene, const Ray* rays, Hit* hits, std::size_t count, RayMode mode) {
  if (mode == RayMode::Stream) {
    RTCIntersectContext context = intersect_context(RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT);
    alignas(64) RTCRayHit chunk[kStreamChunk];
    for (std::size_t first = 0; first < count; first += kStreamChunk) {
      const std::size_t n = std::min(kStreamChunk, count - first);
      for (std::size_t k = 0; k < n; ++k) start_query(rays[first + k], chunk[k]);
      rtcIntersect1M(scene, &context, chunk, static_cast<unsigned int>(n), sizeof(RTCRayHit));
      for (std::size_t k = 0; k < n; ++k) hits[first + k] = hit_of(chunk[k]);
    }
    return;
  }
  if (mode == RayMode::Single) {
    RTCIntersectContext context = intersect_context(RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT);
    for (std::size_t i = 0; i != count; ++i) {
      RTCRayHit rh;
      start_query(rays[i], rh);
      rtcIntersect1(scene, &context, &rh);
      hits[i] = hit_of(rh);
    }
    return;
  }
  RTCIntersectContext context = intersect_context(RTC_INTERSECT_CONTEXT_FLAG_COHERENT);
  for (std::size_t first = 0; first < count; first += 8) {
    alignas(32) RTCRayHit8 rh;
    alignas(32) int valid[8];
    for (int lane = 0; lane < 8; ++lane) {
      const std::size_t i = first + lane;
      valid[lane] = i < count ? -1 : 0;
      set_ray_n(rh.ray, lane, rays[i < count ? i : count - 1]);
      rh.hit.geomID[lane] = RTC_INVALID_GEOMETRY_ID;
      rh.hit.instID[0][lane] = RTC_INVALID_GEOMETRY_ID;
    }
    rtcIntersect8(valid, scene, &context, &rh);
    for (int lane = 0; lane < 8; ++lane) {
      const std::size_t i = first + lane;
      if (i >= count) break;
      hits[i] = hit_of_lane(rh, lane);
    }
  }
}

// The sum of span(first, n) over the spans of [0, count) handed to TBB's threads: kGrain rays,
// or whole packets of 8 in Packet8 mode (packets start at multiples of 8 whatever the split).
template <class Span>
std::size_t over_spans(std::size_t count, RayMode mode, const Span& span) {
  const std::size_t unit = mode == RayMode::Packet8 ? 8 : 1;
  return tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, (count + unit - 1) / unit, kGrain / unit), std::size_t{0},
      [&](const auto& range, std::size_t sum) {
        const std::size_t first = range.begin() * unit;
        return sum + span(first, std::min(count, range.end() * unit) - first);
      },
      std::plus<std::size_t>());
}

// The sum of span(first, n) over `lists` lists laid out `stride` apart: list l starts at
// l * stride and holds counts[l] rays, at most stride.
template <class Span>
std::size_t over_lists(std::size_t stride, const std::uint32_t* counts, std::size_t lists,
                       const Span& span) {
  return tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, lists), std::size_t{0},
      [&](const auto& range, std::size_t sum) {
        for (std::size_t l = range.begin(); l != range.end(); ++l)
          sum += span(l * stride, std::min<std::size_t>(counts[l], stride));
        return sum;
      },
      std::plus<std::size_t>());
}

}  // namespace

void EmbreeScene::intersect(const Ray* rays, Hit* hits, std::size_t count, RayMode mode) const {
  over_spans(count, mode, [&](std::size_t first, std::size_t n) {
    intersect_span(impl_->scene, rays + first, hits + first, n, mode);
    return std::size_t{0};
  });
}

void EmbreeScene::intersect_lists(const Ray* rays, Hit* hits, std::size_t stride,
                                  const std::uint32_t* counts, std::size_t lists,
                                  RayMode mode) const {
  over_lists(stride, counts, lists, [&](std::size_t first, std::size_t n) {
    intersect_span(impl_->scene, rays + first, hits + first, n, mode);
    return std::size_t{0};
  });
}

namespace {

// Hits of an image's rays in tiles of tile_w x tile_h pixels, one packet of N = tile_w * tile_h
// rays each (lanes row by row inside the tile; lanes past the image's edge invalid). Rows of
// tiles in parallel.
template <int kTileW, int kTileH, class RTCRayHitN, class IntersectN>
void intersect_tiles(RTCScene scene, const Ray* rays, Hit* hits, int width, int height,
                     IntersectN intersect_n) {
  constexpr int kN = kTileW * kTileH;
  const int tiles_x = (width + kTileW - 1) / kTileW, tiles_y = (height + kTileH - 1) / kTileH;
  tbb::parallel_for(tbb::blocked_range<int>(0, tiles_y), [&](const auto& tile_rows) {
    RTCIntersectContext context = intersect_context(RTC_INTERSECT_CONTEXT_FLAG_COHERENT);
    for (int ty = tile_rows.begin(); ty != tile_rows.end(); ++ty)
      for (int tx = 0; tx < tiles_x; ++tx) {
        alignas(64) RTCRayHitN rh;
        alignas(64) int valid[kN];
        std::size_t pixel[kN];
        for (int lane = 0; lane < kN; ++lane) {
          const int x = tx * kTileW + lane % kTileW, y = ty * kTileH + lane / kTileW;
          const bool inside = x < width && y < height;
          valid[lane] = inside ? -1 : 0;
          pixel[lane] = inside ? static_cast<std::size_t>(y) * static_cast<std::size_t>(width) +
                                     static_cast<std::size_t>(x)
                               : 0;
          set_ray_n(rh.ray, lane, rays[pixel[lane]]);
          rh.hit.geomID[lane] = RTC_INVALID_GEOMETRY_ID;
          rh.hit.instID[0][lane] = RTC_INVALID_GEOMETRY_ID;
        }
        intersect_n(valid, scene, &context, &rh);
        for (int lane = 0; lane < kN; ++lane) {
          if (!valid[lane]) continue;
          hits[pixel[lane]] = hit_of_lane(rh, lane);
        }
      }
  });
}

}  // namespace

bool EmbreeScene::native_packets_of_16() const {
  return rtcGetDeviceProperty(impl_->device, RTC_DEVICE_PROPERTY_NATIVE_RAY16_SUPPORTED) != 0;
}

void EmbreeScene::intersect_image(const Ray* rays, Hit* hits, int width, int height,
                                  ImageTiles tiles) const {
  if (width <= 0 || height <= 0) return;
  if (tiles == ImageTiles::automatic)
    tiles = native_packets_of_16() ? ImageTiles::tiles_4x4 : ImageTiles::tiles_4x2;
  if (tiles == ImageTiles::tiles_4x4) {
    if (!native_packets_of_16())
      throw EmbreeError("intersect_image: Embree does not trace 16-wide packets on this CPU");
    intersect_tiles<4, 4, RTCRayHit16>(
        impl_->scene, rays, hits, width, height,
        [](const int* valid, RTCScene scene, RTCIntersectContext* context, RTCRayHit16* rh) {
          rtcIntersect16(valid, scene, context, rh);
        });
    return;
  }
  intersect_tiles<4, 2, RTCRayHit8>(
      impl_->scene, rays, hits, width, height,
      [](const int* valid, RTCScene scene, RTCIntersectContext* context, RTCRayHit8* rh) {
        rtcIntersect8(valid, scene, context, rh);
      });
}

namespace {

// EmbreeScene::occluded for the span rays[0..count) on the calling thread: the rays queried.
// A ray with an empty segment gets 0 without a query: many of the path tracer's shadow slots
// held no ray (no light sampled, or one behind the surface: half of them on the Cornell box),
// and asking Embree about them cost a call and a root-node test each (docs/host-path-tracer.md,
// "Empty shadow rays skipped; per-frame fills").
std::size_t occluded_span(RTCScene scene, const Ray* rays, std::uint8_t* occluded,
                          std::size_t count, RayMode mode) {
  const auto has_segment = [&](std::size_t i) { return rays[i].tmin <= rays[i].tmax; };
  std::size_t queried = 0;
  if (mode == RayMode::Stream) {
    RTCIntersectContext context = intersect_context(RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT);
    alignas(64) RTCRay chunk[kStreamChunk];
    std::uint32_t slot[kStreamChunk];
    std::size_t i = 0;
    while (i < count) {
      unsigned int n = 0;
      // Without a branch: every slot is written at chunk[n], and n moves on only past a
      // segment (whether a slot has one is a coin toss on most scenes, which a branch
      // mispredicts; docs/host-path-tracer.md, "Rays written in place").
      for (; i < count && n < kStreamChunk; ++i) {
        occluded[i] = 0;
        to_embree(rays[i], chunk[n]);
        slot[n] = static_cast<std::uint32_t>(i);
        n += has_segment(i) ? 1u : 0u;
      }
      if (n == 0) continue;
      rtcOccluded1M(scene, &context, chunk, n, sizeof(RTCRay));
      for (unsigned int k = 0; k < n; ++k)
        occluded[slot[k]] = std::isinf(chunk[k].tfar) && chunk[k].tfar < 0.0f ? 1 : 0;
      queried += n;
    }
    return queried;
  }
  if (mode == RayMode::Single) {
    RTCIntersectContext context = intersect_context(RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT);
    for (std::size_t i = 0; i != count; ++i) {
      occluded[i] = 0;
      if (!has_segment(i)) continue;
      RTCRay ray;
      to_embree(rays[i], ray);
      rtcOccluded1(scene, &context, &ray);
      occluded[i] = std::isinf(ray.tfar) && ray.tfar < 0.0f ? 1 : 0;
      ++queried;
    }
    return queried;
  }
  RTCIntersectContext context = intersect_context(RTC_INTERSECT_CONTEXT_FLAG_COHERENT);
  for (std::size_t first = 0; first < count; first += 8) {
    alignas(32) RTCRay8 ray;
    alignas(32) int valid[8];
    int lanes = 0;
    for (int lane = 0; lane < 8; ++lane) {
      const std::size_t i = first + lane;
      valid[lane] = i < count && has_segment(i) ? -1 : 0;
      lanes += valid[lane] != 0;
      set_ray_n(ray, lane, rays[i < count ? i : count - 1]);
    }
    if (lanes > 0) rtcOccluded8(valid, scene, &context, &ray);
    queried += static_cast<std::size_t>(lanes);
    for (int lane = 0; lane < 8; ++lane) {
      const std::size_t i = first + lane;
      if (i >= count) break;
      occluded[i] = valid[lane] != 0 && std::isinf(ray.tfar[lane]) && ray.tfar[lane] < 0.0f ? 1 : 0;
    }
  }
  return queried;
}

}  // namespace

std::size_t EmbreeScene::occluded(const Ray* rays, std::uint8_t* occluded, std::size_t count,
                                  RayMode mode) const {
  return over_spans(count, mode, [&](std::size_t first, std::size_t n) {
    return occluded_span(impl_->scene, rays + first, occluded + first, n, mode);
  });
}

std::size_t EmbreeScene::occluded_lists(const Ray* rays, std::uint8_t* occluded, std::size_t stride,
                                        const std::uint32_t* counts, std::size_t lists,
                                        RayMode mode) const {
  return over_lists(stride, counts, lists, [&](std::size_t first, std::size_t n) {
    return occluded_span(impl_->scene, rays + first, occluded + first, n, mode);
  });
}

}  // namespace rtpg
