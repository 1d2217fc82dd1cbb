// The smallest renderer that uses rtpg's guiding library: a camera above a white Lambertian
// floor lit by a small bright sphere, traced analytically on the host (no Embree). Each frame
// it fills the G-buffer, lets the Guider reproject, sample and train, traces the first bounce
// itself and writes one VPL per pixel (the layout of include/rtpg/guiding_layout.h). It prints
// the relMSE of the 1-sample frames against the exact answer with and without guiding.
//
// Usage: minimal_guiding [frames] [size] [device]   (defaults: 32, 96, $RTPG_DEVICE or GPU/CPU)
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <vector>

#include "rtpg/cl_runtime.h"
#include "rtpg/guider.h"
#include "rtpg/vpl_packing.h"

namespace {

// Host element types of the layout's channels: the header's channel lists do the rest.
namespace host {
using float4 = std::array<float, 4>;
using float2 = std::array<float, 2>;
using uint = std::uint32_t;
using uint4 = std::array<std::uint32_t, 4>;
}  // namespace host
#define HOST_CHANNEL(name, type, bytes) std::vector<host::type> name;
struct HostGBuffer {
  PG_GBUFFER_CHANNELS(HOST_CHANNEL)
};
struct HostVpls {
  PG_VPL_CHANNELS(HOST_CHANNEL)
};
struct HostSamples {
  PG_SAMPLE_CHANNELS(HOST_CHANNEL)
};
#undef HOST_CHANNEL

struct Vec3 {
  float x, y, z;
};
Vec3 operator-(Vec3 a, Vec3 b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
Vec3 operator+(Vec3 a, Vec3 b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
Vec3 operator*(Vec3 a, float s) {
  return {a.x * s, a.y * s, a.z * s};
}
float dot(Vec3 a, Vec3 b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
Vec3 normalize(Vec3 a) {
  return a * (1.0f / std::sqrt(dot(a, a)));
}

// The scene: floor z = 0 seen from `eye`, a sphere light of radius r and radiance Le.
constexpr float kPi = 3.14159265358979f;
constexpr Vec3 kEye = {0.0f, 0.0f, 3.0f};
constexpr Vec3 kLight = {0.9f, 0.4f, 1.0f};
constexpr float kRadius = 0.15f, kLe = 20.0f, kAlbedo = 0.8f;

Vec3 floor_point(int x, int y, int size) {
  return {2.0f * (x + 0.5f) / size - 1.0f, 2.0f * (y + 0.5f) / size - 1.0f, 0.0f};
}

// Exact radiance leaving a floor point towards the eye: a Lambertian floor under a sphere
// that is wholly above its horizon receives E = pi Le sin^2(alpha) cos(theta).
float exact(Vec3 p) {
  const Vec3 to = kLight - p;
  const float d2 = dot(to, to);
  return kAlbedo * kLe * (kRadius * kRadius / d2) * (to.z / std::sqrt(d2));
}

// Distance along the unit ray o + t d to the light sphere, or -1.
float hit_light(Vec3 o, Vec3 d) {
  const Vec3 oc = o - kLight;
  const float b = dot(oc, d), c = dot(oc, oc) - kRadius * kRadius, disc = b * b - c;
  if (disc < 0.0f) return -1.0f;
  const float t = -b - std::sqrt(disc);
  return t > 0.0f ? t : -1.0f;
}

// relMSE of 1-sample frames, averaged over the last 8 of `frames`; guided or BSDF sampling.
double run(rtpg::ClRuntime& rt, int size, int frames, bool guided) {
  const std::size_t n = static_cast<std::size_t>(size) * size;
  rtpg::Guider guider(rt, size, size);
  const rtpg::GuiderGBuffer gbuffer = rtpg::make_guider_gbuffer(rt.context(), size, size);
  const rtpg::GuiderVpls vpls = rtpg::make_guider_vpls(rt.context(), size, size);
  const rtpg::GuiderSamples samples = rtpg::make_guider_samples(rt.context(), size, size);

  // A static camera: the same G-buffer every frame, zero motion.
  HostGBuffer g{std::vector<host::float4>(n),   std::vector<host::float4>(n),
                std::vector<host::float4>(n),   std::vector<host::float4>(n),
                std::vector<host::float4>(n),   std::vector<host::uint>(n, 0u),
                std::vector<host::uint>(n, 1u), std::vector<host::float2>(n, {0.0f, 0.0f})};
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * size + x;
      const Vec3 p = floor_point(x, y, size), v = normalize(kEye - p);
      g.position_depth[i] = {p.x, p.y, p.z, std::sqrt(dot(kEye - p, kEye - p))};
      g.shading_normal[i] = {0.0f, 0.0f, 1.0f, 0.0f};
      g.view_dir[i] = {v.x, v.y, v.z, 0.0f};
      g.base_color_roughness[i] = {kAlbedo, kAlbedo, kAlbedo, 1.0f};
      g.metallic_specular[i] = {0.0f, 0.0f, 0.0f, 0.0f};  // F0 = 0: Lambert alone
    }
  rtpg::enqueue_upload(rt.queue(), g, gbuffer);
  rt.queue().finish();

  HostSamples s{std::vector<host::float4>(n), std::vector<host::uint>(n),
                std::vector<host::float4>(n), std::vector<host::float2>(n)};
  HostVpls v{std::vector<host::float4>(n), std::vector<host::uint4>(n)};
  double error_sum = 0.0;
  for (int frame = 0; frame < frames; ++frame) {
    if (frame > 0) guider.reproject(gbuffer, gbuffer);
    guider.sample(gbuffer, 7u, static_cast<std::uint32_t>(frame), 0u, samples);
    rtpg::enqueue_download(rt.queue(), samples, s);
    rt.queue().finish();
    double error = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      const Vec3 p = {g.position_depth[i][0], g.position_depth[i][1], 0.0f};
      const Vec3 d = {s.direction_pdf[i][0], s.direction_pdf[i][1], s.direction_pdf[i][2]};
      const float pdf = s.direction_pdf[i][3];
      const float t = pdf > 0.0f && d.z > 0.0f ? hit_light(p, d) : -1.0f;
      // One-sample estimate of the outgoing radiance: f cos L / pdf, f = albedo / pi.
      const float estimate = t > 0.0f ? kAlbedo / kPi * d.z * kLe / pdf : 0.0f;
      const double ref = exact(p);
      error += (estimate - ref) * (estimate - ref) / (ref * ref + 0.01);
      // The VPL: where the bounce landed, its densities in area measure there (the strategy's:
      // the BSDF's for a BSDF sample, cos / pi for Lambert; and the whole mixture's, pdf), the
      // normal there, the radiance it sends back and its PG_VPL_* bits, packed
      // (include/rtpg/guiding_layout.h, include/rtpg/vpl_packing.h).
      const std::uint32_t strategy = s.strategy[i];
      const std::uint32_t info =
          (t > 0.0f ? PG_VPL_VALID : 0u) | (strategy << PG_VPL_STRATEGY_SHIFT);
      if (t > 0.0f) {
        const Vec3 y = p + d * t, ny = normalize(y - kLight);
        const float source_pdf = strategy == PG_STRATEGY_BSDF ? d.z / kPi : pdf;
        const float to_area = std::fabs(dot(ny, d)) / (t * t);
        v.position[i] = {y.x, y.y, y.z, source_pdf * to_area};
        v.normal_radiance[i] = rtpg::pack_vpl_normal_radiance({ny.x, ny.y, ny.z}, pdf * to_area,
                                                              {kLe, kLe, kLe}, info);
      } else {
        v.position[i] = {0.0f, 0.0f, 0.0f, 0.0f};
        v.normal_radiance[i] =
            rtpg::pack_vpl_normal_radiance({0.0f, 0.0f, 0.0f}, 0.0f, {0.0f, 0.0f, 0.0f}, info);
      }
    }
    if (frame >= frames - 8) error_sum += error / static_cast<double>(n);
    if (guided) {
      rtpg::enqueue_upload(rt.queue(), v, vpls);
      rt.queue().finish();
      guider.train(gbuffer, vpls, 7u, static_cast<std::uint32_t>(frame));
    }
  }
  return error_sum / 8.0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const int frames = argc > 1 ? std::atoi(argv[1]) : 32;
    const int size = argc > 2 ? std::atoi(argv[2]) : 96;
    if (frames < 8 || size < 1) {
      std::fprintf(stderr, "minimal_guiding: need frames >= 8 and size >= 1\n");
      return 2;
    }
    rtpg::request_pinned_cpu_device_threads();  // before the first OpenCL call
    rtpg::ClRuntime rt(argc > 3 ? argv[3] : "");
    const double plain = run(rt, size, frames, false);
    const double guided = run(rt, size, frames, true);
    std::printf("minimal_guiding on %s: %dx%d, relMSE of 1-spp frames %d-%d\n",
                rt.info().device_name.c_str(), size, size, frames - 7, frames);
    std::printf("  BSDF sampling: %.4f\n  guided:        %.4f  (%.2fx lower)\n", plain, guided,
                plain / guided);
    return std::isfinite(guided) && guided < plain ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "minimal_guiding: %s\n", e.what());
    return 1;
  }
}
