// The guiding kernels alone (reproject, sample, train through the Guider) on synthetic but
// realistic inputs: a G-buffer of planes with random normals and materials seen through a
// pinhole camera (a few sky and emitter patches), last frame's G-buffer as the same image two
// pixels away (motion vectors with sub-pixel noise, a few disocclusions), one VPL per pixel
// from a cosine bounce (positions, normals, area densities, radiance with rare bright hits,
// 20% guide-strategy and 10% escaped ones) and trained-like states (k spread over 0..kMax).
//
//   bench_guiding_kernels               1280x720 local-size sweep, 1920x1080 at 16x16 and auto,
//                                       TBB train at 1280x720, one frame's host-device copies
//                                       at 960x540 and 1920x1080
//   bench_guiding_kernels --rtpg_full   also the local-size sweep and TBB train at 1920x1080
//
// Time is the kernel's OpenCL profiling-event time (manual time); every configuration's first
// launch (program build, PoCL's work-group function for that local size) happens before the
// timed loop. Counters:
//   items_per_second     pixels per second (MP/s = this / 1e6)
//   bytes_per_second     bytes the kernel must move per pixel (below) / kernel time
//   copy_bw              what copy_float4 (kernels/copy_float4.cl, 64 MiB each way) reaches,
//                        launched in the same iteration as the kernel
//   copy_fraction        bytes_per_second / copy_bw
//   gflops               (FmaPeak/floatW) multiply-add rate of kernels/fma_peak.cl at vector
//                        width W: 1 is the scalar rate, 8 and 16 what vector code can reach
//   vs_16x16_global      kernel time / the same kernel's time at 16x16 with VPLs read from
//                        global memory and the train kernel's lanes chosen per device,
//                        launched in the same iterations (1 for that one): the local-size
//                        sweep, Local vs Global and the lanes as ratios that host drift does
//                        not disturb
//   row_work_groups      1 where the kernels run in work-groups along rows (local:auto on a CPU
//                        device), 0 for a tile
//   lanes                pixels per work-item of the train kernel (1: train.cl, else
//                        train_wide.cl)
//   flops_per_pixel      floating-point operations along each pixel's path (count_flops, from
//                        the hand counts beside the kernels), mean over the image
//   peak_gflops          FmaPeak/float16's rate, launched in the same iterations
//   roofline_ms          max(bytes / copy_bw, flops / peak): the time the kernel's memory
//                        traffic or arithmetic needs at the machine's measured limits
//   roofline_fraction    roofline_ms / kernel time (1: at the roof; 0.5: within 2x)
// Bytes per pixel, counted from the inputs along each pixel's path through the kernel (each
// buffer element counted once, at its full width; a pixel's neighbours' VPLs are the same
// memory as its own, so the VPL buffers count 32 bytes per pixel):
//   reproject  flags 4 + base_color_roughness 16 + state out 32; guided pixels + motion 8;
//              inside the image + position_depth 2x16 + normal 2x16 + material 2x4;
//              accepted + last frame's state 32
//   sample     flags 4 + direction_pdf/strategy out 20 (the renderer's SampleOutputs::
//              directions: no mixture); surfaces + bcr, normal, view, metallic 4x16; guided +
//              state 32
//   train      state in 32 + out 32 + flags 4 + bcr 16 + VPLs 32; guided + position, normal,
//              view, metallic 4x16 (the work-groups' count records: a few bytes per group)
// FrameTraffic/WxH/{pageable,pinned}: one guided frame's copies between host and device when
// they do not share memory (G-buffer and VPLs up, the samples' directions, densities and
// strategies down, as the renderer moves them without the mixture: bytes_per_pixel) and the rate
// they reach (host_device_GBps), from std::vector or from pinned staging memory.
// TrainTbb runs train.cl's loop (global-memory variant) as plain C++ over TBB on the same
// inputs, calling the same shared functions, and reports kernel_over_tbb = kernel ms / TBB ms
// from both run in every iteration.
#include "bench_common.h"
#include "bench_roofline.h"

#include <map>
#include <memory>
#include <random>
#include <tuple>

#include <tbb/task_arena.h>

#include "rtpg/cl_runtime.h"
#include "rtpg/guiding_settings.h"
#include "rtpg/guider.h"
#include "support/guiding_buffers.h"
#include "rtpg/guiding_layout.h"
#include "shared/gbuffer_packing.h"
#include "shared/guiding_pixel.h"
#include "shared/pmm.h"
#include "shared/pmm_train.h"
#include "shared/vpl_packing.h"

namespace rtpg::bench {
namespace {

namespace sh = rtpg::shared;
using sh::float2;
using sh::float3;
using sh::float4;

// ---- synthetic inputs ------------------------------------------------------------------------

using testing::HostGBuffer;
using testing::HostVpls;

struct Inputs {
  int w = 0, h = 0;
  std::size_t n = 0;
  HostGBuffer cur, prev;
  HostVpls vpls;
  std::vector<float> state;  // 8 floats per pixel
  GuiderGBuffer d_cur, d_prev;
  GuiderVpls d_vpls;
  GuiderSamples d_samples;
  double reproject_bytes = 0, sample_bytes = 0, train_bytes = 0;
  double reproject_flops = 0, sample_flops = 0, train_flops = 0;
  // Of the neighbours a training pixel asks for (frame 1's walk), those that give it a sample,
  // and those with light (count_kept): a Train case on VPLs that train nothing measures an idle
  // kernel (docs/guiding.md, "The train benchmark trained on nothing").
  double train_kept_fraction = 0, train_lit_fraction = 0;
};

float3 tilt(std::mt19937& g, float3 n, float max_deg) {
  std::normal_distribution<float> nd;
  std::uniform_real_distribution<float> u;
  float3 t = sh::cross(n, float3(nd(g), nd(g), nd(g)));
  if (sh::dot(t, t) < 1e-12f) t = sh::cross(n, float3(1, 0, 0));
  t = sh::normalize(t);
  const float a = u(g) * max_deg * PG_PI / 180.0f;
  return sh::normalize(n * std::cos(a) + t * std::sin(a));
}

// The image is split into patches of 32..160 pixels a side, each one plane with its own
// normal (facing the camera within 70 degrees), distance and material out of 12.
void make_gbuffer(Inputs& in, std::mt19937& g) {
  const int w = in.w, h = in.h;
  std::uniform_real_distribution<float> u;
  struct Mat {
    float4 bcr, ms;
    bool emitter;
  };
  std::vector<Mat> mats;
  for (int m = 0; m < 12; ++m) {
    const float rough = m < 2 ? 0.02f : 0.1f + 0.9f * u(g);  // two near-specular (skipped)
    const bool metal = u(g) < 0.25f;
    mats.push_back({float4(u(g), u(g), u(g), rough),
                    float4(metal ? 1.0f : 0.0f, u(g) < 0.5f ? 0.04f : 0.0f, 0, 0), m == 11});
  }
  const float tan_half = std::tan(30.0f * PG_PI / 180.0f), aspect = static_cast<float>(w) / h;
  in.cur = HostGBuffer(in.w, in.h);
  std::vector<int> patch_of(in.n);
  struct Patch {
    float3 n, p0;
    int mat;
    bool sky;
  };
  std::vector<Patch> patches;
  std::uniform_int_distribution<int> side(32, 160);
  std::vector<int> xs{0}, ys{0};
  while (xs.back() < w) xs.push_back(xs.back() + side(g));
  while (ys.back() < h) ys.push_back(ys.back() + side(g));
  for (std::size_t py = 0; py + 1 < ys.size(); ++py)
    for (std::size_t px = 0; px + 1 < xs.size(); ++px) {
      const float cx = (0.5f * (xs[px] + xs[px + 1]) / w * 2.0f - 1.0f) * tan_half * aspect;
      const float cy = (1.0f - 0.5f * (ys[py] + ys[py + 1]) / h * 2.0f) * tan_half;
      const float3 view = sh::normalize(float3(cx, cy, -1.0f));
      Patch p;
      p.n = tilt(g, -view, 70.0f);
      p.p0 = view * (2.0f + 8.0f * u(g));
      const float r = u(g);
      p.sky = py == 0 && r < 0.5f;  // some of the top row is sky
      p.mat = r < 0.03f ? 11 : static_cast<int>(u(g) * 10.99f);
      const int id = static_cast<int>(patches.size());
      patches.push_back(p);
      for (int y = ys[py]; y < std::min(ys[py + 1], h); ++y)
        for (int x = xs[px]; x < std::min(xs[px + 1], w); ++x)
          patch_of[static_cast<std::size_t>(y) * w + x] = id;
    }
  HostGBuffer& c = in.cur;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * w + x;
      const Patch& p = patches[patch_of[i]];
      const float3 dir = sh::normalize(float3(((x + 0.5f) / w * 2.0f - 1.0f) * tan_half * aspect,
                                              (1.0f - (y + 0.5f) / h * 2.0f) * tan_half, -1.0f));
      c.view_dir[i] = float4(-dir, 0.0f);
      c.motion[i] = float2(-2.0f + 0.6f * (u(g) - 0.5f), -1.0f + 0.6f * (u(g) - 0.5f));
      if (p.sky) {
        c.flags[i] = PG_GBUF_SKY;
        continue;
      }
      const float dn = sh::dot(dir, p.n);
      float t = dn < -1e-3f ? sh::dot(p.p0, p.n) / dn : sh::length(p.p0);
      if (!(t > 0.1f) || t > 100.0f) t = sh::length(p.p0);
      const float3 pos = dir * t;
      c.position_depth[i] = float4(pos, -pos.z);
      const float3 ns = tilt(g, p.n, 8.0f);  // bumpy shading normals
      c.shading_normal[i] = float4(ns, 0.0f);
      const Mat& m = mats[p.mat];
      c.base_color_roughness[i] = m.bcr;
      c.metallic_specular[i] = m.ms;
      c.material[i] = static_cast<std::uint32_t>(p.mat);
      std::uint32_t f = 0;
      if (m.emitter) f |= PG_GBUF_EMITTER;
      if (m.bcr.w <= 0.05f) f |= PG_GBUF_DELTA;
      c.flags[i] = f;
    }
  // Last frame: the same image two pixels right and one down; 3% disoccluded (another
  // material), 10% with a slightly different normal (the state is carried across frames).
  in.prev = in.cur;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::size_t j = static_cast<std::size_t>(y) * w + x;
      const int sx = x + 2, sy = y + 1;
      if (sx >= w || sy >= h) continue;
      const std::size_t i = static_cast<std::size_t>(sy) * w + sx;
      in.prev.position_depth[j] = c.position_depth[i];
      in.prev.shading_normal[j] = c.shading_normal[i];
      in.prev.material[j] = c.material[i];
      const float r = u(g);
      if (r < 0.03f)
        in.prev.material[j] = c.material[i] + 1;
      else if (r < 0.13f)
        in.prev.shading_normal[j] =
            float4(tilt(g, sh::pg_float4_xyz(c.shading_normal[i]), 3.0f), 0.0f);
    }
}

// One VPL per surface pixel: a cosine bounce about the shading normal that hits a surface
// 0.3..6 units away (normal facing back within 60 degrees), or escapes (10%). Its mixture
// density D (what trains with the default train_all_samples) is the strategy's for a guided
// sample and 0.5..1.5 times it for a BSDF one (as a mixture of the BSDF and a lobe gives).
void make_vpls(Inputs& in, std::mt19937& g) {
  std::uniform_real_distribution<float> u;
  in.vpls.resize(in.n);
  for (std::size_t i = 0; i < in.n; ++i) {
    if (in.cur.flags[i] & PG_GBUF_SKY) continue;
    const float3 x = sh::pg_float4_xyz(in.cur.position_depth[i]);
    const sh::pg_frame fr = sh::pg_frame_from_normal(sh::pg_float4_xyz(in.cur.shading_normal[i]));
    const float u1 = u(g), u2 = u(g);
    const float r = std::sqrt(u1), phi = 2.0f * PG_PI * u2,
                cz = std::sqrt(std::max(1e-4f, 1.0f - u1));
    const float3 w = sh::pg_to_world(fr, float3(r * std::cos(phi), r * std::sin(phi), cz));
    const float pdf = cz * PG_INV_PI;
    const std::uint32_t strategy = u(g) < 0.8f ? PG_STRATEGY_BSDF : PG_STRATEGY_GUIDE;
    std::uint32_t info = PG_VPL_VALID | (strategy << PG_VPL_STRATEGY_SHIFT);
    const float bright = u(g) < 0.03f ? 50.0f : 1.0f;
    const float mixture = strategy == PG_STRATEGY_GUIDE ? 1.0f : 0.5f + u(g);
    float3 ny(0.0f);
    float to_area = 1.0f;  // solid angle at x to area measure at y (1: a distant VPL)
    if (u(g) < 0.1f) {
      info |= PG_VPL_DISTANT;
      in.vpls.position[i] = float4(w, pdf);
    } else {
      const float d = 0.3f + 5.7f * u(g);
      ny = tilt(g, -w, 60.0f);
      to_area = std::max(1e-3f, -sh::dot(ny, w)) / (d * d);
      in.vpls.position[i] = float4(x + w * d, pdf * to_area);
    }
    const float3 radiance(bright * u(g), bright * u(g), bright * u(g));
    in.vpls.normal_radiance[i] =
        sh::pg_pack_vpl_normal_radiance(ny, mixture * pdf * to_area, radiance, info);
  }
}

// Trained-like states: 10% without a model, 30% at kMax, the rest spread over 1..kMax; lobes
// anywhere in the square, 0.02..0.3 wide, correlated, pi 0.05..0.95.
void make_states(Inputs& in, std::mt19937& g, float k_max) {
  std::uniform_real_distribution<float> u;
  in.state.assign(in.n * 8, 0.0f);
  for (std::size_t i = 0; i < in.n; ++i) {
    const float c = u(g);
    if (c < 0.1f) continue;
    const float k = c < 0.4f ? k_max : std::floor(1.0f + u(g) * (k_max - 0.01f));
    const float mx = 0.05f + 0.9f * u(g), my = 0.05f + 0.9f * u(g);
    const float sx = 0.02f + 0.28f * u(g), sy = 0.02f + 0.28f * u(g), rho = 1.6f * u(g) - 0.8f;
    const float pi = 0.05f + 0.9f * u(g), s0 = std::pow(10.0f, 2.0f * u(g) - 1.0f);
    float* s = &in.state[8 * i];
    s[0] = s0 / pi;
    s[1] = s0;
    s[2] = s0 * mx;
    s[3] = s0 * my;
    s[4] = s0 * (sx * sx + mx * mx);
    s[5] = s0 * (sy * sy + my * my);
    s[6] = s0 * (rho * sx * sy + mx * my);
    s[7] = k;
  }
}

void count_bytes(Inputs& in, const pg_kernel_settings& p) {
  const int w = in.w, h = in.h;
  in.reproject_bytes = in.sample_bytes = in.train_bytes = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * w + x;
      const bool applies =
          sh::pg_guiding_applies(in.cur.flags[i], in.cur.base_color_roughness[i].w, p);
      const bool sky = (in.cur.flags[i] & PG_GBUF_SKY) != 0u;
      double r = 4 + 16 + 32;
      if (applies) {
        r += 8;
        const float2 mv = in.cur.motion[i];
        const int px = static_cast<int>(std::floor(x + 0.5f + mv.x)),
                  py = static_cast<int>(std::floor(y + 0.5f + mv.y));
        if (px >= 0 && py >= 0 && px < w && py < h) {
          r += 2 * 16 + 2 * 16 + 2 * 4;
          const std::size_t j = static_cast<std::size_t>(py) * w + px;
          const float3 n = sh::pg_float4_xyz(in.cur.shading_normal[i]),
                       m = sh::pg_float4_xyz(in.prev.shading_normal[j]);
          if (sh::pg_same_surface(in.cur.position_depth[i], n, in.cur.material[i],
                                  in.prev.position_depth[j], m, in.prev.material[j],
                                  p.reproject_position, p.reproject_normal))
            r += 32;
        }
      }
      in.reproject_bytes += r;
      in.sample_bytes += 4 + 20 + (sky ? 0 : 4 * 16) + (applies ? 32 : 0);
      in.train_bytes += 32 + 32 + 4 + 16 + 32 + (applies ? 4 * 16 : 0);
    }
}

// Floating-point operations along each pixel's path, from the hand counts written beside the
// kernels (kernels/reproject.cl, sample_wide.cl, train_wide.cl; the rules and the breakdown by
// function: docs/guiding.md, "The roofline"): what the pixel itself needs, not what masked lanes
// of its work-item compute besides.
void count_flops(Inputs& in, const pg_kernel_settings& p) {
  const int w = in.w, h = in.h;
  const int side = 2 * p.apron + 1;
  in.reproject_flops = in.sample_flops = in.train_flops = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * w + x;
      const bool applies =
          sh::pg_guiding_applies(in.cur.flags[i], in.cur.base_color_roughness[i].w, p);
      if (!applies) continue;
      const float3 n = sh::pg_float4_xyz(in.cur.shading_normal[i]);
      const sh::pg_frame frame = sh::pg_frame_from_normal(n);
      const sh::pg_lobes lobes = sh::pg_make_lobes(
          sh::pg_material_from_gbuffer(in.cur.base_color_roughness[i], in.cur.metallic_specular[i]),
          sh::pg_to_local(frame, sh::pg_float4_xyz(in.cur.view_dir[i])));
      const bool ggx = lobes.p_specular > 0.0f;
      const float k = in.state[8 * i + 7];
      // reproject: the tests and the frames (78), the reframe where the normals differ (399);
      // a static camera here, so the previous pixel is this one's position in prev.
      const float2 mv = in.cur.motion[i];
      const int px = static_cast<int>(std::floor(x + 0.5f + mv.x)),
                py = static_cast<int>(std::floor(y + 0.5f + mv.y));
      if (px >= 0 && py >= 0 && px < w && py < h) {
        const std::size_t j = static_cast<std::size_t>(py) * w + px;
        const float3 m = sh::pg_float4_xyz(in.prev.shading_normal[j]);
        in.reproject_flops += 78;
        if (sh::pg_pmm_needs_reframe(sh::pg_frame_from_normal(m), frame)) in.reproject_flops += 420;
      }
      // sample: BSDF sampling and its density (248), the GGX lobe (213), a trained model's
      // density (72) and the Gaussian's sampler (107, counted for every trained pixel).
      in.sample_flops += 248 + (ggx ? 213 : 0) + (k > 0.0f ? 72 + 107 : 0);
      // train: 162 + b N + 63 N P + 182 P (b = 158, 264 with GGX; P passes; N neighbours), the
      // count beside kernels/train_wide.cl.
      const int n_samples =
          std::min(std::min(sh::pg_pmm_neighbour_count(k, p), side * side), PG_MAX_TRAIN_SAMPLES);
      const int passes = k >= 0.25f * p.k_max ? 1 : p.em_passes;
      in.train_flops +=
          162.0 + (ggx ? 264.0 : 158.0) * n_samples + 63.0 * n_samples * passes + 182.0 * passes;
    }
}

// What pixel i knows about itself while training (as kernels/train.cl builds it).
sh::pg_train_pixel train_pixel_of(const Inputs& in, std::size_t i) {
  sh::pg_train_pixel px;
  px.x = sh::pg_float4_xyz(in.cur.position_depth[i]);
  px.frame = sh::pg_frame_from_normal(sh::pg_float4_xyz(in.cur.shading_normal[i]));
  px.wo = sh::pg_to_local(px.frame, sh::pg_float4_xyz(in.cur.view_dir[i]));
  px.lobes = sh::pg_make_lobes(
      sh::pg_material_from_gbuffer(in.cur.base_color_roughness[i], in.cur.metallic_specular[i]),
      px.wo);
  return px;
}

// Pixel (x, y)'s training samples of this frame's walk through its window (kernels/train.cl's
// loop): the kept ones in samples and densities, their number returned; the walk's length N in
// *wanted, the neighbours of it inside the image in *asked.
int neighbour_samples(const Inputs& in, const pg_kernel_settings& p, const sh::pg_train_pixel& px,
                      int x, int y, float k, std::uint32_t seed, std::uint32_t frame,
                      float4* samples, float* densities, int* wanted, int* asked) {
  const int w = in.w, h = in.h, side = 2 * p.apron + 1;
  const int n =
      std::min(std::min(sh::pg_pmm_neighbour_count(k, p), side * side), PG_MAX_TRAIN_SAMPLES);
  const sh::uint start = sh::pg_train_walk_start(seed, x, y, static_cast<sh::uint>(w), frame, p);
  int kept = 0;
  *wanted = n;
  *asked = 0;
  for (int s = 0; s < n; ++s) {
    const int wi = sh::pg_train_window_index(start, s, p);
    const int sx = x + wi % side - p.apron, sy = y + wi / side - p.apron;
    if (sx < 0 || sy < 0 || sx >= w || sy >= h) continue;
    const std::size_t j = static_cast<std::size_t>(sy) * w + sx;
    ++*asked;
    kept += sh::pg_train_sample_from_vpl(px, in.vpls.position[j], in.vpls.normal_radiance[j], p,
                                         &samples[kept], &densities[kept]);
  }
  return kept;
}

// train_kept_fraction and train_lit_fraction over every pixel guiding applies to, its
// neighbours of frame 1's walk (seed 1).
void count_kept(Inputs& in, const pg_kernel_settings& p) {
  double asked = 0, kept = 0, lit = 0;
  for (int y = 0; y < in.h; ++y)
    for (int x = 0; x < in.w; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * in.w + x;
      if (!sh::pg_guiding_applies(in.cur.flags[i], in.cur.base_color_roughness[i].w, p)) continue;
      float4 samples[PG_MAX_TRAIN_SAMPLES];
      float densities[PG_MAX_TRAIN_SAMPLES];
      int wanted = 0, pixel_asked = 0;
      const int pixel_kept =
          neighbour_samples(in, p, train_pixel_of(in, i), x, y, in.state[8 * i + 7], 1u, 1u,
                            samples, densities, &wanted, &pixel_asked);
      asked += pixel_asked;
      kept += pixel_kept;
      for (int s = 0; s < pixel_kept; ++s) lit += samples[s].x > 0.0f;
    }
  in.train_kept_fraction = asked > 0 ? kept / asked : 0.0;
  in.train_lit_fraction = asked > 0 ? lit / asked : 0.0;
}

Inputs& inputs_for(int w, int h) {
  static std::map<std::pair<int, int>, std::unique_ptr<Inputs>> cache;
  auto& slot = cache[{w, h}];
  if (slot) return *slot;
  slot = std::make_unique<Inputs>();
  Inputs& in = *slot;
  in.w = w;
  in.h = h;
  in.n = static_cast<std::size_t>(w) * h;
  std::mt19937 g(1234u + static_cast<unsigned>(w));
  const GuidingSettings settings;
  make_gbuffer(in, g);
  make_vpls(in, g);
  make_states(in, g, static_cast<float>(settings.k_max));
  count_bytes(in, to_kernel_settings(settings));
  count_flops(in, to_kernel_settings(settings));
  count_kept(in, to_kernel_settings(settings));
  in.d_cur = testing::upload(runtime(), in.cur);
  in.d_prev = testing::upload(runtime(), in.prev);
  in.d_vpls = testing::upload(runtime(), in.vpls, w, h);
  in.d_samples = make_guider_samples(runtime().context(), w, h);
  return in;
}

// ---- the guiding kernels ---------------------------------------------------------------------

enum class Kernel { Reproject, Sample, Train };

std::unique_ptr<Guider> make_guider(int w, int h, int lx, int ly,
                                    GuidingSettings::TrainMemory memory, int lanes) {
  GuidingSettings settings;
  settings.local_x = lx;
  settings.local_y = ly;
  settings.train_memory = memory;
  settings.train_lanes = lanes;
  // A model per pixel, as the flop and byte counts assume (the synthetic G-buffer's random
  // normals would rarely let a pixel share one; docs/guiding.md, "Models shared by rows").
  settings.rows_per_model = 1;
  auto guider = std::make_unique<Guider>(runtime(), w, h, settings);
  Inputs& in = inputs_for(w, h);
  guider->write_state(in.state);  // first launches of all three kernels, untimed
  guider->reproject(in.d_cur, in.d_prev);
  guider->sample(in.d_cur, 1u, 0u, 0u, in.d_samples);
  guider->train(in.d_cur, in.d_vpls, 1u, 0u);
  return guider;
}

// The configuration every other one is compared with, in the same iterations: 16x16 work-groups,
// VPLs read from global memory and the train kernel's lanes chosen per device (what
// GuidingSettings's Auto picks on CPU devices: as many pixels per work-item as SIMD lanes).
constexpr int kRefX = 16, kRefY = 16, kRefLanes = 0;
constexpr GuidingSettings::TrainMemory kRefMemory = GuidingSettings::TrainMemory::Global;

Guider& reference_guider(int w, int h) {
  static std::unique_ptr<Guider> guider;
  static std::pair<int, int> key;
  if (!guider || key != std::make_pair(w, h)) {
    guider.reset();
    guider = make_guider(w, h, kRefX, kRefY, kRefMemory, kRefLanes);
    key = {w, h};
  }
  return *guider;
}

// One other guider alive at a time (a 1080p guider's buffers take 130 MB): the repetitions of
// one benchmark run back to back and reuse it.
Guider& guider_for(int w, int h, int lx, int ly, GuidingSettings::TrainMemory memory, int lanes) {
  if (lx == kRefX && ly == kRefY && memory == kRefMemory && lanes == kRefLanes)
    return reference_guider(w, h);
  static std::unique_ptr<Guider> guider;
  static std::tuple<int, int, int, int, GuidingSettings::TrainMemory, int> key;
  const auto want = std::make_tuple(w, h, lx, ly, memory, lanes);
  if (!guider || key != want) {
    guider.reset();
    guider = make_guider(w, h, lx, ly, memory, lanes);
    key = want;
  }
  return *guider;
}

double launch(Guider& g, Inputs& in, Kernel k, std::uint32_t frame) {
  switch (k) {
    case Kernel::Reproject:
      g.reproject(in.d_cur, in.d_prev);  // its cost does not depend on the state's values
      return g.last_times().reproject_ms;
    case Kernel::Sample:
      g.sample(in.d_cur, 1u, frame, 0u, in.d_samples, SampleOutputs::directions);
      return g.last_times().sample_ms;
    case Kernel::Train:
      g.write_state(in.state);  // the same trained-like states every time (untimed)
      g.train(in.d_cur, in.d_vpls, 1u, frame);
      return g.last_times().train_ms;
  }
  return 0.0;
}

void BM_GuidingKernel(benchmark::State& state, Kernel kernel, int w, int h, int lx, int ly,
                      GuidingSettings::TrainMemory memory, int lanes) {
  Inputs& in = inputs_for(w, h);
  Guider* g = nullptr;
  Guider* ref = nullptr;
  try {
    ref = &reference_guider(w, h);
    g = &guider_for(w, h, lx, ly, memory, lanes);
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
    return;
  }
  Copy& c = copy();
  FmaPeak& f = fma_peak16();
  double kernel_ms = 0.0, copy_ms = 0.0, fma_ms = 0.0, ref_ms = 0.0;
  std::uint32_t frame = 1;
  for (auto _ : state) {
    const double ms = launch(*g, in, kernel, frame);
    state.SetIterationTime(ms * 1e-3);
    kernel_ms += ms;
    copy_ms += c.run();
    fma_ms += f.run();
    ref_ms += g == ref ? ms : launch(*ref, in, kernel, frame);
    ++frame;
  }
  const double bytes = kernel == Kernel::Reproject ? in.reproject_bytes
                       : kernel == Kernel::Sample  ? in.sample_bytes
                                                   : in.train_bytes;
  const double it = static_cast<double>(state.iterations());
  state.SetItemsProcessed(static_cast<std::int64_t>(in.n) * state.iterations());
  state.SetBytesProcessed(static_cast<std::int64_t>(bytes) * state.iterations());
  const double kernel_bw = bytes * it / (kernel_ms * 1e-3);
  const double copy_bw = Copy::bytes() * it / (copy_ms * 1e-3);
  state.counters["bytes_per_pixel"] = bytes / static_cast<double>(in.n);
  state.counters["copy_bw"] =
      benchmark::Counter(copy_bw, benchmark::Counter::kDefaults, benchmark::Counter::kIs1024);
  state.counters["copy_fraction"] = kernel_bw / copy_bw;
  // The roofline: the kernel's time against max(bytes / copy bandwidth, flops / vector
  // multiply-add rate), both yardsticks launched in the same iterations as the kernel.
  const double flops = kernel == Kernel::Reproject ? in.reproject_flops
                       : kernel == Kernel::Sample  ? in.sample_flops
                                                   : in.train_flops;
  const double peak = f.flops() * it / (fma_ms * 1e-3);  // flop/s
  const double bound_ms = roofline_ms(bytes, flops, copy_ms, fma_ms, it);
  state.counters["flops_per_pixel"] = flops / static_cast<double>(in.n);
  state.counters["peak_gflops"] = peak * 1e-9;
  state.counters["roofline_ms"] = bound_ms;
  state.counters["roofline_fraction"] = bound_ms / (kernel_ms / it);
  state.counters["vs_16x16_global"] = kernel_ms / ref_ms;
  state.counters["row_work_groups"] = g->row_work_groups() ? 1.0 : 0.0;
  if (kernel == Kernel::Train) {
    state.counters["kept_fraction"] = in.train_kept_fraction;
    state.counters["lit_fraction"] = in.train_lit_fraction;
    if (!(in.train_lit_fraction > 0.0))
      state.SkipWithError("the synthetic VPLs give the train kernel no lit sample");
  }
  if (kernel == Kernel::Train) {
    state.counters["local_tile"] = g->train_uses_local_memory() ? 1.0 : 0.0;
    state.counters["lanes"] = g->train_lanes();
  }
}

// ---- train as plain C++ over TBB -------------------------------------------------------------

// train.cl with PG_TRAIN_LOCAL_TILE=0, one pixel per loop iteration, rows spread over TBB.
void tbb_train(const Inputs& in, const pg_kernel_settings& params, std::uint32_t seed,
               std::uint32_t frame, std::vector<float>& out, std::vector<std::uint8_t>& trained) {
  const int w = in.w, h = in.h;
  tbb::parallel_for(tbb::blocked_range<int>(0, h), [&](const tbb::blocked_range<int>& rows) {
    for (int y = rows.begin(); y != rows.end(); ++y)
      for (int x = 0; x < w; ++x) {
        const int i = y * w + x;
        const float* si = &in.state[8 * static_cast<std::size_t>(i)];
        float4 s0(si[0], si[1], si[2], si[3]), s1(si[4], si[5], si[6], si[7]);
        const std::uint32_t f = in.cur.flags[i];
        const float4 bcr = in.cur.base_color_roughness[i];
        std::uint8_t changed = 0;
        if (sh::pg_guiding_applies(f, bcr.w, params) &&
            sh::pg_train_this_frame(s1.w, x, y, frame, params)) {
          sh::pg_pmm_state st;
          st.s0 = s0;
          st.s1 = s1;
          const sh::pg_train_pixel px = train_pixel_of(in, static_cast<std::size_t>(i));
          float4 samples[PG_MAX_TRAIN_SAMPLES];
          float densities[PG_MAX_TRAIN_SAMPLES];
          int n = 0, asked = 0;
          const int kept = neighbour_samples(in, params, px, x, y, s1.w, seed, frame, samples,
                                             densities, &n, &asked);
          int updated = 0;
          st = sh::pg_pmm_train(st, samples, densities, kept, params, static_cast<float>(n),
                                params.em_passes, &updated);
          s0 = st.s0;
          s1 = st.s1;
          changed = static_cast<std::uint8_t>(updated);
        }
        float* so = &out[8 * static_cast<std::size_t>(i)];
        for (int c = 0; c < 4; ++c) {
          so[c] = s0[c];
          so[4 + c] = s1[c];
        }
        trained[i] = changed;
      }
  });
}

void BM_TrainTbb(benchmark::State& state, int w, int h) {
  Inputs& in = inputs_for(w, h);
  Guider& g = reference_guider(w, h);
  const pg_kernel_settings params = to_kernel_settings(g.settings());
  std::vector<float> out(in.n * 8);
  std::vector<std::uint8_t> trained(in.n);
  tbb_train(in, params, 1u, 0u, out, trained);  // warm: pages touched, TBB arena up
  double tbb_ms = 0.0, kernel_ms = 0.0;
  std::uint32_t frame = 1;
  for (auto _ : state) {
    const auto start = std::chrono::steady_clock::now();
    tbb_train(in, params, 1u, frame, out, trained);
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    state.SetIterationTime(ms * 1e-3);
    tbb_ms += ms;
    kernel_ms += launch(g, in, Kernel::Train, frame);
    ++frame;
  }
  // Same step, same inputs: the kernel's and TBB's k must agree (values to rounding).
  std::vector<float> device;
  g.read_state(device);
  std::size_t same_k = 0, guided = 0;
  for (std::size_t i = 0; i < in.n; ++i) {
    same_k += device[8 * i + 7] == out[8 * i + 7];
    guided += trained[i];
  }
  const double it = static_cast<double>(state.iterations());
  state.SetItemsProcessed(static_cast<std::int64_t>(in.n) * state.iterations());
  state.counters["kernel_ms"] = kernel_ms / it;
  state.counters["tbb_ms"] = tbb_ms / it;
  state.counters["kernel_over_tbb"] = kernel_ms / tbb_ms;
  state.counters["k_agreement"] = static_cast<double>(same_k) / static_cast<double>(in.n);
  state.counters["trained_fraction"] = static_cast<double>(guided) / static_cast<double>(in.n);
  state.counters["tbb_threads"] = tbb::this_task_arena::max_concurrency();
}

// ---- host-device traffic of one guided frame ------------------------------------------------

// What crosses the bus each frame when the device does not share host memory
// (host/render/guided_first_bounce.cpp): the G-buffer and the VPLs up, the samples down, through
// the library's own enqueue_upload/enqueue_download. `pageable`: from and into std::vector, as
// the renderer does today; `pinned`: the same copies from and into mapped CL_MEM_ALLOC_HOST_PTR
// staging memory, the way a discrete GPU's driver copies fastest (the number to plan the packing
// of issue 10 against). Wall time from the first enqueue to the queue's finish.
#define RTPG_BENCH_CHANNEL(name, type, bytes) std::vector<sh::type> name;
struct HostSamples {
  PG_SAMPLE_CHANNELS(RTPG_BENCH_CHANNEL)
};
#undef RTPG_BENCH_CHANNEL

struct PinnedFrame {
  std::vector<cl::Buffer> staging;  // kept alive (and mapped) while the views point into them
#define RTPG_BENCH_MAPPED(name, type, bytes) HostChannelView<sh::type> name;
  struct G {
    PG_GBUFFER_CHANNELS(RTPG_BENCH_MAPPED)
  } gbuffer;
  struct V {
    PG_VPL_CHANNELS(RTPG_BENCH_MAPPED)
  } vpls;
  struct S {
    PG_SAMPLE_CHANNELS(RTPG_BENCH_MAPPED)
  } samples;
#undef RTPG_BENCH_MAPPED
  template <class T>
  void map(HostChannelView<T>& c, std::size_t n) {
    staging.emplace_back(runtime().context(), CL_MEM_ALLOC_HOST_PTR, n * sizeof(T));
    c.pointer = static_cast<T*>(runtime().queue().enqueueMapBuffer(
        staging.back(), CL_TRUE, CL_MAP_READ | CL_MAP_WRITE, 0, n * sizeof(T)));
    c.count = n;
  }
  PinnedFrame(const Inputs& in) {
#define RTPG_BENCH_FILL(name, type, bytes) \
  map(gbuffer.name, in.n);                 \
  std::copy(in.cur.name.begin(), in.cur.name.end(), gbuffer.name.pointer);
    PG_GBUFFER_CHANNELS(RTPG_BENCH_FILL)
#undef RTPG_BENCH_FILL
#define RTPG_BENCH_FILL(name, type, bytes) \
  map(vpls.name, in.n);                    \
  std::copy(in.vpls.name.begin(), in.vpls.name.end(), vpls.name.pointer);
    PG_VPL_CHANNELS(RTPG_BENCH_FILL)
#undef RTPG_BENCH_FILL
#define RTPG_BENCH_FILL(name, type, bytes) map(samples.name, in.n);
    PG_SAMPLE_CHANNELS(RTPG_BENCH_FILL)
#undef RTPG_BENCH_FILL
  }
  ~PinnedFrame() {
    try {
      std::size_t i = 0;
      auto unmap = [&](void* p) { runtime().queue().enqueueUnmapMemObject(staging.at(i++), p); };
#define RTPG_BENCH_UNMAP(name, type, bytes) unmap(gbuffer.name.pointer);
      PG_GBUFFER_CHANNELS(RTPG_BENCH_UNMAP)
#undef RTPG_BENCH_UNMAP
#define RTPG_BENCH_UNMAP(name, type, bytes) unmap(vpls.name.pointer);
      PG_VPL_CHANNELS(RTPG_BENCH_UNMAP)
#undef RTPG_BENCH_UNMAP
#define RTPG_BENCH_UNMAP(name, type, bytes) unmap(samples.name.pointer);
      PG_SAMPLE_CHANNELS(RTPG_BENCH_UNMAP)
#undef RTPG_BENCH_UNMAP
      runtime().queue().finish();
    } catch (...) {  // teardown of a benchmark: nothing left to protect
    }
  }
};

template <class G, class V, class S>
double frame_traffic(Inputs& in, const G& gbuffer, const V& vpls, S& samples) {
  const auto start = std::chrono::steady_clock::now();
  cl::CommandQueue& q = runtime().queue();
  enqueue_upload(q, gbuffer, in.d_cur);
  enqueue_upload(q, vpls, in.d_vpls);
  enqueue_download(q, in.d_samples, samples, SampleOutputs::directions);  // as the renderer
  q.finish();
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

void BM_FrameTraffic(benchmark::State& state, int w, int h, bool pinned) {
  Inputs& in = inputs_for(w, h);
  constexpr std::size_t kBytes =
#define RTPG_BENCH_ADD(name, type, bytes) +(bytes)
      0 PG_GBUFFER_CHANNELS(RTPG_BENCH_ADD) PG_VPL_CHANNELS(RTPG_BENCH_ADD) +
      sample_bytes_per_pixel(SampleOutputs::directions);
#undef RTPG_BENCH_ADD
  std::unique_ptr<PinnedFrame> staged;
  HostSamples host_samples;
  if (pinned) {
    staged = std::make_unique<PinnedFrame>(in);
  } else {
#define RTPG_BENCH_RESIZE(name, type, bytes) host_samples.name.resize(in.n);
    PG_SAMPLE_CHANNELS(RTPG_BENCH_RESIZE)
#undef RTPG_BENCH_RESIZE
  }
  auto once = [&] {
    return pinned ? frame_traffic(in, staged->gbuffer, staged->vpls, staged->samples)
                  : frame_traffic(in, in.cur, in.vpls, host_samples);
  };
  once();  // first copies: the driver's page locking and staging allocations, untimed
  double ms_total = 0.0;
  for (auto _ : state) {
    const double ms = once();
    state.SetIterationTime(ms * 1e-3);
    ms_total += ms;
  }
  const double it = static_cast<double>(state.iterations());
  state.SetItemsProcessed(static_cast<std::int64_t>(in.n) * state.iterations());
  state.SetBytesProcessed(static_cast<std::int64_t>(kBytes * in.n) * state.iterations());
  state.counters["bytes_per_pixel"] = static_cast<double>(kBytes);
  state.counters["host_device_GBps"] =
      static_cast<double>(kBytes * in.n) * it / (ms_total * 1e-3) * 1e-9;
}

// ---- the transfer kernels (HostTransfer::packed) ----------------------------------------------

// Transfer/<kernel>/WxH: the three kernels of the packed bus (include/rtpg/guiding_layout.h,
// "Packed ..."), each from its profiled launches, with its roofline like the guiding kernels'.
// Bytes and flops per pixel as counted beside each kernel (kernels/unpack_gbuffer.cl,
// pack_samples.cl, unpack_vpls.cl): divisions, square roots and the hash's integer work count
// one each; for unpack_vpls the BSDF's density only on the pixels whose first sample is the
// BSDF's (half of these).
enum class Transfer { UnpackGBuffer, PackSamples, UnpackVpls };

struct TransferInputs {
  GuiderPackedGBuffer packed_gbuffer;
  GuiderGBuffer unpacked;
  pg_gbuffer_cameras cameras{};
  GuiderSamples samples;
  GuiderPackedSamples packed_samples;
  GuiderPackedVpls packed_vpls;
  GuiderVpls vpls;
  double bsdf_fraction = 0.0;  // of the pixels, those whose VPL takes the BSDF's density
  std::unique_ptr<Guider> guider;
};

rtpg::pg_pinhole_camera transfer_camera(float3 from, float3 at, float aspect) {
  const float3 f = sh::normalize(at - from);
  const float3 r = sh::normalize(sh::cross(f, float3(0, 1, 0)));
  const float3 u = sh::cross(r, f);
  return {from.x, from.y, from.z, r.x, r.y, r.z, u.x, u.y, u.z, f.x, f.y, f.z, 0.6f, aspect};
}

TransferInputs& transfer_inputs(int w, int h) {
  static std::map<std::pair<int, int>, std::unique_ptr<TransferInputs>> cache;
  auto& slot = cache[{w, h}];
  if (slot) return *slot;
  Inputs& in = inputs_for(w, h);
  auto t = std::make_unique<TransferInputs>();
  cl::Context& ctx = runtime().context();
  cl::CommandQueue& q = runtime().queue();
  const std::size_t n = in.n;
  std::mt19937 gen(31);
  std::uniform_real_distribution<float> u01(0.0f, 1.0f);
  // The synthetic G-buffer packed, seen by a camera moving over it with jitter.
  std::vector<sh::uint4> surface(n);
  std::vector<sh::uint2> shading(n);
  for (std::size_t i = 0; i < n; ++i) {
    surface[i] = sh::pg_pack_gbuffer_surface(in.cur.position_depth[i], in.cur.shading_normal[i],
                                             in.cur.base_color_roughness[i]);
    shading[i] = sh::pg_pack_gbuffer_shading(in.cur.metallic_specular[i], in.cur.flags[i],
                                             in.cur.material[i]);
  }
  const float aspect = static_cast<float>(w) / static_cast<float>(h);
  t->cameras = {transfer_camera(float3(1.0f, 1.0f, 4.0f), float3(1.0f, 1.0f, 0.0f), aspect),
                transfer_camera(float3(1.1f, 0.9f, 4.1f), float3(1.0f, 1.0f, 0.0f), aspect),
                w,
                h,
                1,
                1,
                7u,
                3u};
  t->packed_gbuffer = make_guider_packed_gbuffer(ctx, w, h);
  q.enqueueWriteBuffer(t->packed_gbuffer.surface, CL_TRUE, 0, n * 16, surface.data());
  q.enqueueWriteBuffer(t->packed_gbuffer.shading, CL_TRUE, 0, n * 8, shading.data());
  t->unpacked = make_guider_gbuffer(ctx, w, h, 0, KernelAccess::read_write);
  // First samples around each pixel's normal, half the BSDF's; VPLs at, beyond and without hits.
  std::vector<float4> direction_pdf(n), zeros4(n, float4(0.0f));
  std::vector<float2> zeros2(n, float2(0.0f));
  std::vector<std::uint32_t> strategy(n), distance(n), radiance(n);
  std::vector<std::uint16_t> normal(n);
  std::size_t bsdf = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const float3 wi = tilt(gen, float3(in.cur.shading_normal[i]), 80.0f);
    direction_pdf[i] = float4(wi.x, wi.y, wi.z, 0.05f + 5.0f * u01(gen));
    strategy[i] = u01(gen) < 0.5f ? PG_STRATEGY_BSDF : PG_STRATEGY_GUIDE;
    bsdf += strategy[i] == PG_STRATEGY_BSDF;
    const float v = u01(gen);
    distance[i] = sh::as_uint(v < 0.1f ? 0.0f : v < 0.2f ? INFINITY : 0.1f + 5.0f * u01(gen));
    radiance[i] = sh::pg_pack_rgbe(float3(u01(gen), u01(gen), 3.0f * u01(gen)));
    normal[i] = static_cast<std::uint16_t>(sh::pg_pack_unit_vector8(-tilt(gen, wi, 80.0f)));
  }
  t->bsdf_fraction = static_cast<double>(bsdf) / static_cast<double>(n);
  t->samples = make_guider_samples(ctx, w, h, 0, KernelAccess::read_write);
  q.enqueueWriteBuffer(t->samples.direction_pdf, CL_TRUE, 0, n * 16, direction_pdf.data());
  q.enqueueWriteBuffer(t->samples.strategy, CL_TRUE, 0, n * 4, strategy.data());
  q.enqueueWriteBuffer(t->samples.mixture_a, CL_TRUE, 0, n * 16, zeros4.data());
  q.enqueueWriteBuffer(t->samples.mixture_b, CL_TRUE, 0, n * 8, zeros2.data());
  t->packed_samples = make_guider_packed_samples(ctx, w, h);
  t->packed_vpls = make_guider_packed_vpls(ctx, w, h);
  q.enqueueWriteBuffer(t->packed_vpls.distance, CL_TRUE, 0, n * 4, distance.data());
  q.enqueueWriteBuffer(t->packed_vpls.radiance, CL_TRUE, 0, n * 4, radiance.data());
  q.enqueueWriteBuffer(t->packed_vpls.normal, CL_TRUE, 0, n * 2, normal.data());
  t->vpls = make_guider_vpls(ctx, w, h, 0, KernelAccess::read_write);
  t->guider = std::make_unique<Guider>(runtime(), w, h);
  slot = std::move(t);
  return *slot;
}

double launch_transfer(TransferInputs& t, const Inputs& in, Transfer kernel) {
  Guider& g = *t.guider;
  switch (kernel) {
    case Transfer::UnpackGBuffer:
      g.unpack_gbuffer(t.packed_gbuffer, t.unpacked, t.cameras);
      return g.last_times().unpack_ms;
    case Transfer::PackSamples:
      g.pack_samples(t.samples, t.packed_samples);
      return g.last_times().pack_samples_ms;
    case Transfer::UnpackVpls:
      g.unpack_vpls(t.packed_vpls, in.d_cur, t.samples, t.vpls);
      return g.last_times().unpack_vpls_ms;
  }
  return 0.0;
}

void BM_TransferKernel(benchmark::State& state, Transfer kernel, int w, int h) {
  Inputs& in = inputs_for(w, h);
  TransferInputs& t = transfer_inputs(w, h);
  launch_transfer(t, in, kernel);  // first launch: compile the work-group function
  Copy& c = copy();
  FmaPeak& f = fma_peak16();
  double kernel_ms = 0.0, copy_ms = 0.0, fma_ms = 0.0;
  for (auto _ : state) {
    const double ms = launch_transfer(t, in, kernel);
    state.SetIterationTime(ms * 1e-3);
    kernel_ms += ms;
    copy_ms += c.run();
    fma_ms += f.run();
  }
  // Per pixel (the counts beside the kernels).
  const double b = t.bsdf_fraction;
  const double bytes_per_pixel = kernel == Transfer::UnpackGBuffer ? 24.0 + 96.0
                                 : kernel == Transfer::PackSamples
                                     ? 20.0 + 12.0
                                     : 10.0 + 20.0 + 16.0 + 64.0 * b + 32.0;
  const double flops_per_pixel = kernel == Transfer::UnpackGBuffer ? 130.0
                                 : kernel == Transfer::PackSamples ? 15.0
                                                                   : 120.0 + 190.0 * b;
  const double n = static_cast<double>(in.n), it = static_cast<double>(state.iterations());
  const double bound_ms =
      roofline_ms(bytes_per_pixel * n, flops_per_pixel * n, copy_ms, fma_ms, it);
  state.SetItemsProcessed(static_cast<std::int64_t>(in.n) * state.iterations());
  state.counters["bytes_per_pixel"] = bytes_per_pixel;
  state.counters["flops_per_pixel"] = flops_per_pixel;
  state.counters["roofline_ms"] = bound_ms;
  state.counters["roofline_fraction"] = bound_ms / (kernel_ms / it);
}

// ---- registration ----------------------------------------------------------------------------

void register_all(bool full) {
  benchmark::AddCustomContext("opencl_device", runtime().info().device_name);
  benchmark::RegisterBenchmark("CopyFloat4/64MiB", BM_CopyFloat4)
      ->UseManualTime()
      ->Unit(benchmark::kMillisecond);
  for (int width : {1, 8, 16})
    benchmark::RegisterBenchmark(("FmaPeak/float" + std::to_string(width)).c_str(), BM_FmaPeak,
                                 width)
        ->UseManualTime()
        ->Unit(benchmark::kMillisecond);
  using M = GuidingSettings::TrainMemory;
  struct Local {
    int x, y;
  };
  // 0x0: the device's own work-groups (rows on CPUs: host/cl/work_groups.h), the default.
  const std::vector<Local> sweep = {{8, 8}, {16, 16}, {32, 8}, {12, 6}, {0, 0}};
  const std::vector<std::pair<int, int>> sizes = {{1280, 720}, {1920, 1080}};
  for (auto [w, h] : sizes) {
    const bool sweep_here = w == 1280 || full;
    for (const Local& l : sweep) {
      if (!sweep_here && !(l.x == 16 && l.y == 16) && l.x != 0) continue;
      const std::string res = std::to_string(w) + "x" + std::to_string(h);
      const std::string local =
          l.x == 0 ? "/local:auto" : "/local:" + std::to_string(l.x) + "x" + std::to_string(l.y);
      auto add = [&](const std::string& name, Kernel k, M memory, int lanes = kRefLanes) {
        benchmark::RegisterBenchmark(name.c_str(), BM_GuidingKernel, k, w, h, l.x, l.y, memory,
                                     lanes)
            ->UseManualTime()
            ->Unit(benchmark::kMillisecond)
            ->MinTime(0.2);
      };
      add("Reproject/" + res + local, Kernel::Reproject, M::Global);
      add("Sample/" + res + local, Kernel::Sample, M::Global);
      add("Train/" + res + local + "/memory:global", Kernel::Train, M::Global);
      add("Train/" + res + local + "/memory:local", Kernel::Train, M::Local);
      // Pixels per work-item of the train kernel (kernels/train_wide.cl), at 16x16 work-items.
      if (l.x == kRefX && l.y == kRefY)
        for (int lanes : {1, 2, 4, 16})
          add("Train/" + res + local + "/memory:global/lanes:" + std::to_string(lanes),
              Kernel::Train, M::Global, lanes);
    }
  }
  // The bus at the suite's resolution and at 1080p; on a device that shares host memory this is
  // what the renderer avoids by reading the host's buffers in place.
  for (auto [w, h] : std::vector<std::pair<int, int>>{{960, 540}, {1920, 1080}})
    for (bool pinned : {false, true})
      benchmark::RegisterBenchmark(("FrameTraffic/" + std::to_string(w) + "x" + std::to_string(h) +
                                    (pinned ? "/pinned" : "/pageable"))
                                       .c_str(),
                                   BM_FrameTraffic, w, h, pinned)
          ->UseManualTime()
          ->Unit(benchmark::kMillisecond)
          ->MinTime(0.2);
  for (auto [w, h] : std::vector<std::pair<int, int>>{{960, 540}, {1920, 1080}})
    for (auto [name, kernel] :
         std::vector<std::pair<std::string, Transfer>>{{"UnpackGBuffer", Transfer::UnpackGBuffer},
                                                       {"PackSamples", Transfer::PackSamples},
                                                       {"UnpackVpls", Transfer::UnpackVpls}})
      benchmark::RegisterBenchmark(
          ("Transfer/" + name + "/" + std::to_string(w) + "x" + std::to_string(h)).c_str(),
          BM_TransferKernel, kernel, w, h)
          ->UseManualTime()
          ->Unit(benchmark::kMillisecond)
          ->MinTime(0.2);
  for (auto [w, h] : sizes) {
    if (w != 1280 && !full) continue;
    benchmark::RegisterBenchmark(
        ("TrainTbb/" + std::to_string(w) + "x" + std::to_string(h)).c_str(), BM_TrainTbb, w, h)
        ->UseManualTime()
        ->Unit(benchmark::kMillisecond)
        ->MinTime(0.2);
  }
}

}  // namespace
}  // namespace rtpg::bench

int main(int argc, char** argv) {
  rtpg::request_pinned_cpu_device_threads();  // as rtpg itself, before any OpenCL call
  return rtpg::bench::bench_main(argc, argv, rtpg::bench::register_all);
}
