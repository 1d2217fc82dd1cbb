// The guiding kernels (reproject.cl, sample.cl, train.cl) through the guider library, against a
// host implementation of the same per-pixel step that calls the same shared functions
// (kernels/shared/*.h compiled as C++); reprojection geometry under a moving camera; misuse of
// the public header; and one test that uses include/rtpg/guider.h alone. They run on whatever
// device RTPG_DEVICE or the default picks (PoCL in CI) and shrink their images under Oclgrind:
//   export OCLGRIND_BUILD_OPTIONS=-cl-opt-disable RTPG_CACHE_DIR=<fresh dir>
//   oclgrind --data-races --uninitialized --check-api tests/guiding/test_guiding_kernels
// (Oclgrind 21.10's --uninitialized aborts on the LLVM `freeze` instruction that optimised
// builds contain; without --uninitialized the optimised kernels run clean too. A fresh program
// cache keeps rtpg from loading binaries built with other Oclgrind options.)
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "rtpg/cl_runtime.h"
#include "rtpg/guiding_settings.h"
#include "rtpg/guider.h"
#include "support/angles.h"
#include "support/guiding_buffers.h"
#include "shared/gbuffer_packing.h"
#include "shared/guiding_pixel.h"
#include "shared/pmm.h"
#include "shared/pmm_train.h"
#include "shared/rng.h"
#include "shared/sample_packing.h"
#include "rtpg/guiding_layout.h"

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

// ---- host-side buffers (tests/support/guiding_buffers.h) --------------------------------

using testing::HostGBuffer;
using testing::HostVpls;
using testing::upload;

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

// For cases with models shared by rows: in the left half of the image every pixel of a group's
// later rows shows the surface of the pixel above it in the group's first row (its position a
// hundredth of a pixel away, its normal and material), and keeps its own flags and material
// parameters, so that it shares that pixel's model where both are sharable (pg_shares_model).
// In every sixteenth column (from the 16th: the smallest images keep their sharing pixels for the
// counts below) the two face -x, half a degree apart, on the two sides of z = 0,
// where their frames are half a turn apart and no model may be shared.
void share_rows(HostGBuffer& g, int rows_per_model) {
  const float4 wall_above(glm::normalize(float3(-1.0f, 0.002f, 0.004f)), 0.0f);
  const float4 wall_below(glm::normalize(float3(-1.0f, 0.003f, -0.004f)), 0.0f);
  for (int y = 0; y < g.height; ++y)
    for (int x = 0; x < g.width / 2; ++x) {
      const int model_y = y - y % rows_per_model;
      if (model_y == y) continue;
      const std::size_t i = static_cast<std::size_t>(y) * g.width + x;
      const std::size_t m = static_cast<std::size_t>(model_y) * g.width + x;
      g.position_depth[i] = g.position_depth[m] + float4(1e-4f, 0.0f, 0.0f, 0.0f);
      g.shading_normal[i] = g.shading_normal[m];
      if (x % 16 == 15) {
        g.shading_normal[m] = wall_above;
        g.shading_normal[i] = wall_below;
      }
      g.material[i] = g.material[m];
    }
}

// VPLs above the floor: invalid ones, distant ones (a direction and a solid-angle density),
// ones produced by the guide strategy (which train only with train_all_samples), facing away,
// zero density, zero and very bright radiance; the mixture density in normal.w.
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
    const float mixture_pdf = strategy == PG_STRATEGY_GUIDE
                                  ? v.position.back().w
                                  : v.position.back().w * r.uniform(0.5f, 2.0f);
    const float l = r.uniform();
    const float scale = l < 0.1f ? 0.0f : (l < 0.15f ? 1000.0f : 5.0f);
    const float3 radiance(scale * r.uniform(), scale * r.uniform(), scale * r.uniform());
    v.normal_radiance.push_back(sh::pg_pack_vpl_normal_radiance(nrm, mixture_pdf, radiance, info));
  }
  return v;
}

// ---- host reference: the kernels' per-pixel steps ------------------------------------------

// What reprojection did with a pixel.
enum Outcome { kSkipped, kOutside, kRejected, kCopied, kReframed };

// The relative error float32 allows in an aged k = k exp(-E), E = turned / (M alpha)
// (pg_pmm_view_aged_k). turned = 2 atan2(|a - b|, |a + b|) keeps its inputs' few ulp relative to
// itself (up to 32 units of 2^-24 with the lengths' square roots and a device's atan2), and exp
// turns E's absolute error into k's relative one: for a glossy lobe E reaches tens (k ages to
// 1e-30 and below), so k is known to about E times 2e-6.
double aged_k_relative_error(float3 view, float3 prev_view, const sh::pg_material& material,
                             float view_memory) {
  const sh::pg_lobes lobes = sh::pg_make_lobes(material, sh::pg_make_float3(0.0f, 0.0f, 1.0f));
  if (!(view_memory > 0.0f) || !(sh::pg_max3(lobes.f0) > 0.0f)) return 0.0;
  const double ulp = 6e-8;
  const double dx = double(view.x) - prev_view.x, dy = double(view.y) - prev_view.y,
               dz = double(view.z) - prev_view.z;
  const double sx = double(view.x) + prev_view.x, sy = double(view.y) + prev_view.y,
               sz = double(view.z) + prev_view.z;
  const double turned = 2.0 * std::atan2(std::sqrt(dx * dx + dy * dy + dz * dz),
                                         std::sqrt(sx * sx + sy * sy + sz * sz));
  const double exponent = turned / (double(view_memory) * lobes.alpha);
  return std::expm1(32.0 * ulp * exponent) + 4.0 * ulp;
}

// reproject.cl. k_conditioning (if given): per pixel, aged_k_relative_error where the view
// aged the pixel's k.
std::vector<float> host_reproject(const std::vector<float>& prev_state, const HostGBuffer& prev,
                                  const HostGBuffer& cur, const pg_kernel_settings& p,
                                  std::vector<int>& outcome, std::size_t* aged = nullptr,
                                  std::vector<double>* k_conditioning = nullptr) {
  const int w = cur.width, h = cur.height;
  std::vector<float> out(8 * cur.n(), 0.0f);
  outcome.assign(cur.n(), kSkipped);
  if (k_conditioning) k_conditioning->assign(cur.n(), 0.0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * w + x;
      if (!sh::pg_guiding_applies(cur.flags[i], cur.base_color_roughness[i].w, p)) continue;
      const float2 mv = cur.motion[i];
      const int px = static_cast<int>(std::floor(static_cast<float>(x) + 0.5f + mv.x));
      const int py = static_cast<int>(std::floor(static_cast<float>(y) + 0.5f + mv.y));
      // The first of the candidates around (px, py) that shows the same surface
      // (pg_history_candidate); outside: none of them lies in the image.
      outcome[i] = kOutside;
      const float3 n = sh::pg_float4_xyz(cur.shading_normal[i]);
      float3 m(0.0f);
      std::size_t j = 0;
      bool same = false;
      for (int t = 0; t < PG_HISTORY_CANDIDATES && !same; ++t) {
        int dx = 0, dy = 0;
        sh::pg_history_candidate(t, &dx, &dy);
        const int qx = px + dx, qy = py + dy;
        if (qx < 0 || qy < 0 || qx >= w || qy >= h) continue;
        outcome[i] = kRejected;
        j = static_cast<std::size_t>(qy) * w + qx;
        m = sh::pg_float4_xyz(prev.shading_normal[j]);
        same =
            sh::pg_same_surface(cur.position_depth[i], n, cur.material[i], prev.position_depth[j],
                                m, prev.material[j], p.reproject_position, p.reproject_normal) != 0;
      }
      if (!same) continue;
      sh::pg_pmm_state s = state_at(prev_state, j);
      outcome[i] = kCopied;
      const sh::pg_frame from = sh::pg_frame_from_normal(m), to = sh::pg_frame_from_normal(n);
      if (sh::pg_pmm_needs_reframe(from, to)) {
        s = sh::pg_pmm_reframe(s, from, to);
        outcome[i] = kReframed;
      }
      const float k = s.s1.w;
      if (mv.x != 0.0f || mv.y != 0.0f) {
        const float3 view = sh::pg_float4_xyz(cur.view_dir[i]);
        const float3 prev_view = sh::pg_float4_xyz(prev.view_dir[j]);
        const sh::pg_material material =
            sh::pg_material_from_gbuffer(cur.base_color_roughness[i], cur.metallic_specular[i]);
        s.s1.w = sh::pg_pmm_view_aged_k(k, view, prev_view, material, p.reproject_view_memory);
        if (k_conditioning && s.s1.w < k)
          (*k_conditioning)[i] =
              aged_k_relative_error(view, prev_view, material, p.reproject_view_memory);
      }
      if (aged && s.s1.w < k) ++*aged;
      if (sh::pg_pmm_state_finite(s)) set_state(out, i, s);
    }
  return out;
}

// What sample.cl knows of a pixel: its mixture, lobes, local view direction and frame.
struct PixelMixture {
  sh::pg_pmm_model model;
  sh::pg_lobes lobes;
  float3 wo;
  sh::pg_frame frame;
  sh::pg_pmm_state state;                 // what the model was built from
  float3 sampled_wi;                      // the host sampler's own direction, in the frame
  float xi = 0.0f, u1 = 0.0f, u2 = 0.0f;  // the random numbers it was drawn with
  float pdf(float3 wi) const { return sh::pg_pmm_pdf(model, lobes, wo, wi); }
};

// What shared/guiding_pixel.h's pg_shares_model reads of host G-buffer pixel i.
sh::pg_sharing_pixel sharing_pixel(const HostGBuffer& g, std::size_t i) {
  sh::pg_sharing_pixel s;
  s.flags = g.flags[i];
  s.material = g.material[i];
  s.base_color_roughness = g.base_color_roughness[i];
  s.metallic_specular = g.metallic_specular[i];
  s.position_depth = g.position_depth[i];
  s.normal = sh::pg_float4_xyz(g.shading_normal[i]);
  return s;
}

// The kernels' pg_model_pixel: the pixel whose model pixel i samples with.
std::size_t model_pixel(const HostGBuffer& g, std::size_t i, const pg_kernel_settings& p) {
  const int y = static_cast<int>(i / static_cast<std::size_t>(g.width));
  const int model_y = sh::pg_model_row(y, p);
  if (model_y == y) return i;
  const std::size_t m = i - static_cast<std::size_t>(y - model_y) * g.width;
  return sh::pg_shares_model(sharing_pixel(g, i), sharing_pixel(g, m), p) ? m : i;
}

// sample.cl.
void host_sample(const std::vector<float>& state, const HostGBuffer& g, std::uint32_t seed,
                 std::uint32_t frame, std::uint32_t sample_index, const pg_kernel_settings& p,
                 std::vector<float4>& direction_pdf, std::vector<std::uint32_t>& strategy,
                 std::vector<PixelMixture>& mixture) {
  direction_pdf.assign(g.n(), float4(0.0f));
  strategy.assign(g.n(), 0u);
  mixture.assign(g.n(), PixelMixture{});
  for (std::size_t i = 0; i < g.n(); ++i) {
    if ((g.flags[i] & PG_GBUF_SKY) != 0u) {
      direction_pdf[i] = float4(0.0f, 0.0f, 1.0f, 0.0f);
      strategy[i] = PG_STRATEGY_NONE;
      continue;
    }
    const float4 bcr = g.base_color_roughness[i];
    sh::pg_pmm_state s = sh::pg_pmm_initial_state();
    if (sh::pg_guiding_applies(g.flags[i], bcr.w, p)) s = state_at(state, model_pixel(g, i, p));
    PixelMixture& m = mixture[i];
    m.state = s;
    m.model = sh::pg_pmm_model_from_state(s, p);
    m.frame = sh::pg_frame_from_normal(sh::pg_float4_xyz(g.shading_normal[i]));
    m.wo = sh::pg_to_local(m.frame, sh::pg_float4_xyz(g.view_dir[i]));
    m.lobes = sh::pg_make_lobes(sh::pg_material_from_gbuffer(bcr, g.metallic_specular[i]), m.wo);
    sh::pg_rng rng = sh::pg_rng_make(seed, static_cast<std::uint32_t>(i), frame, sample_index,
                                     PG_RNG_STREAM_FIRST_BOUNCE);
    const float xi = sh::pg_rng_next(&rng), u1 = sh::pg_rng_next(&rng), u2 = sh::pg_rng_next(&rng);
    const sh::pg_pmm_sample_t smp = sh::pg_pmm_sample(m.model, m.lobes, m.wo, xi, u1, u2);
    m.sampled_wi = smp.wi;
    m.xi = xi;
    m.u1 = u1;
    m.u2 = u2;
    const float3 w = sh::pg_to_world(m.frame, smp.wi);
    direction_pdf[i] = float4(w.x, w.y, w.z, smp.pdf);
    strategy[i] = smp.strategy;
  }
}

// How much the host's float evaluation of a pixel's mixture pdf changes when the components of
// the direction wi move by up to 4 units of 2^-24 (an ulp of numbers in [0.5, 1); sin, cos
// and sqrt on the device err by a few of those in absolute terms, whatever the component's
// size). M^-1 loses precision near the pole (r^2 = 1 - w.z), which a narrow Gaussian turns into
// a large relative change of exp(-q/2).
float pdf_spread(const PixelMixture& m, float3 wi) {
  const float at = m.pdf(wi);
  const float step = 1.0f / 16777216.0f;
  float spread = 0.0f;
  for (int k = 0; k < 16; ++k) {
    const int a = k % 9 - 4, b = (k * 5) % 9 - 4, c = (k * 7) % 9 - 4;
    const float3 moved(wi.x + a * step, wi.y + b * step, wi.z + c * step);
    spread = std::max(spread, std::fabs(m.pdf(moved) - at));
  }
  return spread;
}

// How much the mixture density at wi changes when the Gaussian's parameters move by the rounding
// float32 allows in pg_pmm_model_from_state. The covariance comes from raw moments,
// S_xx / S0 - mx^2, which cancel for a lobe narrow against its distance from the square's
// corner, and each device rounds that difference (or contracts it into an fma) its own way;
// l22 = sqrt(syy - l21^2) cancels likewise for a strong correlation. On an NVIDIA H100 one
// pixel in 400k differed by 1.5e-4 relative through this alone (docs/design.md, "Floating point
// on other devices").
float model_spread(const PixelMixture& m, float3 wi) {
  if (!m.model.valid) return 0.0f;
  const double ulp = 6e-8, inv = 1.0 / m.state.s0.y;
  const double mx = m.model.mx, my = m.model.my, l11 = m.model.l11, l21 = m.model.l21;
  const double l22 = m.model.l22;
  const double e_xx = 4.0 * ulp * (std::fabs(m.state.s1.x) * inv + mx * mx);
  const double e_yy = 4.0 * ulp * (std::fabs(m.state.s1.y) * inv + my * my);
  const double e_xy = 4.0 * ulp * (std::fabs(m.state.s1.z) * inv + std::fabs(mx * my));
  const double d_l11 = e_xx / (2.0 * l11);
  const double d_l21 = e_xy / l11 + std::fabs(l21) * d_l11 / l11;
  const double d_l22 = (e_yy + 2.0 * std::fabs(l21) * d_l21) / (2.0 * l22);
  const double steps[6] = {
      4.0 * ulp * m.model.pi, 4.0 * ulp * mx, 4.0 * ulp * my, d_l11, d_l21, d_l22};
  const float at = m.pdf(wi);
  float spread = 0.0f;
  for (int k = 0; k < 12; ++k) {
    PixelMixture moved = m;
    float* params[6] = {&moved.model.pi,  &moved.model.mx,  &moved.model.my,
                        &moved.model.l11, &moved.model.l21, &moved.model.l22};
    float& v = *params[k / 2];
    // At least an ulp of the parameter itself, so the move is never lost to rounding.
    const double step = std::max(steps[k / 2], 2.0 * ulp * std::fabs(v));
    v = static_cast<float>(v + (k % 2 == 0 ? step : -step));
    spread = std::max(spread, std::fabs(moved.pdf(wi) - at));
  }
  return spread;
}

// How far the host's sampled direction (in the pixel's frame) moves when its two sampling numbers,
// or the components of the local view direction wo, move by up to 4 units of 2^-24, as
// pdf_spread does for the density: where a sampler is ill-conditioned (the GGX visible-normal
// sampler as u1 -> 1, where nh.z = sqrt(1 - p1^2 - p2^2) cancels; the Gaussian's Box-Muller
// radius as u1 -> 0; a sharp GGX lobe seen at grazing angles, whose visible normals follow wo.z's
// few ulp), the device's own few-ulp sin, cos, log, sqrt and change of frame move the direction
// by as much.
float direction_spread(const PixelMixture& m) {
  const float step = 1.0f / 16777216.0f;
  float spread = 0.0f;
  for (int k = 0; k < 32; ++k) {
    const int a = k % 9 - 4, b = (k * 5) % 9 - 4, c = (k * 7) % 9 - 4;
    const bool move_wo = k >= 16;
    const float3 wo =
        move_wo ? float3(m.wo.x + a * step, m.wo.y + b * step, m.wo.z + c * step) : m.wo;
    const float u1 = move_wo ? m.u1 : std::clamp(m.u1 + a * step, 0.0f, 0.99999994f);
    const float u2 = move_wo ? m.u2 : std::clamp(m.u2 + b * step, 0.0f, 0.99999994f);
    const sh::pg_pmm_sample_t moved = sh::pg_pmm_sample(m.model, m.lobes, wo, m.xi, u1, u2);
    if (!(moved.pdf > 0.0f)) continue;
    spread =
        std::max({spread, std::fabs(moved.wi.x - m.sampled_wi.x),
                  std::fabs(moved.wi.y - m.sampled_wi.y), std::fabs(moved.wi.z - m.sampled_wi.z)});
  }
  return spread;
}

// The relative error float32 allows in the GGX density at wi. D(h) = a2 / (pi d^2) with
// d = h.x^2 + h.y^2 + a2 h.z^2 (kernels/shared/bsdf.h): nothing cancels, so d carries the error
// of the half vector's tangential components, a few ulp of wo and wi (each device rounds its own
// change of frame) over |wo + wi| = 2 cos(theta_d) from the normalisation, and d's own few ulp.
// Near the peak of a sharp lobe (d ~ a2, down to 1.6e-7) the first term is what float32 allows
// in the inputs (~5e-4 at alpha 4e-4), not an artefact of the formula.
double ggx_relative_error(const sh::pg_lobes& lobes, float3 wo, float3 wi) {
  if (!(lobes.p_specular > 0.0f)) return 0.0;
  const double ulp = 6e-8;  // of a number below 1
  const double sx = double(wo.x) + wi.x, sy = double(wo.y) + wi.y, sz = double(wo.z) + wi.z;
  const double len = std::sqrt(sx * sx + sy * sy + sz * sz);
  const double hx = sx / std::max(len, 1e-30), hy = sy / std::max(len, 1e-30);
  const double hz = sz / std::max(len, 1e-30);
  const double a2 = double(lobes.alpha) * lobes.alpha;
  const double d = hx * hx + hy * hy + a2 * hz * hz;
  const double h_error = 8.0 * ulp / std::max(len, 1e-6);
  const double d_error = 2.0 * (std::fabs(hx) + std::fabs(hy)) * h_error + 4.0 * ulp * d;
  return 2.0 * d_error / std::max(d, 1e-30) + 4.0 * ulp;
}

// train.cl (either variant: the local tile holds zeros outside the image, i.e. no VPL, which
// is what skipping those window cells does here).
// conditioning (if given): per pixel, the largest relative error float32 allows in the weight of
// one of its lit samples (ggx_relative_error at the sample's direction: a weight is L f cos / r
// with the BSDF f), which the state's sums carry at most as far.
std::vector<float> host_train(const std::vector<float>& state, const HostGBuffer& g,
                              const HostVpls& v, std::uint32_t seed, std::uint32_t frame,
                              const pg_kernel_settings& p, std::vector<int>& trained,
                              std::vector<double>* conditioning = nullptr) {
  const int w = g.width, h = g.height;
  std::vector<float> out = state;
  trained.assign(g.n(), 0);
  if (conditioning) conditioning->assign(g.n(), 0.0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const int i = y * w + x;
      const float4 bcr = g.base_color_roughness[i];
      sh::pg_pmm_state s = state_at(state, i);
      if (!sh::pg_guiding_applies(g.flags[i], bcr.w, p) ||
          !sh::pg_train_this_frame(s.s1.w, x, y, frame, p) ||
          model_pixel(g, static_cast<std::size_t>(i), p) != static_cast<std::size_t>(i))
        continue;
      sh::pg_train_pixel px;
      px.x = sh::pg_float4_xyz(g.position_depth[i]);
      px.frame = sh::pg_frame_from_normal(sh::pg_float4_xyz(g.shading_normal[i]));
      px.wo = sh::pg_to_local(px.frame, sh::pg_float4_xyz(g.view_dir[i]));
      px.lobes =
          sh::pg_make_lobes(sh::pg_material_from_gbuffer(bcr, g.metallic_specular[i]), px.wo);
      const int side = 2 * p.apron + 1;
      const int n = std::min(std::min(sh::pg_pmm_neighbour_count(s.s1.w, p), side * side),
                             PG_MAX_TRAIN_SAMPLES);
      const std::uint32_t start =
          sh::pg_train_walk_start(seed, x, y, static_cast<std::uint32_t>(w), frame, p);
      float4 samples[PG_MAX_TRAIN_SAMPLES];
      float densities[PG_MAX_TRAIN_SAMPLES];
      int kept = 0;
      for (int k = 0; k < n; ++k) {
        const int c = sh::pg_train_window_index(start, k, p);
        const int sx = x + c % side - p.apron, sy = y + c / side - p.apron;
        if (sx < 0 || sy < 0 || sx >= w || sy >= h) continue;
        const int j = sy * w + sx;
        kept += sh::pg_train_sample_from_vpl(px, v.position[j], v.normal_radiance[j], p,
                                             &samples[kept], &densities[kept]);
      }
      if (conditioning) {
        PixelMixture m;
        m.lobes = px.lobes;
        m.wo = px.wo;
        for (int k = 0; k < kept; ++k)
          if (samples[k].x > 0.0f)
            (*conditioning)[i] = std::max(
                (*conditioning)[i],
                ggx_relative_error(
                    m.lobes, m.wo,
                    sh::pg_square_to_hemisphere(sh::pg_make_float2(samples[k].y, samples[k].z))));
      }
      int updated = 0;
      s = sh::pg_pmm_train(s, samples, densities, kept, p, static_cast<float>(n), p.em_passes,
                           &updated);
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
// k_rel: k's own relative tolerance, 0 where k must be exact (small integers on any device).
bool states_agree(const sh::pg_pmm_state& a, const sh::pg_pmm_state& b, float rel,
                  float k_rel = 0.0f) {
  const float va[8] = {a.s0.x, a.s0.y, a.s0.z, a.s0.w, a.s1.x, a.s1.y, a.s1.z, a.s1.w};
  const float vb[8] = {b.s0.x, b.s0.y, b.s0.z, b.s0.w, b.s1.x, b.s1.y, b.s1.z, b.s1.w};
  const float scale = std::max(std::fabs(a.s0.y), std::fabs(b.s0.y));
  for (int c = 0; c < 8; ++c) {
    if (same_bits(va[c], vb[c])) continue;
    if (!std::isfinite(va[c]) || !std::isfinite(vb[c])) return false;
    if (c == 7) {
      if (!(std::fabs(va[c] - vb[c]) <= k_rel * std::max(std::fabs(va[c]), std::fabs(vb[c]))))
        return false;
      continue;
    }
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

// Local sizes the guider runs at: the two common ones, one that is not a power of two and 0x0,
// the device's own (rows of work-groups on CPUs: host/cl/work_groups.h); image sizes are not
// multiples of them (the padding work-items must do nothing, and the local tile must be filled
// where they stand). Each with its own neighbourhood radius.
struct KernelCase {
  int local_x, local_y;
  int width, height;
  int apron;
  int rows_per_model;  // models shared by groups of this many rows (GuidingSettings)
};

// Every row-sharing setting the default chooses (rows_per_model_for_height: 1, 2, 4 and, from
// 1080 rows, 8) in one case or another; at full size each sharing case's image ends in a group
// its height cuts short.
std::vector<KernelCase> kernel_cases(const ClRuntime& rt) {
  if (simulated(rt))
    return {{8, 8, 13, 9, 2, 8}, {16, 16, 19, 5, 1, 2}, {12, 6, 14, 8, 3, 4}, {0, 0, 21, 7, 2, 1}};
  // 300 pixels a row: three row groups of 100 work-items for one pixel per work-item.
  return {
      {8, 8, 93, 61, 3, 4}, {16, 16, 101, 77, 2, 8}, {12, 6, 98, 47, 1, 2}, {0, 0, 300, 29, 2, 1}};
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
// depth, or motion out of the image. Sub-pixel motion stays 0.1 px away from pixel borders;
// a tenth of the pixels have motion exactly 0, as under a still camera.
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
      if (r.uniform() < 0.1f) {  // a still camera: motion exactly 0 (no view age)
        dx = dy = 0;
        cur.motion[i] = float2(0.0f, 0.0f);
      }
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
// the covariance from a Jacobian in closed form, or by differences of step 1e-3 near the square's
// centre and the pole (there an error of a few ulp of 0.5 in a probe, 3e-7, becomes 3e-4 in the
// Jacobian; docs/guiding.md, "The reframe's Jacobian in closed form"). A reframed mean that lands
// within ulps of the horizon threshold (w.z = 1e-4) may be carried on one side and dropped on the
// other: such pixels are counted and bounded (none are expected at these sizes). The first and last
// cases age glossy models as their view turns (reproject_view_memory); k then goes through
// atan2 and exp, which may differ by a few ulp between the device and the host: within 1e-5
// relative plus twice aged_k_relative_error (the exponent's conditioning; on an NVIDIA H100,
// with acos then, a k aged by exp(-90) differed by 2e-5 relative, docs/design.md, "Floating
// point on other devices"). Three cases share models by rows (rows_per_model 2, 4 and 8, on
// G-buffers whose left halves repeat each group's first row): there reproject leaves a sharing
// pixel alone, and after the sample kernel it holds its model pixel's reprojected state.
TEST(GuidingKernels, ReprojectMatchesHostReference) {
  ClRuntime rt;
  Random r(101);
  std::size_t pixels = 0, count[5] = {0, 0, 0, 0, 0}, aged = 0, sharing = 0;
  const std::vector<KernelCase> cases = kernel_cases(rt);
  for (std::size_t c_index = 0; c_index < cases.size(); ++c_index) {
    const KernelCase& kc = cases[c_index];
    GuidingSettings settings;
    settings.reproject_view_memory = c_index == 1 ? 0.0f : 2.0f;
    settings.local_x = kc.local_x;
    settings.local_y = kc.local_y;
    settings.apron = kc.apron;
    settings.rows_per_model = kc.rows_per_model;
    const pg_kernel_settings p = to_kernel_settings(settings);
    Guider guider(rt, kc.width, kc.height, settings);
    HostGBuffer prev(1, 1), cur(1, 1);
    make_reprojection_pair(r, kc.width, kc.height, prev, cur);
    share_rows(cur, settings.rows_per_model);
    const std::vector<float> prev_state = random_states(r, prev.n(), p.k_max, true);
    std::vector<int> outcome;
    std::vector<double> k_conditioning;
    const std::vector<float> expected =
        host_reproject(prev_state, prev, cur, p, outcome, &aged, &k_conditioning);
    // Whether pixel `at` of `got` holds the host's reprojected state of pixel e.
    const auto agrees = [&](const std::vector<float>& got, std::size_t at, std::size_t e) {
      const sh::pg_pmm_state want = state_at(expected, e), have = state_at(got, at);
      const float k_rel = settings.reproject_view_memory > 0.0f
                              ? 1e-5f + static_cast<float>(2.0 * k_conditioning[e])
                              : 0.0f;
      if (outcome[e] == kReframed) return states_agree(want, have, 1e-3f, k_rel);
      bool ok = true;
      for (int c = 0; c < 7; ++c) ok = ok && same_bits(expected[8 * e + c], got[8 * at + c]);
      const float ek = expected[8 * e + 7], gk = got[8 * at + 7];
      return ok && (same_bits(ek, gk) || std::fabs(ek - gk) <= k_rel * std::fabs(ek));
    };
    const GuiderGBuffer current = upload(rt, cur);
    guider.write_state(prev_state);
    guider.reproject(current, upload(rt, prev));
    std::vector<float> got;
    guider.read_state(got);
    ASSERT_EQ(got.size(), expected.size());
    std::size_t mismatched = 0, shared_here = 0;
    for (std::size_t i = 0; i < cur.n(); ++i) {
      const bool shares = model_pixel(cur, i, p) != i;
      shared_here += shares;
      // A pixel that shares its model is left to the sample kernel: its state in reproject's
      // destination is what was there (a new guider's zeros), not a carried one.
      bool ok = true;
      if (shares)
        for (int c = 0; c < 8; ++c) ok = ok && same_bits(got[8 * i + c], 0.0f);
      else
        ok = agrees(got, i, i);
      if (!ok && ++mismatched <= 5) {
        ADD_FAILURE() << name(kc) << " pixel " << i
                      << (shares ? " (sharing: to be left as it was, zeros)" : "")
                      << (outcome[i] == kReframed ? " (reframed)" : "") << ": host "
                      << describe(state_at(expected, i)) << " device "
                      << describe(state_at(got, i));
      }
      ++count[outcome[i]];
    }
    EXPECT_EQ(mismatched, 0u) << name(kc);
    if (settings.rows_per_model > 1) {
      EXPECT_GT(shared_here, 0u) << name(kc);
    }
    sharing += shared_here;
    // After sampling, every pixel holds the state reprojection carries to its model pixel (its
    // own where it shares none): what reprojecting every pixel and then sampling gave.
    const GuiderSamples samples = make_guider_samples(rt.context(), kc.width, kc.height);
    guider.sample(current, 17u, 3u, 0u, samples);
    std::vector<float> sampled;
    guider.read_state(sampled);
    std::size_t after_sampling = 0;
    for (std::size_t i = 0; i < cur.n(); ++i) {
      const std::size_t from = model_pixel(cur, i, p);
      if (!agrees(sampled, i, from) && ++after_sampling <= 5)
        ADD_FAILURE() << name(kc) << " pixel " << i << " after sampling (model pixel " << from
                      << "): host " << describe(state_at(expected, from)) << " device "
                      << describe(state_at(sampled, i));
    }
    EXPECT_EQ(after_sampling, 0u) << name(kc);
    pixels += cur.n();
  }
  // The inputs exercised every path.
  for (int o = kSkipped; o <= kReframed; ++o) EXPECT_GT(count[o] * 30, pixels) << "outcome " << o;
  EXPECT_GT(aged * 30, pixels) << "glossy models aged by a turned view";
  std::printf(
      "[ info     ] reproject: %zu pixels: %zu skipped, %zu outside, %zu rejected, %zu "
      "copied, %zu reframed, %zu aged, %zu sharing a model\n",
      pixels, count[0], count[1], count[2], count[3], count[4], aged, sharing);
}

// ---- sample --------------------------------------------------------------------------------

// Device and host agree on every pixel's strategy and direction, and the device's pdf is the
// mixture density of the direction it produced, for every variant of the kernel: sample.cl and
// sample_wide.cl with 2, 4, 8 and 16 pixels per work-item (kernels/wide/).
//  - Direction: 1e-4 per component plus twice direction_spread. Device sin/cos/log/sqrt may be a
//    few ulp off, and the GGX visible-normal sampler amplifies that in its tail (nh.z =
//    sqrt(1 - p1^2 - p2^2) cancels as u1 -> 1): the spread measures that amplification at the
//    pixel's own sampling numbers.
//  - pdf: compared with the host's pdf at the device's direction (brought into the pixel's
//    frame), so that the sampler's conditioning does not count twice: within 1e-4 relative
//    (exp of a quadratic form, fma contraction), plus twice pdf_spread there, twice
//    model_spread (float32 conditioning of the Gaussian's parameters) and ggx_relative_error
//    (of the GGX density itself). Pixels that need the spread
//    are counted: they must be the sharp lobes only, not most pixels.
//  - Strategy: can differ only where xi is within ulps of pi or where a Gaussian sample lies
//    within ulps of the square's border (pdf 0 on one side): both have probability ~1e-6 per
//    pixel, so the test allows one such pixel in all the images.
TEST(GuidingKernels, SampleMatchesHostReference) {
  ClRuntime rt;
  Random r(202);
  std::size_t pixels = 0, guided = 0, near_threshold = 0, ill_conditioned = 0, mismatched = 0;
  const int lane_counts[] = {1, 2, 4, 8, 16};
  for (const KernelCase& kc : kernel_cases(rt)) {
    HostGBuffer g = random_gbuffer(r, kc.width, kc.height);
    // One case has a Lambert-only lower half, so that whole work-items of the wide kernel skip
    // the GGX lobe.
    if (kc.apron == 3)
      for (std::size_t i = g.n() / 2; i < g.n(); ++i) g.metallic_specular[i] = float4(0.0f);
    GuidingSettings settings;
    settings.local_x = kc.local_x;
    settings.local_y = kc.local_y;
    settings.rows_per_model = kc.rows_per_model;
    share_rows(g, settings.rows_per_model);
    const GuiderGBuffer dg = upload(rt, g);
    const pg_kernel_settings p = to_kernel_settings(settings);
    std::size_t sharing = 0;
    for (std::size_t i = 0; i < g.n(); ++i) sharing += model_pixel(g, i, p) != i;
    if (settings.rows_per_model > 1) {
      EXPECT_GT(sharing, g.n() / 20) << name(kc);
    }
    const std::vector<float> state = random_states(r, g.n(), p.k_max, false);
    const GuiderSamples samples = make_guider_samples(rt.context(), kc.width, kc.height);
    for (std::uint32_t frame = 0; frame < 3 * std::size(lane_counts); ++frame) {
      // Each variant (sample.cl, then sample_wide.cl at 2 to 16 lanes) draws three frames.
      settings.sample_lanes = lane_counts[frame / 3];
      Guider guider(rt, kc.width, kc.height, settings);
      ASSERT_EQ(guider.sample_lanes(), settings.sample_lanes);
      guider.write_state(state);
      const std::uint32_t seed = 7u + frame * 13u;
      guider.sample(dg, seed, frame, frame % 2u, samples);
      // A pixel that shares its model now holds the model's state as its own, to the bit
      // (kernels/shared/guiding_pixel.h, pg_shares_model); every other state is untouched.
      std::vector<float> carried;
      guider.read_state(carried);
      std::size_t carried_wrong = 0;
      for (std::size_t i = 0; i < g.n(); ++i) {
        const std::size_t from = model_pixel(g, i, p) * PG_STATE_FLOATS_PER_PIXEL;
        carried_wrong += std::memcmp(carried.data() + i * PG_STATE_FLOATS_PER_PIXEL,
                                     state.data() + from, PG_STATE_FLOATS_PER_PIXEL * 4) != 0;
      }
      EXPECT_EQ(carried_wrong, 0u) << name(kc) << ", " << settings.sample_lanes << " lanes";
      std::vector<float4> got_dir(g.n()), want_dir, got_mixture_a(g.n());
      std::vector<float2> got_mixture_b(g.n());
      std::vector<std::uint32_t> got_strategy(g.n()), want_strategy;
      std::vector<PixelMixture> mixture;
      rt.queue().enqueueReadBuffer(samples.direction_pdf, CL_TRUE, 0, g.n() * 16, got_dir.data());
      rt.queue().enqueueReadBuffer(samples.strategy, CL_TRUE, 0, g.n() * 4, got_strategy.data());
      rt.queue().enqueueReadBuffer(samples.mixture_a, CL_TRUE, 0, g.n() * 16, got_mixture_a.data());
      rt.queue().enqueueReadBuffer(samples.mixture_b, CL_TRUE, 0, g.n() * 8, got_mixture_b.data());
      // The work-groups' counts (include/rtpg/guiding_layout.h, "Counts") are those of the
      // pixels' own outputs: every work-group shape and lane count sums every pixel once.
      const GuiderSampleCounts counts = guider.sample_counts();
      std::size_t surfaces = 0, with_gaussian = 0;
      double pi_sum = 0.0;
      for (std::size_t i = 0; i < g.n(); ++i) {
        if ((g.flags[i] & PG_GBUF_SKY) != 0u) continue;
        ++surfaces;
        if (!(got_mixture_a[i].w > 0.0f)) continue;
        ++with_gaussian;
        pi_sum += got_mixture_a[i].x;
      }
      EXPECT_EQ(counts.surfaces, surfaces) << name(kc) << ", " << settings.sample_lanes << " lanes";
      EXPECT_EQ(counts.guided, with_gaussian) << name(kc) << ", " << settings.sample_lanes;
      EXPECT_NEAR(counts.pi_sum, pi_sum, 1e-5 * pi_sum)
          << name(kc) << ", " << settings.sample_lanes;
      // Without the mixture the kernel draws the same samples and leaves the mixture's
      // channels as they were. The states as they were before the first call, so that a pixel
      // that shares draws from its model's state only if this call finds it sharing: in odd
      // frames (sample_index 1 of the same frame) by the first call's decision, read from
      // shares_model (include/rtpg/guiding_layout.h, "Shared models").
      guider.write_state(state);
      const std::vector<float4> marker(g.n(), float4(-7.0f));
      rt.queue().enqueueWriteBuffer(samples.mixture_a, CL_TRUE, 0, g.n() * 16, marker.data());
      guider.sample(dg, seed, frame, frame % 2u, samples, SampleOutputs::directions);
      std::vector<float4> bare_dir(g.n()), bare_mixture_a(g.n());
      std::vector<std::uint32_t> bare_strategy(g.n());
      rt.queue().enqueueReadBuffer(samples.direction_pdf, CL_TRUE, 0, g.n() * 16, bare_dir.data());
      rt.queue().enqueueReadBuffer(samples.strategy, CL_TRUE, 0, g.n() * 4, bare_strategy.data());
      rt.queue().enqueueReadBuffer(samples.mixture_a, CL_TRUE, 0, g.n() * 16,
                                   bare_mixture_a.data());
      EXPECT_EQ(0, std::memcmp(bare_dir.data(), got_dir.data(), g.n() * 16)) << name(kc);
      EXPECT_EQ(bare_strategy, got_strategy) << name(kc);
      EXPECT_EQ(0, std::memcmp(bare_mixture_a.data(), marker.data(), g.n() * 16)) << name(kc);
      const GuiderSampleCounts bare_counts = guider.sample_counts();
      EXPECT_EQ(bare_counts.guided, counts.guided);
      EXPECT_EQ(bare_counts.pi_sum, counts.pi_sum);
      host_sample(state, g, seed, frame, frame % 2u, p, want_dir, want_strategy, mixture);
      for (std::size_t i = 0; i < g.n(); ++i) {
        const float4 a = want_dir[i], b = got_dir[i];
        const bool pdf_zero_differs = (a.w > 0.0f) != (b.w > 0.0f);
        if (want_strategy[i] != got_strategy[i] || pdf_zero_differs) {
          ++near_threshold;
          continue;
        }
        guided += want_strategy[i] == PG_STRATEGY_GUIDE;
        if (a.w == 0.0f) continue;  // no sample: the direction is a placeholder
        // Where the device drew the host's direction to the bit, the density is evaluated at the
        // host sampler's own local direction: the round trip through world space moves it by an
        // ulp, which at the peak of the sharpest GGX lobes (alpha 4e-4) changes the density
        // severalfold, an artefact of the check and not of the kernel.
        const bool same_direction = a.x == b.x && a.y == b.y && a.z == b.z;
        const float3 local = same_direction
                                 ? mixture[i].sampled_wi
                                 : sh::pg_to_local(mixture[i].frame, float3(b.x, b.y, b.z));
        const float reference = mixture[i].pdf(local), spread = pdf_spread(mixture[i], local);
        const double ggx = ggx_relative_error(mixture[i].lobes, mixture[i].wo, local);
        const float model = model_spread(mixture[i], local);
        const double pdf_tolerance = (1e-4 + ggx) * reference + 2.0 * spread + 2.0 * model;
        ill_conditioned +=
            2.0 * spread > 1e-3 * reference || 2.0 * model > 1e-3 * reference || ggx > 1e-3;
        // The mixture the kernel hands to the host gives, evaluated on the host, the density
        // the kernel sampled with (within the float allowance above): what next-event MIS at
        // the primary hit needs.
        PixelMixture handed = mixture[i];
        handed.model = sh::pg_pmm_model_from_mixture(got_mixture_a[i], got_mixture_b[i]);
        const float host_side = handed.pdf(local);
        // A direction component may differ by 1e-4 plus twice the sampler's spread there (in
        // the frame; the change to world coordinates keeps lengths).
        const float dir_spread = same_direction ? 0.0f : direction_spread(mixture[i]);
        const float dir_tolerance = 1e-4f + 2.0f * dir_spread;
        ill_conditioned += 2.0f * dir_spread > 1e-4f;
        const bool ok = std::fabs(b.x - a.x) <= dir_tolerance &&
                        std::fabs(b.y - a.y) <= dir_tolerance &&
                        std::fabs(b.z - a.z) <= dir_tolerance && std::isfinite(b.w) &&
                        std::fabs(double(b.w) - reference) <= pdf_tolerance &&
                        handed.model.valid == mixture[i].model.valid &&
                        std::fabs(double(host_side) - b.w) <= pdf_tolerance;
        if (!ok && ++mismatched <= 5)
          ADD_FAILURE() << name(kc) << ", " << settings.sample_lanes << " lanes, frame " << frame
                        << " pixel " << i << ": host (" << a.x << " " << a.y << " " << a.z
                        << " pdf " << a.w << ") device (" << b.x << " " << b.y << " " << b.z
                        << " pdf " << b.w << "), direction +- " << dir_tolerance
                        << ", host pdf there " << reference << " +- " << pdf_tolerance
                        << ", from the kernel's mixture " << host_side;
      }
      pixels += g.n();
    }
  }
  EXPECT_EQ(mismatched, 0u) << "of " << pixels << " pixels";
  EXPECT_LE(near_threshold, 1u) << "of " << pixels << " pixels";
  EXPECT_GT(guided, pixels / 10);  // the Gaussian branch was exercised
  // The conditioning allowances exceed 1e-3 for sharp lobes only (a tenth of the random
  // materials have roughness below 0.05), not as a blanket tolerance.
  EXPECT_LT(ill_conditioned * 10, pixels);
  std::printf(
      "[ info     ] sample: %zu pixels, %zu guided, %zu near a threshold, %zu with an "
      "ill-conditioned pdf\n",
      pixels, guided, near_threshold, ill_conditioned);
}

// ---- train ---------------------------------------------------------------------------------

// Device and host agree after one EM step per pixel, for every variant of the kernel: train.cl
// with the VPL tile in local memory and with direct global reads (which must also agree bit
// for bit with each other: the same arithmetic on the same VPLs), and train_wide.cl with 2, 4,
// 8 and 16 pixels per work-item (kernels/wide/). Tolerance 1e-4 relative (of the value, plus of
// S0 for the moments): the step size uses exp and log (3 ulp each in OpenCL), the E-step exp of
// a quadratic form, and the device may contract a*b+c into fma; plus, where a sharp GGX lobe
// makes a sample's weight ill-conditioned in float32, twice ggx_relative_error at its direction
// (as the sample test allows for the density; under Oclgrind a random 21x7 image had one pixel
// whose brightest sample's weight moved by 1e-3 there). A pixel could differ beyond that
// only where a decision flips on a few-ulp difference (a responsibility at the re-seeding
// threshold, gamma = 1e-3, or a weight at max_weight); none does with these seeds, and any
// mismatch fails the test. In
// one case the lower half of the image is Lambert only, so that whole work-items of the wide
// kernel skip the GGX lobe. In the two cases whose models are shared by rows, train decides
// which pixels share in the first frame and reads the sample kernel's decision in the second.
TEST(GuidingKernels, TrainMatchesHostReferenceInEveryVariant) {
  ClRuntime rt;
  Random r(303);
  std::size_t pixels = 0, trained_total = 0, off = 0, ill_conditioned = 0;
  for (const KernelCase& kc : kernel_cases(rt)) {
    HostGBuffer g = random_gbuffer(r, kc.width, kc.height);
    if (kc.apron == 3)
      for (std::size_t i = g.n() / 2; i < g.n(); ++i) g.metallic_specular[i] = float4(0.0f);
    HostVpls v = random_vpls(r, g.n());
    // The left third of the image sees only dark VPLs (as a room lit through an opening
    // mostly does): whole steps of train_wide's lanes take its shortcut for them, which must
    // give what the scalar code gives pixel by pixel.
    for (std::size_t i = 0; i < g.n(); ++i)
      if (static_cast<int>(i % static_cast<std::size_t>(kc.width)) < kc.width / 3)
        v.normal_radiance[i] =
            sh::pg_pack_vpl_normal_radiance(sh::pg_vpl_normal(v.normal_radiance[i]),
                                            sh::pg_vpl_mixture_density(v.normal_radiance[i]),
                                            float3(0.0f), sh::pg_vpl_info(v.normal_radiance[i]));
    GuidingSettings settings;
    settings.local_x = kc.local_x;
    settings.local_y = kc.local_y;
    settings.apron = kc.apron;
    settings.rows_per_model = kc.rows_per_model;
    share_rows(g, settings.rows_per_model);
    if (settings.rows_per_model > 1) {
      const pg_kernel_settings sharing_settings = to_kernel_settings(settings);
      std::size_t sharing = 0;
      for (std::size_t i = 0; i < g.n(); ++i) sharing += model_pixel(g, i, sharing_settings) != i;
      EXPECT_GT(sharing, g.n() / 20) << name(kc);
    }
    const GuiderGBuffer dg = upload(rt, g);
    const GuiderVpls dv = upload(rt, v, g.width, g.height);
    // The training options vary with the case (every case has its own apron): every VPL at
    // its mixture density and the weight clamp with apron 2, amortised training of mature pixels
    // and re-seeds that take two samples of a batch with apron 1, the variance-aware mixing weight
    // with aprons 1 and 3 (EM's with apron 2).
    settings.train_all_samples = kc.apron == 2 ? 1 : 0;
    settings.pi_learning = kc.apron != 2 ? 1 : 0;
    settings.train_interval = kc.apron == 1 ? 3 : 1;
    settings.reseed_samples = kc.apron == 1 ? 2 : 1;
    settings.weight_clamp = kc.apron == 2 ? 5.0f : 0.0f;
    const pg_kernel_settings p = to_kernel_settings(settings);
    std::vector<float> state = random_states(r, g.n(), p.k_max, false);
    std::vector<float> per_variant[2];
    const GuiderSamples samples = make_guider_samples(rt.context(), kc.width, kc.height);
    const int lanes[] = {1, 1, 2, 4, 8, 16};
    for (int variant = 0; variant < 6; ++variant) {
      settings.train_memory =
          variant == 0 ? GuidingSettings::TrainMemory::Local : GuidingSettings::TrainMemory::Global;
      settings.train_lanes = lanes[variant];
      const std::string variant_name =
          variant == 0 ? " local" : " global, " + std::to_string(lanes[variant]) + " lanes";
      Guider guider(rt, kc.width, kc.height, settings);
      ASSERT_EQ(guider.train_uses_local_memory(), variant == 0);
      // The device's own work-groups: reproject and sample in rows on a CPU device.
      if (kc.local_x == 0) {
        EXPECT_EQ(guider.row_work_groups(), rt.info().type == "cpu");
      }
      ASSERT_EQ(guider.train_lanes(), lanes[variant]);
      std::vector<float> s = state;
      // Two frames: the second starts from the first's result (models seeded at k = 0 train on).
      for (std::uint32_t frame = 0; frame < 2; ++frame) {
        const std::uint32_t seed = 11u + frame;
        std::vector<int> trained;
        std::vector<double> conditioning;
        // Where models are shared, the second frame samples first: the sample kernel decides
        // which pixels share and carries the models into them, and train reads its decision
        // (include/rtpg/guiding_layout.h, "Shared models"); in the first frame train decides.
        const bool sampled_first = frame == 1 && settings.rows_per_model > 1;
        if (sampled_first)
          for (std::size_t i = 0; i < g.n(); ++i) {
            const std::size_t from = model_pixel(g, i, p);
            std::copy_n(s.begin() + static_cast<std::ptrdiff_t>(from * PG_STATE_FLOATS_PER_PIXEL),
                        PG_STATE_FLOATS_PER_PIXEL,
                        s.begin() + static_cast<std::ptrdiff_t>(i * PG_STATE_FLOATS_PER_PIXEL));
          }
        const std::vector<float> expected =
            host_train(s, g, v, seed, frame, p, trained, &conditioning);
        guider.write_state(s);
        if (sampled_first) guider.sample(dg, seed, frame, 0u, samples);
        guider.train(dg, dv, seed, frame);
        std::vector<float> got;
        guider.read_state(got);
        std::size_t mismatched = 0;
        for (std::size_t i = 0; i < g.n(); ++i) {
          // 1e-4 relative, plus twice the float32 conditioning of the pixel's sample weights
          // where a sharp GGX lobe makes it larger (counted: the sharp lobes only).
          const float allowance = static_cast<float>(2.0 * conditioning[i]);
          ill_conditioned += allowance > 1e-4f;
          if (states_agree(state_at(expected, i), state_at(got, i), 1e-4f + allowance)) continue;
          ++mismatched;
          if (mismatched <= 5)
            ADD_FAILURE() << name(kc) << variant_name << " frame " << frame << " pixel " << i
                          << ": host " << describe(state_at(expected, i)) << " device "
                          << describe(state_at(got, i));
        }
        off += mismatched;
        std::size_t host_trained = 0;
        for (int t : trained) host_trained += t != 0;
        const std::size_t device_trained = guider.count_trained();
        EXPECT_LE(device_trained > host_trained ? device_trained - host_trained
                                                : host_trained - device_trained,
                  mismatched)
            << name(kc) << variant_name;
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
  // The conditioning allowance is for pixels with sharp lobes, not a blanket tolerance.
  EXPECT_LT(ill_conditioned * 10, pixels);
  std::printf(
      "[ info     ] train: %zu pixel steps, %zu trained, %zu differ, %zu with ill-conditioned "
      "weights\n",
      pixels, trained_total, off, ill_conditioned);
}

}  // namespace
}  // namespace rtpg

namespace rtpg {
namespace {

// ---- reprojection geometry -----------------------------------------------------------------

// A pinhole camera (z up), pixel centres at integer + 0.5, y down the image.
struct Camera {
  glm::dvec3 pos, fwd, right, up;
  double tan_half, aspect;
  int width, height;
  Camera(glm::dvec3 p, glm::dvec3 target, double fov_deg, int w, int h)
      : pos(p),
        tan_half(std::tan(fov_deg * 3.14159265358979323846 / 360.0)),
        aspect(double(w) / h),
        width(w),
        height(h) {
    fwd = glm::normalize(target - p);
    right = glm::normalize(glm::cross(fwd, glm::dvec3(0, 0, 1)));
    up = glm::cross(right, fwd);
  }
  glm::dvec3 ray(int x, int y) const {
    const double sx = (2.0 * (x + 0.5) / width - 1.0) * tan_half * aspect;
    const double sy = (1.0 - 2.0 * (y + 0.5) / height) * tan_half;
    return glm::normalize(fwd + right * sx + up * sy);
  }
  // Continuous pixel coordinates of a world point (false behind the camera).
  bool project(glm::dvec3 p, double& px, double& py) const {
    const glm::dvec3 d = p - pos;
    const double z = glm::dot(d, fwd);
    if (z <= 1e-9) return false;
    px = (glm::dot(d, right) / z / (tan_half * aspect) + 1.0) * 0.5 * width;
    py = (1.0 - glm::dot(d, up) / z / tan_half) * 0.5 * height;
    return true;
  }
};

// A unit sphere resting on a 8 x 8 floor, sky elsewhere. Objects: 0 sky, 1 sphere, 2 floor.
struct Hit {
  int object = 0;
  glm::dvec3 p{0.0}, n{0.0};
  double t = 0.0;
};

Hit trace(glm::dvec3 o, glm::dvec3 d) {
  Hit hit;
  const glm::dvec3 c(0.0, 0.0, 1.0);
  const glm::dvec3 oc = o - c;
  const double b = glm::dot(oc, d), disc = b * b - (glm::dot(oc, oc) - 1.0);
  if (disc > 0.0) {
    const double t = -b - std::sqrt(disc);
    if (t > 1e-6) {
      hit.object = 1;
      hit.t = t;
      hit.p = o + d * t;
      hit.n = glm::normalize(hit.p - c);
    }
  }
  if (d.z < 0.0) {
    const double t = -o.z / d.z;
    const glm::dvec3 p = o + d * t;
    if (std::fabs(p.x) < 4.0 && std::fabs(p.y) < 4.0 && (hit.object == 0 || t < hit.t)) {
      hit.object = 2;
      hit.t = t;
      hit.p = p;
      hit.n = glm::dvec3(0, 0, 1);
    }
  }
  return hit;
}

HostGBuffer render_gbuffer(const Camera& cam, std::vector<Hit>& hits, const Camera* previous) {
  HostGBuffer g(cam.width, cam.height);
  hits.assign(g.n(), Hit{});
  for (int y = 0; y < cam.height; ++y)
    for (int x = 0; x < cam.width; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * cam.width + x;
      const glm::dvec3 d = cam.ray(x, y);
      const Hit h = trace(cam.pos, d);
      hits[i] = h;
      g.base_color_roughness[i] = float4(0.7f, 0.7f, 0.7f, 0.5f);
      g.metallic_specular[i] = float4(0.0f, 0.04f, 0.0f, 0.0f);
      g.view_dir[i] = float4(float(-d.x), float(-d.y), float(-d.z), 0.0f);
      g.material[i] = static_cast<std::uint32_t>(h.object);
      if (h.object == 0) {
        g.flags[i] = PG_GBUF_SKY;
        g.shading_normal[i] = float4(0.0f, 0.0f, 1.0f, 0.0f);
        continue;
      }
      g.flags[i] = 0u;
      g.position_depth[i] =
          float4(float(h.p.x), float(h.p.y), float(h.p.z), float(h.t * glm::dot(d, cam.fwd)));
      g.shading_normal[i] = float4(float(h.n.x), float(h.n.y), float(h.n.z), 0.0f);
      double px = 0.0, py = 0.0;
      if (previous != nullptr && previous->project(h.p, px, py))
        g.motion[i] = float2(float(px - (x + 0.5)), float(py - (y + 0.5)));
      else if (previous != nullptr)
        g.motion[i] = float2(-1e6f, -1e6f);
    }
  return g;
}

// The camera moves and turns between two frames over a sphere on a floor. Every surface pixel
// of the first frame holds a lobe pointing at the world direction L (where L is above its
// horizon). After reprojection, a pixel that sees the same surface as the pixel its motion
// vector lands on (within 2% of the depth, normals within 18 degrees) carries that lobe with
// its mean still pointing at L: within 1e-3 rad where it was reframed (the mean goes through
// world space exactly; M^-1 loses up to ~2.4e-4 near the pole), and within 1e-3 rad plus twice
// the normals' angle where reframing is skipped (dot >= PG_REFRAME_MIN_COS: the two frames differ
// by about that angle, at most 4.5e-3 rad). Pixels whose motion leaves the image, or that land on
// another object with no pixel of their own object around (disocclusion at the sphere's
// silhouette), restart from the initial state: all zeros, k = 0. Pixels between the two cases are
// not judged.
TEST(GuidingKernels, ReprojectionFollowsAMovingCamera) {
  ClRuntime rt;
  const bool small = simulated(rt);
  const int w = small ? 32 : 96, h = small ? 24 : 64;
  const Camera cam0(glm::dvec3(0.0, -6.0, 3.0), glm::dvec3(0.0, 0.0, 0.7), 45.0, w, h);
  const Camera cam1(glm::dvec3(1.6, -5.4, 3.4), glm::dvec3(0.5, 0.2, 0.8), 48.0, w, h);
  std::vector<Hit> hits0, hits1;
  const HostGBuffer g0 = render_gbuffer(cam0, hits0, nullptr);
  const HostGBuffer g1 = render_gbuffer(cam1, hits1, &cam0);
  const glm::dvec3 light = glm::normalize(glm::dvec3(0.3, -0.4, 1.0));
  const float3 lf(float(light.x), float(light.y), float(light.z));

  GuidingSettings settings;
  Guider guider(rt, w, h, settings);
  std::vector<float> state0(8 * g0.n(), 0.0f);
  for (std::size_t j = 0; j < g0.n(); ++j) {
    if (hits0[j].object == 0) continue;
    const sh::pg_frame f = sh::pg_frame_from_normal(sh::pg_float4_xyz(g0.shading_normal[j]));
    const float3 l = sh::pg_to_local(f, lf);
    if (l.z < 0.15f) continue;
    const float2 u = sh::pg_hemisphere_to_square(l);
    // Each pixel's lobe carries its own weight S0, so a kept state names the pixel it came from:
    // a fetch one pixel off on the same object would pass every other check here.
    const float s0 = 1.0f + 0.01f * static_cast<float>(j % 97);
    set_state(state0, j, make_state(u.x, u.y, 0.002f, 0.003f, 0.0005f, 0.6f, 10.0f, s0));
  }
  guider.write_state(state0);
  guider.reproject(upload(rt, g1), upload(rt, g0));
  std::vector<float> state1;
  guider.read_state(state1);

  std::size_t kept = 0, kept_reframed = 0, outside = 0, disoccluded = 0, sky = 0;
  double worst = 0.0;
  const pg_kernel_settings p = to_kernel_settings(settings);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * w + x;
      const sh::pg_pmm_state s = state_at(state1, i);
      const std::string what = "pixel " + std::to_string(x) + "," + std::to_string(y);
      const bool zero = s.s0 == float4(0.0f) && s.s1 == float4(0.0f);
      if (hits1[i].object == 0) {
        EXPECT_TRUE(zero) << what << " (sky) " << describe(s);
        ++sky;
        continue;
      }
      double qx = 0.0, qy = 0.0;
      const bool in_front = cam0.project(hits1[i].p, qx, qy);
      if (!in_front || qx < -1.0 || qy < -1.0 || qx >= w + 1.0 || qy >= h + 1.0) {
        EXPECT_TRUE(zero) << what << " (came into view) " << describe(s);
        ++outside;
        continue;
      }
      if (qx < 1.0 || qy < 1.0 || qx >= w - 1.0 || qy >= h - 1.0) continue;  // at the border
      const std::size_t j =
          static_cast<std::size_t>(std::floor(qy)) * w + static_cast<std::size_t>(std::floor(qx));
      const Hit& before = hits0[j];
      if (before.object != hits1[i].object) {
        // History may come from a neighbour of j that shows this object (pg_history_candidate);
        // where none of the 3x3 does, the pixel was disoccluded.
        bool object_nearby = false;
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx)
            object_nearby |=
                hits0[j + static_cast<std::ptrdiff_t>(dy) * w + dx].object == hits1[i].object;
        if (object_nearby) continue;  // not judged
        EXPECT_TRUE(zero) << what << " (disoccluded) " << describe(s);
        ++disoccluded;
        continue;
      }
      const double depth = g1.position_depth[i].w;
      if (glm::length(before.p - hits1[i].p) > 0.02 * depth ||
          glm::dot(before.n, hits1[i].n) < 0.95)
        continue;  // not judged
      const sh::pg_pmm_state s_before = state_at(state0, j);
      if (s_before.s1.w == 0.0f) {
        EXPECT_TRUE(zero) << what << " (no lobe before) " << describe(s);
        continue;
      }
      const sh::pg_frame f = sh::pg_frame_from_normal(sh::pg_float4_xyz(g1.shading_normal[i]));
      if (sh::pg_to_local(f, lf).z < 0.05f) continue;  // L near the new horizon: either is right
      ++kept;
      // The kernel reframes unless the two hemisphere frames nearly agree
      // (pg_pmm_needs_reframe); then the state is copied and the frames differ by at most
      // (twice) the larger of the normals' and the tangents' angles.
      const sh::pg_frame f_before =
          sh::pg_frame_from_normal(sh::pg_float4_xyz(g0.shading_normal[j]));
      const sh::pg_frame f_now = sh::pg_frame_from_normal(sh::pg_float4_xyz(g1.shading_normal[i]));
      const bool reframed = sh::pg_pmm_needs_reframe(f_before, f_now);
      kept_reframed += reframed;
      const double frame_angle =
          std::max(std::acos(std::min(1.0, double(sh::dot(f_now.n, f_before.n)))),
                   std::acos(std::min(1.0, double(sh::dot(f_now.t, f_before.t)))));
      const double allowed = 1e-3 + (reframed ? 0.0 : 2.0 * frame_angle);
      ASSERT_EQ(s.s1.w, 10.0f) << what << " " << describe(s);
      EXPECT_EQ(s.s0.x, s_before.s0.x) << what;
      EXPECT_EQ(s.s0.y, s_before.s0.y) << what;
      const sh::pg_pmm_model m = sh::pg_pmm_model_from_state(s, p);
      ASSERT_TRUE(m.valid) << what;
      EXPECT_GT(m.l11, 0.0f);
      EXPECT_GT(m.l22, 0.0f);
      const float3 mean = sh::pg_to_world(f, sh::pg_square_to_hemisphere(float2(m.mx, m.my)));
      const double angle = std::acos(std::clamp(double(sh::dot(mean, lf)), -1.0, 1.0));
      if (reframed) worst = std::max(worst, angle);
      EXPECT_LT(angle, allowed) << what << (reframed ? " (reframed)" : " (copied)");
    }
  // Every case occurred: a moving camera over a sphere must show all of them.
  EXPECT_GT(kept * 3, g1.n() - sky);
  EXPECT_GE(kept_reframed, 20);  // enough reframed pixels to exercise the change of frame
  EXPECT_GT(outside, 0u);
  EXPECT_GT(disoccluded, 0u);
  EXPECT_GT(sky, 0u);
  std::printf(
      "[ info     ] %zu kept (%zu reframed, worst reframed mean off by %.2g rad), %zu came "
      "into view, %zu disoccluded, %zu sky\n",
      kept, kept_reframed, worst, outside, disoccluded, sky);
}

// ---- unpack_gbuffer ------------------------------------------------------------------------

// A pinhole camera at `from` looking at `at` (include/rtpg/guiding_layout.h, "Cameras").
rtpg::pg_pinhole_camera pinhole(float3 from, float3 at, float tan_half_fov_y, float aspect) {
  const float3 f = glm::normalize(at - from);
  const float3 r = glm::normalize(glm::cross(f, float3(0, 1, 0)));
  const float3 u = glm::cross(r, f);
  return {from.x, from.y, from.z,         r.x,   r.y, r.z, u.x, u.y, u.z, f.x,
          f.y,    f.z,    tan_half_fov_y, aspect};
}

// The device's unpack of a packed G-buffer (kernels/unpack_gbuffer.cl) equals the host's
// (kernels/shared/gbuffer_packing.h) at odd sizes (the last work-group's padding must write
// nothing), with the camera moving, still, moving with every point behind its last position, and
// without jitter: bit for bit where the unpacking is integer arithmetic and exact float products
// (depths, halves, flags, material ids, a still camera's zero motion, the sky's position), within
// 8 units in the last place per component for the normal (sqrt and a division: 3 and 2.5 ulp in
// OpenCL 1.2) and for the view direction plus its film point's division carried through the
// camera's spread, and within the rounding of their normalisations, dot products and
// divisions for the positions and the motion, which a device may compute with fused
// multiply-adds. A guided frame then reads these channels as if they had been uploaded.
TEST(GuidingKernels, UnpackGBufferMatchesTheHostUnpack) {
  ClRuntime rt;
  Random r(808);
  const std::vector<std::pair<int, int>> sizes =
      simulated(rt) ? std::vector<std::pair<int, int>>{{13, 9}, {1, 1}, {65, 1}}
                    : std::vector<std::pair<int, int>>{{93, 61}, {1, 1}, {301, 3}, {64, 2}};
  enum class Motion { moved, still, behind, no_jitter };
  for (const Motion motion : {Motion::moved, Motion::still, Motion::behind, Motion::no_jitter}) {
    for (const auto& [w, h] : sizes) {
      SCOPED_TRACE(std::to_string(w) + "x" + std::to_string(h) + " case " +
                   std::to_string(static_cast<int>(motion)));
      HostGBuffer g = random_gbuffer(r, w, h);
      const std::size_t n = g.n();
      for (std::size_t i = 0; i < n; ++i) {
        g.material[i] = static_cast<std::uint32_t>(r.uniform(0.0f, 1.0f) * PG_PACKED_MATERIAL_MAX);
        if (i % 7 == 0) g.base_color_roughness[i].x = r.uniform(0.0f, 1e-5f);  // subnormal halves
        if ((g.flags[i] & PG_GBUF_SKY) != 0u) g.position_depth[i].w = 0.0f;
      }
      const float aspect = static_cast<float>(w) / static_cast<float>(h);
      const float3 eye(1.0f, 1.0f, 4.0f);
      const rtpg::pg_gbuffer_cameras cameras{
          pinhole(eye, float3(1.0f, 1.0f, 0.0f), 0.6f, aspect),
          motion == Motion::behind
              ? pinhole(float3(1.0f, 1.0f, -4.0f), float3(1.0f, 1.0f, -8.0f), 0.6f, aspect)
              : pinhole(float3(1.3f, 0.8f, 4.2f), float3(0.9f, 1.1f, 0.0f), 0.6f, aspect),
          w,
          h,
          motion == Motion::still ? 0 : 1,
          motion == Motion::no_jitter ? 0 : 1,
          77u,
          static_cast<std::uint32_t>(w + h)};
      std::vector<sh::uint4> surface(n);
      std::vector<sh::uint2> shading(n);
      for (std::size_t i = 0; i < n; ++i) {
        surface[i] = sh::pg_pack_gbuffer_surface(g.position_depth[i], g.shading_normal[i],
                                                 g.base_color_roughness[i]);
        shading[i] = sh::pg_pack_gbuffer_shading(g.metallic_specular[i], g.flags[i], g.material[i]);
      }
      const GuiderPackedGBuffer packed = make_guider_packed_gbuffer(rt.context(), w, h);
      rt.queue().enqueueWriteBuffer(packed.surface, CL_FALSE, 0, n * 16, surface.data());
      rt.queue().enqueueWriteBuffer(packed.shading, CL_FALSE, 0, n * 8, shading.data());
      const GuiderGBuffer out =
          make_guider_gbuffer(rt.context(), w, h, 0, KernelAccess::read_write);
      Guider guider(rt, w, h);
      guider.unpack_gbuffer(packed, out, cameras);
      EXPECT_GE(guider.last_times().unpack_ms, 0.0);
      HostGBuffer d(w, h);
#define RTPG_READ(name, type, bytes) \
  rt.queue().enqueueReadBuffer(out.name, CL_TRUE, 0, n*(bytes), d.name.data());
      PG_GBUFFER_CHANNELS(RTPG_READ)
#undef RTPG_READ
      const auto same4 = [](float4 a, float4 b) {
        return same_bits(a.x, b.x) && same_bits(a.y, b.y) && same_bits(a.z, b.z) &&
               same_bits(a.w, b.w);
      };
      constexpr float eps = std::numeric_limits<float>::epsilon();
      const auto near_unit = [](float4 a, float4 b) {
        for (int c = 0; c < 4; ++c)
          if (!(std::fabs(a[c] - b[c]) <= 8.0f * eps)) return false;
        return true;
      };
      const float3 camera_forward(cameras.current.forward_x, cameras.current.forward_y,
                                  cameras.current.forward_z);
      std::size_t moving = 0;
      for (std::size_t i = 0; i < n; ++i) {
        const bool sky = (g.flags[i] & PG_GBUF_SKY) != 0u;
        const sh::uint x = static_cast<sh::uint>(i % static_cast<std::size_t>(w)),
                       y = static_cast<sh::uint>(i / static_cast<std::size_t>(w));
        const float3 ray = sh::pg_gbuffer_camera_ray(cameras, x, y);
        const float4 pd = sh::pg_gbuffer_position_depth(cameras.current, ray,
                                                        sh::pg_unpack_gbuffer_depth(surface[i]));
        ASSERT_TRUE(same_bits(d.position_depth[i].w, g.position_depth[i].w)) << i;
        // The film point (x + jitter) / width is a division, 3 ulp on a device (docs/design.md,
        // "Floating point on other devices"), which the ray carries times the film's spread,
        // 2 tan(fov / 2) (aspect + 1): to the point, times its depth along the view axis (the
        // ray's forward component is 1 there); to the view direction, over the ray's length
        // before normalisation, 1 / (v . forward). At the centre of the 301x3 image (a view
        // 176 degrees wide) that is 2e-5 of the view direction, a few ulp at 93x61.
        const float spread =
            2.0f * cameras.current.tan_half_fov_y * (cameras.current.aspect + 1.0f);
        const float film_error = 3.0f * eps * spread;
        // The ray's few ulp, scaled by the distance to the point, on top of the eye's position.
        const float reach = glm::length(float3(pd) - eye);
        for (int c = 0; c < 3; ++c)
          ASSERT_NEAR(d.position_depth[i][c], pd[c],
                      16.0f * eps * (4.0f + reach) + film_error * pd.w)
              << i << " " << c;
        if (sky) {
          ASSERT_TRUE(same4(d.position_depth[i], float4(0.0f))) << i;
        }
        const float4 view = sh::pg_gbuffer_view_dir(ray);
        const float view_tolerance =
            8.0f * eps + film_error * std::fabs(glm::dot(float3(view), camera_forward));
        for (int c = 0; c < 3; ++c)
          ASSERT_NEAR(d.view_dir[i][c], view[c], view_tolerance) << i << " " << c;
        ASSERT_EQ(d.view_dir[i].w, 0.0f) << i;
        ASSERT_TRUE(
            near_unit(d.shading_normal[i], sh::pg_unpack_gbuffer_shading_normal(surface[i])))
            << i;
        ASSERT_TRUE(same4(d.base_color_roughness[i],
                          sh::pg_unpack_gbuffer_base_color_roughness(surface[i])))
            << i;
        ASSERT_TRUE(
            same4(d.metallic_specular[i], sh::pg_unpack_gbuffer_metallic_specular(shading[i])))
            << i;
        ASSERT_EQ(d.flags[i], g.flags[i]) << i;
        ASSERT_EQ(d.material[i], g.material[i]) << i;
        const float2 m = sky ? float2(0.0f) : sh::pg_gbuffer_motion(cameras, float3(pd), x, y);
        if (m != float2(0.0f)) ++moving;
        // The points lie 1-5 units in front of the cameras: the projection's rounding is a few
        // ulp of the film coordinate, times the image's size; the position's, a few ulp over the
        // ray's cosine to the view axis (down to 0.02 at the edges of the 301x3 image), of the
        // offset.
        const float cosine = glm::dot(ray, sh::pg_camera_forward(cameras.current));
        const float motion_bound = 128.0f * eps * static_cast<float>(std::max(w, h) + 1) +
                                   32.0f * eps * glm::length(m) / cosine;
        ASSERT_NEAR(d.motion[i].x, m.x, motion_bound) << i;
        ASSERT_NEAR(d.motion[i].y, m.y, motion_bound) << i;
        if (m == float2(0.0f)) {
          ASSERT_EQ(d.motion[i], float2(0.0f)) << i;
        }
      }
      // Motion everywhere but on the sky where the camera moved with the points in front of it.
      if (motion == Motion::still || motion == Motion::behind) {
        EXPECT_EQ(moving, 0u);
      } else if (n > 20) {
        EXPECT_GT(moving, n / 2);
      }
    }
  }
}

// ---- misuse of the public header -----------------------------------------------------------

// Runs f and expects a GuiderError whose message contains `needle`.
template <typename F>
void expect_guider_error(F f, const std::string& needle) {
  try {
    f();
    ADD_FAILURE() << "no GuiderError; expected one naming " << needle;
  } catch (const GuiderError& e) {
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos)
        << "message \"" << e.what() << "\" does not name " << needle;
  }
}

TEST(GuiderMisuse, WrongBuffersAreNamedAndLeaveTheGuiderUsable) {
  ClRuntime rt;
  const int w = 21, h = 11;
  Random r(404);
  const HostGBuffer hg = random_gbuffer(r, w, h);
  const GuiderGBuffer good = upload(rt, hg);
  const GuiderVpls vpls = upload(rt, random_vpls(r, hg.n()), w, h);
  const GuiderSamples samples = make_guider_samples(rt.context(), w, h);
  Guider guider(rt, w, h);
  const std::vector<float> state = random_states(r, hg.n(), 32.0f, false);
  guider.write_state(state);

  // Each G-buffer member one element short, then not set at all.
  struct Member {
    const char* name;
    cl::Buffer GuiderGBuffer::*field;
    std::size_t element;
  };
#define RTPG_MEMBER(name, type, bytes) {#name, &GuiderGBuffer::name, bytes},
  const Member members[] = {PG_GBUFFER_CHANNELS(RTPG_MEMBER)};
#undef RTPG_MEMBER
  for (const Member& m : members) {
    GuiderGBuffer bad = good;
    bad.*m.field = cl::Buffer(rt.context(), CL_MEM_READ_WRITE, (hg.n() - 1) * m.element);
    const std::string name(m.name);
    expect_guider_error([&] { guider.reproject(bad, good); }, "current." + name);
    expect_guider_error([&] { guider.reproject(good, bad); }, "previous." + name);
    expect_guider_error([&] { guider.sample(bad, 1, 0, 0, samples); }, "current." + name);
    expect_guider_error([&] { guider.train(bad, vpls, 1, 0); }, "current." + name);
    bad.*m.field = cl::Buffer();
    expect_guider_error([&] { guider.sample(bad, 1, 0, 0, samples); }, "current." + name);
    // A G-buffer of a larger resolution (one more row): its rows would be misread.
    bad.*m.field = cl::Buffer(rt.context(), CL_MEM_READ_WRITE, (hg.n() + w) * m.element);
    expect_guider_error([&] { guider.sample(bad, 1, 0, 0, samples); }, "current." + name);
    expect_guider_error([&] { guider.reproject(good, bad); }, "previous." + name);
  }
  cl::Buffer short16(rt.context(), CL_MEM_READ_WRITE, hg.n() * 16 - 16);
  cl::Buffer short4(rt.context(), CL_MEM_READ_WRITE, hg.n() * 4 - 4);
  cl::Buffer short8(rt.context(), CL_MEM_READ_WRITE, hg.n() * 8 - 8);
  // Each sample channel one element short.
  struct SampleMember {
    const char* name;
    cl::Buffer GuiderSamples::*field;
    const cl::Buffer* too_short;
  };
#define RTPG_MEMBER(name, type, bytes) \
  {#name, &GuiderSamples::name, bytes == 16 ? &short16 : bytes == 8 ? &short8 : &short4},
  const SampleMember sample_members[] = {PG_SAMPLE_CHANNELS(RTPG_MEMBER)};
#undef RTPG_MEMBER
  for (const SampleMember& m : sample_members) {
    GuiderSamples bad = samples;
    bad.*m.field = *m.too_short;
    expect_guider_error([&] { guider.sample(good, 1, 0, 0, bad); },
                        std::string("samples.") + m.name);
  }
  expect_guider_error(
      [&] {
        guider.train(good, {short16, vpls.normal_radiance}, 1, 0);
      },
      "vpls.position");
  expect_guider_error(
      [&] {
        guider.train(good, {vpls.position, short16}, 1, 0);
      },
      "vpls.normal_radiance");
  expect_guider_error([&] { guider.write_state(std::vector<float>(state.size() - 1)); },
                      "write_state");
  expect_guider_error([&] { guider.write_state(std::vector<float>(state.size() + 8)); },
                      "write_state");
  expect_guider_error([&] { guider.write_state({}); }, "write_state");

  // None of that touched the state, and the guider still works.
  std::vector<float> after;
  guider.read_state(after);
  ASSERT_EQ(after.size(), state.size());
  for (std::size_t c = 0; c < state.size(); ++c) ASSERT_TRUE(same_bits(after[c], state[c])) << c;
  guider.sample(good, 1, 0, 0, samples);
  guider.train(good, vpls, 1, 0);
  guider.reproject(good, good);
  EXPECT_GT(guider.count_trained(), 0u);
}

// The device's packing of the samples for their way back (kernels/pack_samples.cl) equals the
// host's (kernels/shared/sample_packing.h) at odd sizes: the density and strategy bit for bit,
// the direction's octahedral floats within the few ulp of the device's division (OpenCL 1.2:
// 2.5), so that the host's decoded direction lies within 1e-6 rad of the sampled one.
TEST(GuidingKernels, PackSamplesMatchesTheHostPacking) {
  ClRuntime rt;
  Random r(909);
  const std::vector<std::pair<int, int>> sizes =
      simulated(rt) ? std::vector<std::pair<int, int>>{{13, 9}, {1, 1}}
                    : std::vector<std::pair<int, int>>{{93, 61}, {1, 1}, {301, 3}};
  for (const auto& [w, h] : sizes) {
    SCOPED_TRACE(std::to_string(w) + "x" + std::to_string(h));
    const std::size_t n = static_cast<std::size_t>(w) * h;
    std::vector<float4> direction_pdf(n);
    std::vector<std::uint32_t> strategy(n);
    for (std::size_t i = 0; i < n; ++i) {
      const float3 d = r.unit();
      const float u = r.uniform();
      direction_pdf[i] = float4(d.x, d.y, d.z, u < 0.1f ? 0.0f : r.uniform(1e-3f, 1e3f));
      strategy[i] = u < 0.1f ? PG_STRATEGY_NONE : (u < 0.6f ? PG_STRATEGY_BSDF : PG_STRATEGY_GUIDE);
    }
    const GuiderSamples samples =
        make_guider_samples(rt.context(), w, h, 0, KernelAccess::read_write);
    rt.queue().enqueueWriteBuffer(samples.direction_pdf, CL_FALSE, 0, n * 16, direction_pdf.data());
    rt.queue().enqueueWriteBuffer(samples.strategy, CL_FALSE, 0, n * 4, strategy.data());
    // The mixture's channels are read by nothing here, but a kernel argument must be defined.
    const std::vector<float4> zeros4(n, float4(0.0f));
    rt.queue().enqueueWriteBuffer(samples.mixture_a, CL_FALSE, 0, n * 16, zeros4.data());
    rt.queue().enqueueWriteBuffer(samples.mixture_b, CL_FALSE, 0, n * 8, zeros4.data());
    const GuiderPackedSamples packed = make_guider_packed_samples(rt.context(), w, h);
    Guider guider(rt, w, h);
    guider.pack_samples(samples, packed);
    EXPECT_GE(guider.last_times().pack_samples_ms, 0.0);
    std::vector<float2> direction(n);
    std::vector<float> pdf_strategy(n);
    rt.queue().enqueueReadBuffer(packed.direction, CL_FALSE, 0, n * 8, direction.data());
    rt.queue().enqueueReadBuffer(packed.pdf_strategy, CL_TRUE, 0, n * 4, pdf_strategy.data());
    for (std::size_t i = 0; i < n; ++i) {
      const float3 d(direction_pdf[i]);
      ASSERT_TRUE(
          same_bits(pdf_strategy[i], sh::pg_pack_sample_density(direction_pdf[i].w, strategy[i])))
          << i;
      const float2 host = sh::pg_pack_direction(d);
      ASSERT_NEAR(direction[i].x, host.x, 4.0f * std::numeric_limits<float>::epsilon()) << i;
      ASSERT_NEAR(direction[i].y, host.y, 4.0f * std::numeric_limits<float>::epsilon()) << i;
      ASSERT_LT(rtpg::testing::angle_between(sh::pg_unpack_direction(direction[i]), d), 1e-6) << i;
    }
  }
}

// The device's unpack of packed VPLs (kernels/unpack_vpls.cl) equals the host's (kernels/shared/
// vpl_packing.h, pg_unpack_vpl with the BSDF's density evaluated on the host) at odd sizes: the
// radiance, info and normal words bit for bit (the normal's 8-bit code becomes its 16-bit one in
// integers), the position and the densities within the rounding of the device's square roots and
// divisions (and of its BSDF density for a BSDF sample).
// Overlapped with the training, its time is recorded when the training is waited for.
TEST(GuidingKernels, UnpackVplsMatchesTheHostUnpack) {
  ClRuntime rt;
  Random r(1010);
  const std::vector<std::pair<int, int>> sizes =
      simulated(rt) ? std::vector<std::pair<int, int>>{{13, 9}, {1, 1}}
                    : std::vector<std::pair<int, int>>{{93, 61}, {1, 1}, {301, 3}};
  for (const auto& [w, h] : sizes) {
    SCOPED_TRACE(std::to_string(w) + "x" + std::to_string(h));
    const HostGBuffer g = random_gbuffer(r, w, h);
    const std::size_t n = g.n();
    std::vector<float4> direction_pdf(n), mixture_a(n, float4(0.0f));
    std::vector<float2> mixture_b(n, float2(0.0f));
    std::vector<std::uint32_t> strategy(n), distance(n), radiance(n);
    std::vector<std::uint16_t> normal(n);
    for (std::size_t i = 0; i < n; ++i) {
      const float3 nx(g.shading_normal[i]);
      const float3 wi = r.tilt(nx, 0.0f, 85.0f);
      const float u = r.uniform();
      direction_pdf[i] = float4(wi.x, wi.y, wi.z, r.uniform(0.05f, 5.0f));
      strategy[i] = u < 0.5f ? PG_STRATEGY_BSDF : PG_STRATEGY_GUIDE;
      const float d = u < 0.1f ? 0.0f : (u < 0.2f ? INFINITY : r.uniform(0.01f, 20.0f));
      distance[i] = sh::as_uint(d);
      radiance[i] =
          sh::pg_pack_rgbe(float3(r.uniform(0.0f, 3.0f), r.uniform(), 1e3f * r.uniform()));
      normal[i] = static_cast<std::uint16_t>(sh::pg_pack_unit_vector8(-r.tilt(wi, 0.0f, 80.0f)));
    }
    const GuiderGBuffer dg = upload(rt, g);
    const GuiderSamples samples =
        make_guider_samples(rt.context(), w, h, 0, KernelAccess::read_write);
    const GuiderPackedVpls packed = make_guider_packed_vpls(rt.context(), w, h);
    cl::CommandQueue& q = rt.queue();
    q.enqueueWriteBuffer(samples.direction_pdf, CL_FALSE, 0, n * 16, direction_pdf.data());
    q.enqueueWriteBuffer(samples.strategy, CL_FALSE, 0, n * 4, strategy.data());
    q.enqueueWriteBuffer(samples.mixture_a, CL_FALSE, 0, n * 16, mixture_a.data());
    q.enqueueWriteBuffer(samples.mixture_b, CL_FALSE, 0, n * 8, mixture_b.data());
    q.enqueueWriteBuffer(packed.distance, CL_FALSE, 0, n * 4, distance.data());
    q.enqueueWriteBuffer(packed.radiance, CL_FALSE, 0, n * 4, radiance.data());
    q.enqueueWriteBuffer(packed.normal, CL_FALSE, 0, n * 2, normal.data());
    const GuiderVpls out = make_guider_vpls(rt.context(), w, h, 0, KernelAccess::read_write);
    Guider guider(rt, w, h);
    guider.unpack_vpls(packed, dg, samples, out);
    EXPECT_GE(guider.last_times().unpack_vpls_ms, 0.0);
    std::vector<float4> position(n);
    std::vector<sh::uint4> nr(n);
    q.enqueueReadBuffer(out.position, CL_FALSE, 0, n * 16, position.data());
    q.enqueueReadBuffer(out.normal_radiance, CL_TRUE, 0, n * 16, nr.data());
    std::size_t valid = 0, distant = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const sh::pg_frame frame = sh::pg_frame_from_normal(float3(g.shading_normal[i]));
      const float3 wo = sh::pg_to_local(frame, float3(g.view_dir[i]));
      const sh::pg_lobes lobes = sh::pg_make_lobes(
          sh::pg_material_from_gbuffer(g.base_color_roughness[i], g.metallic_specular[i]), wo);
      const float3 wi = sh::pg_to_local(frame, float3(direction_pdf[i]));
      const float bsdf = sh::pg_bsdf_pdf(lobes, wo, wi);
      // A BSDF sample's density is the device's own evaluation of the lobes: near a sharp GGX
      // peak float32 allows it more than 1e-4 (ggx_relative_error). The message on failure
      // splits the density from its conversion to area measure (docs/design.md, "Floating
      // point on other devices": how a metal's density came out 1.5e-3 off on an H200).
      const double density_allowance =
          strategy[i] == PG_STRATEGY_BSDF ? ggx_relative_error(lobes, wo, wi) : 0.0;
      const sh::pg_vpl host =
          sh::pg_unpack_vpl(distance[i], radiance[i], normal[i], float3(g.position_depth[i]),
                            direction_pdf[i], strategy[i], bsdf);
      const std::uint32_t info = sh::pg_vpl_info(host.normal_radiance);
      ASSERT_EQ(sh::pg_vpl_info(nr[i]), info) << i;
      ASSERT_EQ(nr[i].z, host.normal_radiance.z) << i;
      ASSERT_EQ(nr[i].w, host.normal_radiance.w) << i;
      if ((info & PG_VPL_VALID) == 0u) {
        ASSERT_EQ(position[i], float4(0.0f)) << i;
        continue;
      }
      ++valid;
      distant += (info & PG_VPL_DISTANT) != 0u;
      for (int c = 0; c < 3; ++c)
        ASSERT_NEAR(position[i][c], host.position[c], 1e-5f * (std::fabs(host.position[c]) + 25.0f))
            << i;
      const float device_to_area = sh::pg_vpl_mixture_density(nr[i]) / direction_pdf[i].w,
                  host_to_area =
                      sh::pg_vpl_mixture_density(host.normal_radiance) / direction_pdf[i].w;
      ASSERT_NEAR(position[i].w / host.position.w, 1.0f, 1e-4 + density_allowance)
          << i << " strategy " << strategy[i] << " roughness " << g.base_color_roughness[i].w
          << " to_area " << device_to_area << " / " << host_to_area << " strategy density "
          << position[i].w / device_to_area << " / " << host.position.w / host_to_area
          << " normal bits " << nr[i].x << " / " << host.normal_radiance.x;
      ASSERT_NEAR(
          sh::pg_vpl_mixture_density(nr[i]) / sh::pg_vpl_mixture_density(host.normal_radiance),
          1.0f, 1e-4f)
          << i;
      ASSERT_EQ(nr[i].x, host.normal_radiance.x) << i;
    }
    if (n > 20) {
      EXPECT_GT(valid, n / 2);
      EXPECT_GT(distant, 0u);
    }
    // Left running before an overlapped training (Wait::later), its time is recorded once the
    // training is waited for, with nothing else waited for (the renderer's order where only the
    // training overlaps the next frame).
    Guider overlapped(rt, w, h);
    overlapped.unpack_vpls(packed, dg, samples, out, Guider::Wait::later);
    overlapped.train(dg, out, 7u, 1u, Guider::Wait::later);
    EXPECT_EQ(overlapped.last_times().unpack_vpls_ms, 0.0);
    overlapped.wait_for_training();
    EXPECT_GT(overlapped.last_times().unpack_vpls_ms, 0.0);
    EXPECT_GT(overlapped.last_times().train_ms, 0.0);
  }
}

// unpack_gbuffer refuses a G-buffer kernels may not write, packed channels of another size and
// cameras of another image, naming them; pack_samples samples it may not read.
// Transfers between host channels and device buffers of other sizes are refused, naming the
// channel: a short upload left the rest of the image as the buffer held it, a short download
// read part of it. And buffers of another OpenCL context are refused by every call that takes
// them.
TEST(GuiderMisuse, MissizedTransfersAndForeignBuffersAreRefused) {
  ClRuntime rt;
  const int w = 13, h = 7;
  Random r(405);
  const HostGBuffer hg = random_gbuffer(r, w, h);
  const GuiderGBuffer dev = make_guider_gbuffer(rt.context(), w, h);
  for (const std::size_t size : {hg.n() - 1, std::size_t{0}, hg.n() + 1}) {
    HostGBuffer bad = hg;
    bad.position_depth.resize(size);
    expect_guider_error([&] { enqueue_upload(rt.queue(), bad, dev); }, "position_depth");
  }
  const GuiderSamples samples = make_guider_samples(rt.context(), w, h);
  struct HostSampleChannels {
#define RTPG_TEST_CHANNEL(name, type, bytes) std::vector<shared::type> name;
    PG_SAMPLE_CHANNELS(RTPG_TEST_CHANNEL)
#undef RTPG_TEST_CHANNEL
  } host;
#define RTPG_TEST_RESIZE(name, type, bytes) host.name.resize(hg.n());
  PG_SAMPLE_CHANNELS(RTPG_TEST_RESIZE)
#undef RTPG_TEST_RESIZE
  enqueue_download(rt.queue(), samples, host);
  rt.queue().finish();
  host.direction_pdf.resize(hg.n() - 1);
  expect_guider_error([&] { enqueue_download(rt.queue(), samples, host); }, "direction_pdf");
  rt.queue().finish();

  ClRuntime other;
  Guider guider(rt, w, h);
  const GuiderGBuffer good = upload(rt, hg);
  const GuiderGBuffer foreign = make_guider_gbuffer(other.context(), w, h);
  expect_guider_error([&] { guider.sample(foreign, 1, 0, 0, samples); }, "another OpenCL context");
  expect_guider_error([&] { guider.reproject(good, foreign); }, "another OpenCL context");
  expect_guider_error(
      [&] { guider.sample(good, 1, 0, 0, make_guider_samples(other.context(), w, h)); },
      "another OpenCL context");
}

TEST(GuiderMisuse, UnpackGBufferRefusesReadOnlyAndMissizedBuffers) {
  ClRuntime rt;
  const int w = 9, h = 5;
  Guider guider(rt, w, h);
  const GuiderPackedGBuffer packed = make_guider_packed_gbuffer(rt.context(), w, h);
  const GuiderGBuffer writable =
      make_guider_gbuffer(rt.context(), w, h, 0, KernelAccess::read_write);
  rtpg::pg_gbuffer_cameras cameras{};
  cameras.width = w;
  cameras.height = h;
  expect_guider_error(
      [&] { guider.unpack_gbuffer(packed, make_guider_gbuffer(rt.context(), w, h), cameras); },
      "KernelAccess::read_write");
  GuiderPackedGBuffer bad = packed;
  bad.shading = cl::Buffer(rt.context(), CL_MEM_READ_WRITE, (w * h - 1) * 16);
  expect_guider_error([&] { guider.unpack_gbuffer(bad, writable, cameras); }, "packed.shading");
  expect_guider_error(
      [&] {
        guider.unpack_gbuffer(
            packed, make_guider_gbuffer(rt.context(), w + 1, h, 0, KernelAccess::read_write),
            cameras);
      },
      "unpacked.position_depth");
  rtpg::pg_gbuffer_cameras other = cameras;
  other.height = h + 1;
  expect_guider_error([&] { guider.unpack_gbuffer(packed, writable, other); }, "9x6");
  // pack_samples reads the samples: write-only ones are refused, and packed channels of another
  // size named.
  const GuiderPackedSamples packed_samples = make_guider_packed_samples(rt.context(), w, h);
  expect_guider_error(
      [&] { guider.pack_samples(make_guider_samples(rt.context(), w, h), packed_samples); },
      "KernelAccess::read_write");
  // unpack_vpls writes VPLs and reads the first samples: read-only VPLs and write-only samples
  // are refused.
  const GuiderPackedVpls packed_vpls = make_guider_packed_vpls(rt.context(), w, h);
  const GuiderSamples readable =
      make_guider_samples(rt.context(), w, h, 0, KernelAccess::read_write);
  expect_guider_error(
      [&] {
        guider.unpack_vpls(packed_vpls, writable, readable, make_guider_vpls(rt.context(), w, h));
      },
      "KernelAccess::read_write");
  expect_guider_error(
      [&] {
        guider.unpack_vpls(packed_vpls, writable, make_guider_samples(rt.context(), w, h),
                           make_guider_vpls(rt.context(), w, h, 0, KernelAccess::read_write));
      },
      "first samples are write-only");
  GuiderPackedSamples short_samples = packed_samples;
  short_samples.pdf_strategy = cl::Buffer(rt.context(), CL_MEM_READ_WRITE, (w * h - 1) * 4);
  expect_guider_error(
      [&] {
        guider.pack_samples(make_guider_samples(rt.context(), w, h, 0, KernelAccess::read_write),
                            short_samples);
      },
      "packed.pdf_strategy");
}

TEST(GuiderMisuse, ConfigurationsTheDeviceCannotRunAreRefused) {
  ClRuntime rt;
  // Invalid parameters.
  GuidingSettings bad;
  bad.apron = 9;
  expect_guider_error([&] { Guider g(rt, 8, 8, bad); }, "apron");
  bad = GuidingSettings{};
  bad.pi_min = 0.9f;
  bad.pi_max = 0.5f;
  expect_guider_error([&] { Guider g(rt, 8, 8, bad); }, "pi_min");
  expect_guider_error([&] { Guider g(rt, 0, 8); }, "resolution");
  // Several pixels per work-item read VPLs from global memory: no tile in local memory.
  bad = GuidingSettings{};
  bad.train_lanes = 8;
  bad.train_memory = GuidingSettings::TrainMemory::Local;
  expect_guider_error([&] { Guider g(rt, 8, 8, bad); }, "train_lanes");
  // A work-group size of 0 stands for the device's own in both directions or neither.
  bad = GuidingSettings{};
  bad.local_x = 16;
  bad.local_y = 0;
  expect_guider_error([&] { Guider g(rt, 8, 8, bad); }, "local_x = 16 and local_y = 0");
  // A local size no device accepts.
  GuidingSettings huge;
  huge.local_x = 4096;
  huge.local_y = 4096;
  expect_guider_error([&] { Guider g(rt, 64, 64, huge); }, "local size");
  // The largest local size every guiding kernel accepts, one row high, with the widest apron:
  // its VPL tile of (local_x + 16) x 17 x 48 bytes exceeds the local memory of any device
  // whose work-groups hold more than ~1000 items per 48 KiB.
  std::size_t largest = rt.device().getInfo<CL_DEVICE_MAX_WORK_ITEM_SIZES>().at(0);
  for (cl::Kernel k : {rt.kernel("reproject.cl", "reproject"), rt.kernel("sample.cl", "sample"),
                       rt.kernel("train.cl", "train", "-DPG_TRAIN_LOCAL_TILE=1")})
    largest = std::min(largest, k.getWorkGroupInfo<CL_KERNEL_WORK_GROUP_SIZE>(rt.device()));
  GuidingSettings tile;
  tile.local_x = static_cast<int>(largest);
  tile.local_y = 1;
  tile.apron = 8;
  tile.train_memory = GuidingSettings::TrainMemory::Local;
  const std::size_t bytes = (largest + 16) * 17 * 48;
  if (bytes <= rt.info().local_mem_size) {
    GTEST_SKIP() << "a " << bytes << "-byte tile fits in " << rt.info().local_mem_size << " bytes";
  }
  expect_guider_error([&] { Guider g(rt, 64, 64, tile); }, "local memory");
  // The same local size reading VPLs from global memory needs no tile.
  tile.train_memory = GuidingSettings::TrainMemory::Global;
  EXPECT_NO_THROW(Guider(rt, 64, 64, tile));
}

}  // namespace
}  // namespace rtpg
