// The guiding kernels (reproject.cl, sample.cl, train.cl) through the guider library, against a
// host implementation of the same per-pixel step that calls the same shared functions
// (kernels/shared/*.h compiled as C++); reprojection geometry under a moving camera; misuse of
// the public header; and one test that uses include/rtpg/guider.h alone. They run on whatever
// device RTPG_DEVICE or the default picks (PoCL in CI) and shrink their images under Oclgrind.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "cl/cl_runtime.h"
#include "guiding/guiding_params.h"
#include "rtpg/guider.h"
#include "shared/guiding_pixel.h"
#include "shared/pmm.h"
#include "shared/pmm_train.h"
#include "shared/rng.h"
#include "shared/vpl.h"

namespace rtpg {
namespace {

namespace sh = rtpg::shared;
using sh::float2;
using sh::float3;
using sh::float4;

// Oclgrind simulates each work-item (about 100x slower than PoCL): keep its images small.
bool simulated(const ClRuntime& rt) {
  return rt.info().platform_name.find("Oclgrind") != std::string::npos;
}

// ---- host-side buffers ---------------------------------------------------------------------

struct HostGBuffer {
  int width = 0, height = 0;
  std::vector<float4> position_depth, shading_normal, view_dir, base_color_roughness,
      metallic_specular;
  std::vector<std::uint32_t> flags, material;
  std::vector<float2> motion;

  HostGBuffer(int w, int h)
      : width(w),
        height(h),
        position_depth(n()),
        shading_normal(n()),
        view_dir(n()),
        base_color_roughness(n()),
        metallic_specular(n()),
        flags(n()),
        material(n()),
        motion(n()) {}
  std::size_t n() const { return static_cast<std::size_t>(width) * height; }
};

struct HostVpls {
  std::vector<float4> position, normal, radiance_info;
};

template <typename T>
cl::Buffer upload(ClRuntime& rt, const std::vector<T>& v) {
  return cl::Buffer(rt.context(), CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, v.size() * sizeof(T),
                    const_cast<T*>(v.data()));
}

GuiderGBuffer upload(ClRuntime& rt, const HostGBuffer& g) {
  GuiderGBuffer d;
  d.position_depth = upload(rt, g.position_depth);
  d.shading_normal = upload(rt, g.shading_normal);
  d.view_dir = upload(rt, g.view_dir);
  d.base_color_roughness = upload(rt, g.base_color_roughness);
  d.metallic_specular = upload(rt, g.metallic_specular);
  d.flags = upload(rt, g.flags);
  d.material = upload(rt, g.material);
  d.motion = upload(rt, g.motion);
  return d;
}

GuiderVpls upload(ClRuntime& rt, const HostVpls& v) {
  return {upload(rt, v.position), upload(rt, v.normal), upload(rt, v.radiance_info)};
}

// The guider's state layout: 8 floats per pixel, s0.xyzw then s1.xyzw.
sh::pg_pmm_state state_at(const std::vector<float>& s, std::size_t i) {
  sh::pg_pmm_state r;
  r.s0 = float4(s[8 * i], s[8 * i + 1], s[8 * i + 2], s[8 * i + 3]);
  r.s1 = float4(s[8 * i + 4], s[8 * i + 5], s[8 * i + 6], s[8 * i + 7]);
  return r;
}

void set_state(std::vector<float>& s, std::size_t i, const sh::pg_pmm_state& r) {
  for (int c = 0; c < 4; ++c) {
    s[8 * i + c] = r.s0[c];
    s[8 * i + 4 + c] = r.s1[c];
  }
}

// A state with mean (mx, my), raw covariance (sxx, syy, sxy), pi = S0 / W and k epochs.
sh::pg_pmm_state make_state(float mx, float my, float sxx, float syy, float sxy, float pi, float k,
                            float s0) {
  sh::pg_pmm_state s;
  s.s0 = float4(s0 / pi, s0, s0 * mx, s0 * my);
  s.s1 = float4(s0 * (sxx + mx * mx), s0 * (syy + my * my), s0 * (sxy + mx * my), k);
  return s;
}

// ---- random inputs -------------------------------------------------------------------------

struct Random {
  std::mt19937 gen;
  explicit Random(unsigned seed) : gen(seed) {}
  float uniform(float lo = 0.0f, float hi = 1.0f) {
    return std::uniform_real_distribution<float>(lo, hi)(gen);
  }
  float3 unit() {
    std::normal_distribution<float> n(0.0f, 1.0f);
    return sh::normalize(float3(n(gen), n(gen), n(gen)));
  }
  // A unit vector within `max_deg` degrees of n (at least min_deg away).
  float3 tilt(float3 n, float min_deg, float max_deg) {
    const float3 t = sh::normalize(sh::cross(n, unit()));
    const float a = uniform(min_deg, max_deg) * PG_PI / 180.0f;
    return sh::normalize(n * std::cos(a) + t * std::sin(a));
  }
};

// Random states: a fifth without a model (k = 0), some at k_max, a few non-finite (the
// kernels must not carry those).
std::vector<float> random_states(Random& r, std::size_t n, float k_max, bool with_nan) {
  std::vector<float> s(8 * n, 0.0f);
  for (std::size_t i = 0; i < n; ++i) {
    const float c = r.uniform();
    if (c < 0.2f) continue;  // initial state
    if (with_nan && c < 0.23f) {
      set_state(s, i, make_state(0.5f, 0.5f, 0.01f, 0.01f, 0.0f, 0.5f, 3.0f, 1.0f));
      s[8 * i + 2 + static_cast<int>(r.uniform(0.0f, 5.99f))] =
          r.uniform() < 0.5f ? std::numeric_limits<float>::quiet_NaN()
                             : std::numeric_limits<float>::infinity();
      continue;
    }
    const float sx = r.uniform(0.02f, 0.3f), sy = r.uniform(0.02f, 0.3f),
                rho = r.uniform(-0.95f, 0.95f);
    const float k = c < 0.35f ? k_max : std::floor(r.uniform(1.0f, k_max + 0.99f));
    set_state(s, i,
              make_state(r.uniform(0.03f, 0.97f), r.uniform(0.03f, 0.97f), sx * sx, sy * sy,
                         rho * sx * sy, r.uniform(0.03f, 0.99f), std::min(k, k_max),
                         std::pow(10.0f, r.uniform(-2.0f, 2.0f))));
  }
  return s;
}

// Surface pixels of a bumpy floor seen from above, with every kind of pixel guiding skips
// (sky, emitter, delta, transmissive, roughness at or below roughness_skip) and back-facing
// view directions.
HostGBuffer random_gbuffer(Random& r, int w, int h) {
  HostGBuffer g(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * w + x;
      g.position_depth[i] =
          float4(2.0f * x / w + r.uniform(-0.01f, 0.01f), 2.0f * y / h + r.uniform(-0.01f, 0.01f),
                 r.uniform(-0.05f, 0.05f), r.uniform(1.0f, 5.0f));
      const float3 n = r.uniform() < 0.1f ? r.unit() : r.tilt(float3(0, 0, 1), 0.0f, 45.0f);
      g.shading_normal[i] = float4(n.x, n.y, n.z, 0.0f);
      const float3 v = r.uniform() < 0.05f ? r.unit() : r.tilt(n, 0.0f, 85.0f);
      g.view_dir[i] = float4(v.x, v.y, v.z, 0.0f);
      const float rough = r.uniform() < 0.1f ? r.uniform(0.0f, 0.05f) : r.uniform(0.06f, 1.0f);
      g.base_color_roughness[i] = float4(r.uniform(), r.uniform(), r.uniform(), rough);
      const float m = r.uniform();
      const float spec[] = {0.0f, 0.04f, 0.5f};
      g.metallic_specular[i] = float4(m < 0.3f ? 1.0f : (m < 0.7f ? 0.0f : r.uniform()),
                                      spec[static_cast<int>(r.uniform(0.0f, 2.99f))], 0.0f, 0.0f);
      const float f = r.uniform();
      g.flags[i] = f < 0.08f   ? PG_GBUF_SKY
                   : f < 0.12f ? PG_GBUF_EMITTER
                   : f < 0.16f ? PG_GBUF_DELTA
                   : f < 0.20f ? PG_GBUF_TRANSMISSIVE
                   : f < 0.21f ? (PG_GBUF_EMITTER | PG_GBUF_DELTA)
                               : 0u;
      g.material[i] = static_cast<std::uint32_t>(r.uniform(0.0f, 3.99f));
      g.motion[i] = float2(0.0f, 0.0f);
    }
  return g;
}

// VPLs above the floor: invalid ones, distant ones (a direction and a solid-angle density),
// ones produced by the guide strategy (which must not train), facing away, zero density,
// zero and very bright radiance.
HostVpls random_vpls(Random& r, std::size_t n) {
  HostVpls v;
  for (std::size_t i = 0; i < n; ++i) {
    std::uint32_t info = r.uniform() < 0.9f ? PG_VPL_VALID : 0u;
    const float s = r.uniform();
    const std::uint32_t strategy =
        s < 0.7f ? PG_STRATEGY_BSDF : (s < 0.95f ? PG_STRATEGY_GUIDE : PG_STRATEGY_NONE);
    info |= strategy << PG_VPL_STRATEGY_SHIFT;
    if (r.uniform() < 0.15f) {
      info |= PG_VPL_DISTANT;
      const float3 d = r.tilt(float3(0, 0, 1), 0.0f, 89.0f);
      v.position.push_back(float4(d.x, d.y, d.z, r.uniform(0.05f, 2.0f)));
    } else {
      const float pdf = r.uniform() < 0.05f ? 0.0f : std::pow(10.0f, r.uniform(-2.0f, 2.0f));
      v.position.push_back(
          float4(r.uniform(-1.0f, 3.0f), r.uniform(-1.0f, 3.0f), r.uniform(0.3f, 2.0f), pdf));
    }
    const float3 nrm = r.uniform() < 0.8f ? r.tilt(float3(0, 0, -1), 0.0f, 80.0f) : r.unit();
    v.normal.push_back(float4(nrm.x, nrm.y, nrm.z, 0.0f));
    const float l = r.uniform();
    const float scale = l < 0.1f ? 0.0f : (l < 0.15f ? 1000.0f : 5.0f);
    v.radiance_info.push_back(float4(scale * r.uniform(), scale * r.uniform(), scale * r.uniform(),
                                     static_cast<float>(info)));
  }
  return v;
}

// ---- host reference: the kernels' per-pixel steps ------------------------------------------

// What reprojection did with a pixel.
enum Outcome { kSkipped, kOutside, kRejected, kCopied, kReframed };

// reproject.cl.
std::vector<float> host_reproject(const std::vector<float>& prev_state, const HostGBuffer& prev,
                                  const HostGBuffer& cur, const sh::pg_guiding_params& p,
                                  std::vector<int>& outcome) {
  const int w = cur.width, h = cur.height;
  std::vector<float> out(8 * cur.n(), 0.0f);
  outcome.assign(cur.n(), kSkipped);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * w + x;
      if (!sh::pg_guiding_applies(cur.flags[i], cur.base_color_roughness[i].w, p)) continue;
      const float2 mv = cur.motion[i];
      const int px = static_cast<int>(std::floor(static_cast<float>(x) + 0.5f + mv.x));
      const int py = static_cast<int>(std::floor(static_cast<float>(y) + 0.5f + mv.y));
      outcome[i] = kOutside;
      if (px < 0 || py < 0 || px >= w || py >= h) continue;
      const std::size_t j = static_cast<std::size_t>(py) * w + px;
      const float4 pp = cur.position_depth[i], q = prev.position_depth[j];
      const float3 n = sh::pg_float4_xyz(cur.shading_normal[i]);
      const float3 m = sh::pg_float4_xyz(prev.shading_normal[j]);
      const float3 d = sh::pg_float4_xyz(pp) - sh::pg_float4_xyz(q);
      const bool same = std::sqrt(sh::dot(d, d)) <= p.reproject_depth * std::fmax(pp.w, 1e-6f) &&
                        sh::dot(n, m) >= p.reproject_normal &&
                        prev.material[j] == cur.material[i] && q.w > 0.0f;
      outcome[i] = kRejected;
      if (!same) continue;
      sh::pg_pmm_state s = state_at(prev_state, j);
      outcome[i] = kCopied;
      if (sh::dot(n, m) < 0.99999f) {
        s = sh::pg_pmm_reframe(s, sh::pg_frame_from_normal(m), sh::pg_frame_from_normal(n));
        outcome[i] = kReframed;
      }
      if (sh::pg_pmm_state_finite(s)) set_state(out, i, s);
    }
  return out;
}

// sample.cl. pdf_spread[i] is how much the mixture pdf changes when the sampled direction
// moves by 2e-6 rad (about 30 ulp of a unit vector's components): near a sharp GGX peak
// (alpha down to 4e-4) D(h) depends on h.z through 1 - h.z^2 (1 - alpha^2), so a direction
// that is a few ulp off changes the pdf by tens of percent. That is conditioning, not error.
void host_sample(const std::vector<float>& state, const HostGBuffer& g, std::uint32_t seed,
                 std::uint32_t frame, std::uint32_t sample_index, const sh::pg_guiding_params& p,
                 std::vector<float4>& direction_pdf, std::vector<std::uint32_t>& strategy,
                 std::vector<float>& pdf_spread) {
  direction_pdf.assign(g.n(), float4(0.0f));
  strategy.assign(g.n(), 0u);
  pdf_spread.assign(g.n(), 0.0f);
  for (std::size_t i = 0; i < g.n(); ++i) {
    if ((g.flags[i] & PG_GBUF_SKY) != 0u) {
      direction_pdf[i] = float4(0.0f, 0.0f, 1.0f, 0.0f);
      strategy[i] = PG_STRATEGY_NONE;
      continue;
    }
    const float4 bcr = g.base_color_roughness[i];
    sh::pg_pmm_state s = sh::pg_pmm_initial_state();
    if (sh::pg_guiding_applies(g.flags[i], bcr.w, p)) s = state_at(state, i);
    const sh::pg_pmm_model model = sh::pg_pmm_model_from_state(s, p);
    const sh::pg_frame frame_x = sh::pg_frame_from_normal(sh::pg_float4_xyz(g.shading_normal[i]));
    const float3 wo = sh::pg_to_local(frame_x, sh::pg_float4_xyz(g.view_dir[i]));
    const sh::pg_lobes lobes =
        sh::pg_make_lobes(sh::pg_material_from_gbuffer(bcr, g.metallic_specular[i]), wo);
    sh::pg_rng rng = sh::pg_rng_make(seed, static_cast<std::uint32_t>(i), frame, sample_index, 1u);
    const float xi = sh::pg_rng_next(&rng), u1 = sh::pg_rng_next(&rng), u2 = sh::pg_rng_next(&rng);
    const sh::pg_pmm_sample_t smp = sh::pg_pmm_sample(model, lobes, wo, xi, u1, u2);
    const float3 w = sh::pg_to_world(frame_x, smp.wi);
    direction_pdf[i] = float4(w.x, w.y, w.z, smp.pdf);
    strategy[i] = smp.strategy;
    if (smp.pdf > 0.0f) {
      const sh::pg_frame around = sh::pg_frame_from_normal(smp.wi);
      for (const float3 d : {around.t, around.b, -around.t, -around.b}) {
        const float3 moved = sh::normalize(smp.wi + d * 2e-6f);
        const float change = std::fabs(sh::pg_pmm_pdf(model, lobes, wo, moved) - smp.pdf);
        pdf_spread[i] = std::max(pdf_spread[i], change);
      }
    }
  }
}

// train.cl (either variant: the local tile holds zeros outside the image, i.e. no VPL, which
// is what skipping those window cells does here).
std::vector<float> host_train(const std::vector<float>& state, const HostGBuffer& g,
                              const HostVpls& v, std::uint32_t seed, std::uint32_t frame,
                              const sh::pg_guiding_params& p, std::vector<int>& trained) {
  const int w = g.width, h = g.height;
  std::vector<float> out = state;
  trained.assign(g.n(), 0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const int i = y * w + x;
      const float4 bcr = g.base_color_roughness[i];
      if (!sh::pg_guiding_applies(g.flags[i], bcr.w, p)) continue;
      sh::pg_pmm_state s = state_at(state, i);
      sh::pg_train_pixel px;
      px.x = sh::pg_float4_xyz(g.position_depth[i]);
      px.frame = sh::pg_frame_from_normal(sh::pg_float4_xyz(g.shading_normal[i]));
      px.wo = sh::pg_to_local(px.frame, sh::pg_float4_xyz(g.view_dir[i]));
      px.lobes =
          sh::pg_make_lobes(sh::pg_material_from_gbuffer(bcr, g.metallic_specular[i]), px.wo);
      const int side = 2 * p.apron + 1;
      const int n = std::min(std::min(sh::pg_pmm_neighbour_count(s.s1.w, p), side * side),
                             PG_MAX_TRAIN_SAMPLES);
      sh::pg_rng rng = sh::pg_rng_make(seed, static_cast<std::uint32_t>(i), frame, 0u, 3u);
      const std::uint32_t start =
          sh::pg_rng_next_uint(&rng) % static_cast<std::uint32_t>(side * side);
      float4 samples[PG_MAX_TRAIN_SAMPLES];
      int kept = 0;
      for (int k = 0; k < n; ++k) {
        const int c = sh::pg_train_window_index(start, k, p);
        const int sx = x + c % side - p.apron, sy = y + c / side - p.apron;
        if (sx < 0 || sy < 0 || sx >= w || sy >= h) continue;
        const int j = sy * w + sx;
        kept += sh::pg_train_sample_from_vpl(px, v.position[j], v.normal[j], v.radiance_info[j],
                                             &samples[kept]);
      }
      int updated = 0;
      s = sh::pg_pmm_train(s, samples, kept, p, static_cast<float>(n), p.em_passes, &updated);
      set_state(out, i, s);
      trained[i] = updated;
    }
  return out;
}

// ---- comparison ----------------------------------------------------------------------------

bool same_bits(float a, float b) {
  if (std::isnan(a) || std::isnan(b)) return std::isnan(a) && std::isnan(b);
  return std::memcmp(&a, &b, sizeof a) == 0;
}

// Whether two states agree: k exactly; W and S0 to `rel`; the moments to `rel` of their own
// size plus `rel` of S0 (they are S0 times numbers in [0, 1], and a raw covariance entry is a
// difference of such products, so its absolute error scales with S0, not with itself).
bool states_agree(const sh::pg_pmm_state& a, const sh::pg_pmm_state& b, float rel) {
  const float va[8] = {a.s0.x, a.s0.y, a.s0.z, a.s0.w, a.s1.x, a.s1.y, a.s1.z, a.s1.w};
  const float vb[8] = {b.s0.x, b.s0.y, b.s0.z, b.s0.w, b.s1.x, b.s1.y, b.s1.z, b.s1.w};
  const float scale = std::max(std::fabs(a.s0.y), std::fabs(b.s0.y));
  for (int c = 0; c < 8; ++c) {
    if (same_bits(va[c], vb[c])) continue;
    if (!std::isfinite(va[c]) || !std::isfinite(vb[c])) return false;
    if (c == 7) return false;  // k: small integers, exact on any device
    const float mag = std::max(std::fabs(va[c]), std::fabs(vb[c])) + (c >= 2 ? scale : 0.0f);
    if (std::fabs(va[c] - vb[c]) > rel * mag) return false;
  }
  return true;
}

std::string describe(const sh::pg_pmm_state& s) {
  char buf[256];
  std::snprintf(buf, sizeof buf, "(%g %g %g %g | %g %g %g %g)", s.s0.x, s.s0.y, s.s0.z, s.s0.w,
                s.s1.x, s.s1.y, s.s1.z, s.s1.w);
  return buf;
}

// Local sizes the guider runs at: the two common ones and one that is not a power of two;
// image sizes are not multiples of them (the padding work-items must do nothing, and the
// local tile must be filled where they stand). Each with its own neighbourhood radius.
struct KernelCase {
  int local_x, local_y;
  int width, height;
  int apron;
};

std::vector<KernelCase> kernel_cases(const ClRuntime& rt) {
  if (simulated(rt)) return {{8, 8, 13, 9, 2}, {16, 16, 19, 5, 1}, {12, 6, 14, 8, 3}};
  return {{8, 8, 45, 29, 3}, {16, 16, 53, 37, 2}, {12, 6, 50, 31, 1}};
}

std::string name(const KernelCase& c) {
  return std::to_string(c.local_x) + "x" + std::to_string(c.local_y) + " on " +
         std::to_string(c.width) + "x" + std::to_string(c.height) + " apron " +
         std::to_string(c.apron);
}

// ---- reproject -----------------------------------------------------------------------------

// The previous frame's G-buffer is random; every pixel of this frame points through its motion
// vector at a previous pixel and is built from it as a case of the rejection rules, with
// margins far from every threshold: the same surface (position within 1% of the depth, the
// normal equal or tilted by 3-15 degrees so that the state is reframed), a position 30% of the
// depth away, a normal tilted by 40-90 degrees, another material, a previous pixel with no
// depth, or motion out of the image. Sub-pixel motion stays 0.1 px away from pixel borders.
void make_reprojection_pair(Random& r, int w, int h, HostGBuffer& prev, HostGBuffer& cur) {
  prev = random_gbuffer(r, w, h);
  cur = random_gbuffer(r, w, h);  // keeps its own flags, roughness and view directions
  for (std::size_t j = 0; j < prev.n(); ++j)
    if (r.uniform() < 0.03f) prev.position_depth[j].w = 0.0f;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * w + x;
      int dx = static_cast<int>(std::floor(r.uniform(-3.0f, 4.0f)));
      int dy = static_cast<int>(std::floor(r.uniform(-3.0f, 4.0f)));
      if (r.uniform() < 0.05f) dx += (r.uniform() < 0.5f ? -1 : 1) * (w + 2);
      cur.motion[i] = float2(static_cast<float>(dx) + r.uniform(-0.4f, 0.4f),
                             static_cast<float>(dy) + r.uniform(-0.4f, 0.4f));
      const int px = std::clamp(x + dx, 0, w - 1), py = std::clamp(y + dy, 0, h - 1);
      const std::size_t j = static_cast<std::size_t>(py) * w + px;
      const float4 q = prev.position_depth[j];
      const float depth = std::max(q.w, 1.0f);
      const float3 m = sh::pg_float4_xyz(prev.shading_normal[j]);
      float3 pos = sh::pg_float4_xyz(q) + r.unit() * (0.01f * depth * r.uniform());
      float3 n = r.uniform() < 0.5f ? m : r.tilt(m, 3.0f, 15.0f);
      std::uint32_t material = prev.material[j];
      const float c = r.uniform();
      if (c < 0.1f)
        pos = pos + r.unit() * (0.3f * depth);
      else if (c < 0.2f)
        n = r.tilt(m, 40.0f, 90.0f);
      else if (c < 0.3f)
        material = (material + 1u) % 4u;
      cur.position_depth[i] = float4(pos.x, pos.y, pos.z, depth);
      cur.shading_normal[i] = float4(n.x, n.y, n.z, 0.0f);
      cur.material[i] = material;
    }
}

// Device and host agree: bit for bit where the state is copied or reset; within 1e-3 relative
// (of the value, plus of S0 for the moments) where it is reframed. The reframe maps the mean
// through sin/cos/atan2/sqrt, which OpenCL allows to be 4-6 ulp off the host's libm, and builds
// the covariance from a Jacobian by central differences of step 1e-3 (an error of a few ulp of
// 0.5 in a probe, 3e-7, becomes 3e-4 in the Jacobian). A reframed mean that lands within ulps of
// the horizon threshold (w.z = 1e-4) may be carried on one side and dropped on the other:
// such pixels are counted and bounded (none are expected at these sizes).
TEST(GuidingKernels, ReprojectMatchesHostReference) {
  ClRuntime rt;
  Random r(101);
  std::size_t pixels = 0, count[5] = {0, 0, 0, 0, 0};
  for (const KernelCase& kc : kernel_cases(rt)) {
    GuidingConfig config;
    config.local_x = kc.local_x;
    config.local_y = kc.local_y;
    config.apron = kc.apron;
    const sh::pg_guiding_params p = make_guiding_params(config);
    Guider guider(rt, kc.width, kc.height, config);
    HostGBuffer prev(1, 1), cur(1, 1);
    make_reprojection_pair(r, kc.width, kc.height, prev, cur);
    const std::vector<float> prev_state = random_states(r, prev.n(), p.k_max, true);
    std::vector<int> outcome;
    const std::vector<float> expected = host_reproject(prev_state, prev, cur, p, outcome);
    guider.write_state(prev_state);
    guider.reproject(upload(rt, cur), upload(rt, prev));
    std::vector<float> got;
    guider.read_state(got);
    ASSERT_EQ(got.size(), expected.size());
    std::size_t mismatched = 0;
    for (std::size_t i = 0; i < cur.n(); ++i) {
      const sh::pg_pmm_state e = state_at(expected, i), d = state_at(got, i);
      bool ok = true;
      const bool reframed = outcome[i] == kReframed;
      if (reframed) {
        ok = states_agree(e, d, 1e-3f);
      } else {
        for (int c = 0; c < 8; ++c) ok = ok && same_bits(expected[8 * i + c], got[8 * i + c]);
      }
      if (!ok) {
        ++mismatched;
        ADD_FAILURE() << name(kc) << " pixel " << i << (reframed ? " (reframed)" : "") << ": host "
                      << describe(e) << " device " << describe(d);
      }
      ++count[outcome[i]];
    }
    pixels += cur.n();
    EXPECT_EQ(mismatched, 0u) << name(kc);
  }
  // The inputs exercised every path.
  for (int o = kSkipped; o <= kReframed; ++o) EXPECT_GT(count[o] * 30, pixels) << "outcome " << o;
  std::printf(
      "[ info     ] reproject: %zu pixels: %zu skipped, %zu outside, %zu rejected, %zu "
      "copied, %zu reframed\n",
      pixels, count[0], count[1], count[2], count[3], count[4]);
}

// ---- sample --------------------------------------------------------------------------------

// Device and host agree on every pixel's direction (1e-4 per component: sin/cos/log/sqrt of
// the Gaussian and GGX samplers may be a few ulp off) and mixture pdf (1e-4 relative: exp of
// a quadratic form q changes by q * few ulp; plus twice the pdf's change under a 2e-6 rad move
// of the direction, see host_sample), and the strategy is the same. The strategy can
// differ only where xi is within ulps of pi or where a Gaussian sample lies within ulps of the
// square's border (pdf 0 on one side): both have probability ~1e-6 per pixel, so the test
// allows one such pixel in all the images.
TEST(GuidingKernels, SampleMatchesHostReference) {
  ClRuntime rt;
  Random r(202);
  std::size_t pixels = 0, guided = 0, near_threshold = 0, ill_conditioned = 0;
  for (const KernelCase& kc : kernel_cases(rt)) {
    GuidingConfig config;
    config.local_x = kc.local_x;
    config.local_y = kc.local_y;
    const sh::pg_guiding_params p = make_guiding_params(config);
    Guider guider(rt, kc.width, kc.height, config);
    const HostGBuffer g = random_gbuffer(r, kc.width, kc.height);
    const GuiderGBuffer dg = upload(rt, g);
    const std::vector<float> state = random_states(r, g.n(), p.k_max, false);
    guider.write_state(state);
    cl::Buffer dir(rt.context(), CL_MEM_READ_WRITE, g.n() * 16);
    cl::Buffer strat(rt.context(), CL_MEM_READ_WRITE, g.n() * 4);
    for (std::uint32_t frame = 0; frame < 3; ++frame) {
      const std::uint32_t seed = 7u + frame * 13u;
      guider.sample(dg, seed, frame, frame % 2u, {dir, strat});
      std::vector<float4> got_dir(g.n()), want_dir;
      std::vector<std::uint32_t> got_strategy(g.n()), want_strategy;
      std::vector<float> spread;
      rt.queue().enqueueReadBuffer(dir, CL_TRUE, 0, g.n() * 16, got_dir.data());
      rt.queue().enqueueReadBuffer(strat, CL_TRUE, 0, g.n() * 4, got_strategy.data());
      host_sample(state, g, seed, frame, frame % 2u, p, want_dir, want_strategy, spread);
      for (std::size_t i = 0; i < g.n(); ++i) {
        const float4 a = want_dir[i], b = got_dir[i];
        const bool pdf_zero_differs = (a.w > 0.0f) != (b.w > 0.0f);
        if (want_strategy[i] != got_strategy[i] || pdf_zero_differs) {
          ++near_threshold;
          continue;
        }
        guided += want_strategy[i] == PG_STRATEGY_GUIDE;
        if (a.w == 0.0f) continue;  // no sample: the direction is a placeholder
        const std::string what =
            name(kc) + " frame " + std::to_string(frame) + " pixel " + std::to_string(i);
        EXPECT_NEAR(b.x, a.x, 1e-4f) << what;
        EXPECT_NEAR(b.y, a.y, 1e-4f) << what;
        EXPECT_NEAR(b.z, a.z, 1e-4f) << what;
        EXPECT_NEAR(b.w, a.w, 1e-4f * a.w + 2.0f * spread[i]) << what;
        ill_conditioned += spread[i] > 1e-4f * a.w;
      }
      pixels += g.n();
    }
  }
  EXPECT_LE(near_threshold, 1u) << "of " << pixels << " pixels";
  EXPECT_GT(guided, pixels / 10);  // the Gaussian branch was exercised
  // The spread allowance is for sharp lobes only, not a blanket tolerance.
  EXPECT_LT(ill_conditioned * 10, pixels);
  std::printf(
      "[ info     ] sample: %zu pixels, %zu guided, %zu near a threshold, %zu with an "
      "ill-conditioned pdf\n",
      pixels, guided, near_threshold, ill_conditioned);
}

// ---- train ---------------------------------------------------------------------------------

// Device and host agree after one EM step per pixel, for both variants of the kernel (VPL tile
// in local memory and direct global reads), which must also agree bit for bit with each other
// (the same arithmetic on the same VPLs). Tolerance 1e-4 relative (of the value, plus of S0 for
// the moments): the step size uses exp and log (3 ulp each in OpenCL), the E-step exp of a
// quadratic form, and the device may contract a*b+c into fma. A pixel may differ beyond that
// only where a decision flips on a few-ulp difference: a responsibility at the re-seeding
// threshold (gamma = 1e-3) or a weight at max_weight. The bound allows 0.1% of the pixels.
TEST(GuidingKernels, TrainMatchesHostReferenceInBothMemoryVariants) {
  ClRuntime rt;
  Random r(303);
  std::size_t pixels = 0, trained_total = 0, off = 0;
  for (const KernelCase& kc : kernel_cases(rt)) {
    const HostGBuffer g = random_gbuffer(r, kc.width, kc.height);
    const HostVpls v = random_vpls(r, g.n());
    const GuiderGBuffer dg = upload(rt, g);
    const GuiderVpls dv = upload(rt, v);
    GuidingConfig config;
    config.local_x = kc.local_x;
    config.local_y = kc.local_y;
    config.apron = kc.apron;
    const sh::pg_guiding_params p = make_guiding_params(config);
    std::vector<float> state = random_states(r, g.n(), p.k_max, false);
    std::vector<float> per_variant[2];
    for (int variant = 0; variant < 2; ++variant) {
      config.train_memory =
          variant == 0 ? GuidingConfig::TrainMemory::Local : GuidingConfig::TrainMemory::Global;
      Guider guider(rt, kc.width, kc.height, config);
      ASSERT_EQ(guider.train_uses_local_memory(), variant == 0);
      std::vector<float> s = state;
      // Two frames: the second starts from the first's result (models seeded at k = 0 train on).
      for (std::uint32_t frame = 0; frame < 2; ++frame) {
        const std::uint32_t seed = 11u + frame;
        std::vector<int> trained;
        const std::vector<float> expected = host_train(s, g, v, seed, frame, p, trained);
        guider.write_state(s);
        guider.train(dg, dv, seed, frame);
        std::vector<float> got;
        guider.read_state(got);
        std::size_t mismatched = 0;
        for (std::size_t i = 0; i < g.n(); ++i) {
          if (states_agree(state_at(expected, i), state_at(got, i), 1e-4f)) continue;
          ++mismatched;
          if (mismatched <= 5)
            ADD_FAILURE() << name(kc) << (variant == 0 ? " local" : " global") << " frame " << frame
                          << " pixel " << i << ": host " << describe(state_at(expected, i))
                          << " device " << describe(state_at(got, i));
        }
        off += mismatched;
        std::size_t host_trained = 0;
        for (int t : trained) host_trained += t != 0;
        const std::size_t device_trained = guider.count_trained();
        EXPECT_LE(device_trained > host_trained ? device_trained - host_trained
                                                : host_trained - device_trained,
                  mismatched)
            << name(kc);
        trained_total += host_trained;
        pixels += g.n();
        s = expected;  // continue from the host's result: device differences do not compound
        if (frame == 0 && variant == 0) per_variant[0] = got;
        if (frame == 0 && variant == 1) per_variant[1] = got;
      }
    }
    ASSERT_EQ(per_variant[0].size(), per_variant[1].size());
    std::size_t differ = 0;
    for (std::size_t c = 0; c < per_variant[0].size(); ++c)
      differ += !same_bits(per_variant[0][c], per_variant[1][c]);
    EXPECT_EQ(differ, 0u) << name(kc) << ": local and global variants differ";
  }
  EXPECT_LE(off * 1000, pixels) << off << " of " << pixels << " pixels differ";
  EXPECT_GT(trained_total, pixels / 4);  // the EM step ran on many pixels
  std::printf("[ info     ] train: %zu pixel steps, %zu trained, %zu differ\n", pixels,
              trained_total, off);
}

}  // namespace
}  // namespace rtpg
