// kernels/svgf_*.cl against SvgfReference (host/denoise/svgf_reference.h), stage by stage, and
// the properties a denoiser must have (docs/denoising.md), on synthetic G-buffers whose answer
// is known.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "denoise/svgf_denoiser.h"
#include "denoise/svgf_reference.h"
#include "rtpg/errors.h"
#include "support/settings_rows.h"

namespace rtpg {
namespace {

// Oclgrind simulates each work-item (about 100x slower than PoCL): keep its images small.
bool simulated(const ClRuntime& rt) {
  return rt.info().platform_name.find("Oclgrind") != std::string::npos;
}

// A G-buffer of a few surfaces the camera sees, as a renderer fills it: a floor plane whose
// depth grows with y (a slope), two boxes at other depths with their own normals and materials,
// sky (a band and a patch), an emitter, textured albedo. The boxes have moved shift_x pixels right
// since frame 0 and the floor has not, with the motion vectors saying so: the boxes' trailing edges
// uncover floor.
GBuffer scene_gbuffer(int w, int h, float shift_x, std::mt19937& rng) {
  GBuffer g;
  g.resize(w, h);
  // A camera looking along +z, the depth axis of the positions below, so that the plane slope
  // (SvgfSettings::depth_slope_from_normal) is that of each surface's tilt, not 0 (a default
  // camera has no field of view).
  CameraView view;
  view.position = glm::vec3(0.0f, 0.0f, 0.0f);
  view.look_at = glm::vec3(0.0f, 0.0f, 1.0f);
  view.up = glm::vec3(0.0f, -1.0f, 0.0f);
  g.camera = make_camera_frame(view, static_cast<float>(w) / static_cast<float>(h));
  g.previous_camera = g.camera;
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * w + x;
      const float bx = static_cast<float>(x) - shift_x;  // a box point's x in frame 0
      const float jitter = 0.5f * (unit(rng) - 0.5f);
      g.motion[i] = glm::vec2(0.0f);
      // Sky: a band across the top, and a patch on the left whose edge splits rows, so that a
      // work-item of the wide a-trous kernel holds pixels with and without a surface.
      if (y < h / 6 || (x < w / 5 + 3 && y < h / 2)) {
        g.flags[i] = PG_GBUF_SKY;
        g.emission[i] = glm::vec4(0.3f, 0.5f, 0.9f, 0.0f);
        continue;
      }
      float sx = static_cast<float>(x);  // this point's x in frame 0
      float depth =
          2.0f + 8.0f * static_cast<float>(h - y) / static_cast<float>(h) + 0.01f * jitter;
      glm::vec3 n(0.0f, 1.0f, 0.0f);
      std::uint32_t material = 0;
      if (bx > 0.25f * w && bx < 0.5f * w && y > h / 3) {  // a box, nearer, facing the camera
        depth = 1.5f;
        n = glm::vec3(0.0f, 0.0f, 1.0f);
        material = 1;
      } else if (bx >= 0.6f * w && y > h / 2) {  // another, tilted
        depth = 3.0f + 0.02f * bx;
        n = glm::normalize(glm::vec3(0.6f, 0.0f, 0.8f));
        material = 2;
      }
      if (material != 0) {
        sx = bx;
        g.motion[i] = glm::vec2(-shift_x, 0.0f);
      }
      g.flags[i] = 0;
      g.position_depth[i] =
          glm::vec4(sx * 0.01f * depth, static_cast<float>(y) * 0.01f, depth, depth);
      g.shading_normal[i] = glm::vec4(n, 0.0f);
      g.material[i] = material;
      // A checker texture: demodulation must keep it sharp.
      const bool checker = ((static_cast<int>(std::floor(sx / 3.0f)) + y / 3) & 1) != 0;
      const float a = material == 0 ? (checker ? 0.8f : 0.2f) : 0.5f + 0.2f * material;
      g.base_color_roughness[i] = glm::vec4(a, 0.9f * a, 0.7f * a, 0.5f);
      if (material == 2 && y > h - 3) {  // an emitter strip
        g.flags[i] |= PG_GBUF_EMITTER;
        g.emission[i] = glm::vec4(4.0f, 3.0f, 2.0f, 0.0f);
      }
    }
  return g;
}

// Noisy colour on g: albedo * (smooth illumination * heavy-tailed noise) + emission.
std::vector<glm::vec3> noisy_colour(const GBuffer& g, std::mt19937& rng) {
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  std::vector<glm::vec3> c(g.pixel_count());
  for (std::size_t i = 0; i < c.size(); ++i) {
    if (!g.has_surface(i)) {
      c[i] = glm::vec3(g.emission[i]);
      continue;
    }
    const float u = unit(rng);
    const float noise = u < 0.05f ? 12.0f * unit(rng) : 0.5f * unit(rng);  // mean 0.8375
    const float light = 1.0f + 0.5f * static_cast<float>(g.material[i]);
    c[i] = glm::vec3(g.base_color_roughness[i]) * light * noise + glm::vec3(g.emission[i]);
  }
  return c;
}

// The denoised colour as the stage images hold it: w = 1.
std::vector<glm::vec4> with_unit_w(const std::vector<glm::vec3>& rgb) {
  std::vector<glm::vec4> out(rgb.size());
  for (std::size_t i = 0; i < rgb.size(); ++i) out[i] = glm::vec4(rgb[i], 1.0f);
  return out;
}

// |a - b| within a relative tolerance of the larger magnitude (plus a floor for values near 0).
void expect_close(const std::vector<glm::vec4>& device, const std::vector<glm::vec4>& host,
                  const char* stage, float tolerance) {
  ASSERT_EQ(device.size(), host.size());
  int reported = 0;
  for (std::size_t i = 0; i < host.size(); ++i)
    for (int c = 0; c < 4; ++c) {
      const float a = device[i][c], b = host[i][c];
      const float scale = std::max({std::fabs(a), std::fabs(b), 1e-3f});
      if (!(std::fabs(a - b) <= tolerance * scale) && reported++ < 5)
        ADD_FAILURE() << stage << ": pixel " << i << " channel " << c << ": device " << a
                      << ", host " << b;
    }
}

struct Case {
  int width, height, local_x, local_y, lanes;
  int atrous_radius = 2, history_atrous_radius = 2;
  int phi_normal = 128;  // a build option of the kernels (kernels/shared/svgf.h)
  int depth_slope_from_normal = 0;
  int history_iteration = 1;  // the default, 0, in the cases that name it (a test of their own)
};

// Every stage of three frames of a panning camera, device against host, for each case: the
// variance and a-trous kernels one pixel per work-item and in vector lanes (widths that are not a
// multiple of the lanes, images narrower than one work-item's lanes).
void expect_equal_to_the_host_reference(ClRuntime& rt, const std::vector<Case>& cases) {
  // Every case's denoiser lives to the end of the test: under Oclgrind, buffers allocated after
  // others were released draw false uninitialised-value reports (docs/denoising.md, "Tests").
  std::vector<std::unique_ptr<SvgfDenoiser>> denoisers;
  for (const Case& c : cases) {
    SCOPED_TRACE(std::to_string(c.width) + "x" + std::to_string(c.height) + ", history iteration " +
                 std::to_string(c.history_iteration) + ", local " + std::to_string(c.local_x) +
                 "x" + std::to_string(c.local_y) + ", lanes " + std::to_string(c.lanes) +
                 ", a-trous radius " + std::to_string(c.atrous_radius) + " (" +
                 std::to_string(c.history_atrous_radius) + " up to the history), phi_normal " +
                 std::to_string(c.phi_normal) + ", depth slope from the normal " +
                 std::to_string(c.depth_slope_from_normal));
    SvgfSettings s;
    s.phi_normal = c.phi_normal;
    s.depth_slope_from_normal = c.depth_slope_from_normal;
    s.atrous_radius = c.atrous_radius;
    s.history_atrous_radius = c.history_atrous_radius;
    s.local_x = c.local_x;
    s.local_y = c.local_y;
    s.lanes = c.lanes;
    s.history_iteration = c.history_iteration;
    // Frame 3's still pixels hold 3 frames of history and take the temporal variance, the rest
    // the spatial one: work-items of the wide kernel with both.
    s.min_history = 3;
    denoisers.push_back(std::make_unique<SvgfDenoiser>(rt, c.width, c.height, s));
    SvgfDenoiser& device = *denoisers.back();
    SvgfReference host(c.width, c.height, s);
    std::mt19937 rng(7);
    for (int f = 0; f < 3; ++f) {
      const GBuffer g = scene_gbuffer(c.width, c.height, 1.7f * static_cast<float>(f), rng);
      const std::vector<glm::vec3> colour = noisy_colour(g, rng);
      const std::vector<glm::vec3> out = device.denoise(colour, g);
      const std::vector<glm::vec3> host_out = host.denoise(colour, g);
      // The exp and log of the device may be 3 ulp off the host's; sums of 25-49 terms.
      const float tol = 2e-4f;
      expect_close(device.read(SvgfStage::Surface), host.stage(SvgfStage::Surface), "surface", 0);
      std::vector<glm::vec4> slope_d, slope_h;
      for (float v : device.read_depth_slope()) slope_d.emplace_back(v);
      for (float v : host.depth_slope()) slope_h.emplace_back(v);
      // The neighbours' depth differences are exact; the plane slope divides and takes square
      // roots, which a device may round an ulp or two apart (1 ulp under Oclgrind).
      expect_close(slope_d, slope_h, "depth slope", c.depth_slope_from_normal != 0 ? 1e-5f : 0.0f);
      // The plane slope compared where it is not 0 (the scene's camera sees its surfaces tilted).
      if (c.depth_slope_from_normal != 0) {
        EXPECT_TRUE(std::any_of(slope_h.begin(), slope_h.end(), [](const glm::vec4& v) {
          return v.x > 0.0f;
        })) << "every plane slope is 0";
      }
      expect_close(device.read(SvgfStage::Integrated), host.stage(SvgfStage::Integrated),
                   "integrated", tol);
      expect_close(device.read(SvgfStage::Moments), host.stage(SvgfStage::Moments), "moments", tol);
      expect_close(device.read(SvgfStage::Illumination), host.stage(SvgfStage::Illumination),
                   "illumination", tol);
      expect_close(device.read(SvgfStage::History), host.stage(SvgfStage::History), "history", tol);
      expect_close(device.read(SvgfStage::Filtered), host.stage(SvgfStage::Filtered), "filtered",
                   tol);
      expect_close(with_unit_w(out), host.stage(SvgfStage::Output), "output", tol);
      expect_close(device.read(SvgfStage::Output), with_unit_w(host_out), "output read back", tol);
    }
  }
}

// With the paper's 5x5 a-trous kernel.
TEST(SvgfKernels, EqualTheHostReferenceAtSeveralSizes) {
  ClRuntime rt;
  std::vector<Case> cases = {{37, 23, 16, 16, 1},
                             {37, 23, 4, 4, 16},
                             {17, 13, 1, 1, 1},
                             {17, 13, 1, 1, 4},
                             {40, 9, 7, 3, 8},
                             {40, 9, 2, 5, 2},
                             {1, 1, 8, 8, 1},
                             {1, 1, 8, 8, 16},
                             {37, 23, 16, 16, 0},
                             // Work-groups per device (rows on CPUs: host/cl/work_groups.h).
                             {37, 23, 0, 0, 0},
                             {37, 23, 0, 0, 1}};
  if (!simulated(rt)) {
    cases.push_back({130, 71, 16, 8, 1});
    cases.push_back({130, 71, 16, 8, 16});
    // Rows of several work-groups each (300 work-items a row: three groups of 100).
    cases.push_back({300, 19, 0, 0, 1});
    cases.push_back({300, 19, 0, 0, 0});
  }
  expect_equal_to_the_host_reference(rt, cases);
}

// The default history iteration, 0 (the cases above take 1, so that the history is not the first
// a-trous pass's input alone): the first iteration's output kept for the next frame. A test of
// its own so that Oclgrind runs it beside the 5x5 cases (oclgrind_test_svgf_part2), with one case.
TEST(SvgfKernels, EqualTheHostReferenceWithTheDefaultHistoryIteration) {
  ClRuntime rt;
  std::vector<Case> cases = {{40, 9, 7, 3, 8, 2, 2, 128, 0, 0}};
  if (!simulated(rt)) cases.push_back({37, 23, 16, 16, 1, 2, 2, 128, 0, 0});
  expect_equal_to_the_host_reference(rt, cases);
}

// The 3x3 a-trous kernel (SvgfSettings::atrous_radius 1) in every iteration, after the history
// iteration only, and before it only. A test of its own so that Oclgrind runs it beside the
// 5x5 cases (tests/CMakeLists.txt, oclgrind_test_svgf_part2).
TEST(SvgfKernels, EqualTheHostReferenceWithThe3x3Kernel) {
  ClRuntime rt;
  expect_equal_to_the_host_reference(rt, {{37, 23, 16, 16, 1, 1, 1},
                                          {37, 23, 4, 4, 16, 1, 1},
                                          {40, 9, 7, 3, 8, 1, 1},
                                          {1, 1, 8, 8, 16, 1, 1},
                                          {37, 23, 16, 16, 1, 1, 2},
                                          {40, 9, 7, 3, 8, 1, 2},
                                          {37, 23, 4, 4, 16, 2, 1}});
}

// The normal weight's exponent other than the paper's 128: the kernels square it out at build
// time, the host reference in a loop over its bits (0: no normal weight; odd ones multiply at every
// bit; 4096, the largest the settings take).
TEST(SvgfKernels, EqualTheHostReferenceAtOtherNormalExponents) {
  ClRuntime rt;
  std::vector<Case> cases;
  if (simulated(rt)) {  // under Oclgrind, one exponent per kernel (the eight cases took 100 s)
    cases = {{37, 23, 4, 4, 1, 2, 2, 7}, {37, 23, 4, 4, 16, 2, 2, 4096}};
  } else {
    for (int phi : {0, 1, 7, 4096})
      for (int lanes : {1, 16}) cases.push_back({37, 23, 4, 4, lanes, 2, 2, phi});
  }
  expect_equal_to_the_host_reference(rt, cases);
}

// pg_svgf_plane_slope is the screen-space depth slope of the plane through the pixel: for
// planes at several tilts seen through pixel centres, it equals max(|dz/dx|, |dz/dy|), in depth
// per pixel, of the plane's exact depth (in double, by central differences a thousandth of a
// pixel wide) to 1e-3 relative.
TEST(SvgfPlaneSlope, IsTheDepthSlopeOfThePlaneThroughThePixel) {
  const int width = 160, height = 90;
  CameraView view;
  view.position = glm::vec3(0.3f, 1.2f, 4.0f);
  view.look_at = glm::vec3(0.0f, 0.5f, 0.0f);
  const CameraFrame camera = make_camera_frame(view, static_cast<float>(width) / height);
  const shared::pg_svgf_view v = to_svgf_view(camera, height);
  int checked = 0;
  for (const glm::vec3& normal_unnormalised : {glm::vec3(0, 1, 0), glm::vec3(0.2f, 1, 0.5f),
                                               glm::vec3(1, 0.1f, 0.3f), glm::vec3(0, 0, 1)}) {
    const glm::dvec3 n = glm::normalize(glm::dvec3(normal_unnormalised));
    const glm::dvec3 on_plane(0.0, 0.2, 0.0), eye(camera.position), forward(camera.forward);
    // The camera depth where the ray through film point (px, py) pixels meets the plane.
    const auto depth_at = [&](double px, double py) {
      const double tan_y = camera.tan_half_fov_y, aspect = camera.aspect;
      const glm::dvec3 d = forward +
                           (2.0 * px / width - 1.0) * tan_y * aspect * glm::dvec3(camera.right) +
                           (1.0 - 2.0 * py / height) * tan_y * glm::dvec3(camera.up);
      const double t = glm::dot(n, on_plane - eye) / glm::dot(n, d);  // d has unit depth
      return t;
    };
    for (int y = 10; y < height - 10; y += 7)
      for (int x = 10; x < width - 10; x += 9) {
        const double cx = x + 0.5, cy = y + 0.5, h = 1e-3;
        const double z = depth_at(cx, cy);
        if (!(z > 0.0)) continue;
        const double slope = std::max(std::fabs(depth_at(cx + h, cy) - depth_at(cx - h, cy)),
                                      std::fabs(depth_at(cx, cy + h) - depth_at(cx, cy - h))) /
                             (2.0 * h);
        const glm::dvec3 d =
            forward +
            (2.0 * cx / width - 1.0) * camera.tan_half_fov_y * camera.aspect *
                glm::dvec3(camera.right) +
            (1.0 - 2.0 * cy / height) * camera.tan_half_fov_y * glm::dvec3(camera.up);
        // Seen nearly edge-on the slope is bounded through |n . D| >= 1e-3: left out here.
        if (std::fabs(glm::dot(n, d)) < 0.05) continue;
        const glm::vec3 p(eye + d * z);
        const float plane = shared::pg_svgf_plane_slope(
            shared::float3(static_cast<float>(n.x), static_cast<float>(n.y),
                           static_cast<float>(n.z)),
            shared::float3(p.x, p.y, p.z), static_cast<float>(z), v);
        EXPECT_NEAR(plane, slope, 1e-3 * slope + 1e-7)
            << "normal " << n.x << "," << n.y << "," << n.z << " pixel " << x << "," << y;
        ++checked;
      }
  }
  EXPECT_GT(checked, 200);
}

// The depth weight's slope from the pixel's plane (depth_slope_from_normal): every stage still
// equals the host reference, one pixel per work-item and in lanes.
TEST(SvgfKernels, EqualTheHostReferenceWithThePlaneSlope) {
  ClRuntime rt;
  expect_equal_to_the_host_reference(
      rt, {{37, 23, 4, 4, 1, 2, 2, 128, 1}, {40, 9, 7, 3, 16, 2, 2, 128, 1}});
}

// A frame whose illumination is the same everywhere comes out as it went in, texture included:
// every weight sums colours equal to the centre's (with either a-trous kernel).
TEST(SvgfKernels, FlatIlluminationPassesThroughUnchanged) {
  ClRuntime rt;
  const int w = simulated(rt) ? 20 : 64, h = simulated(rt) ? 14 : 40;
  for (const int radius : {2, 1}) {
    SCOPED_TRACE("a-trous radius " + std::to_string(radius));
    SvgfSettings s;
    s.atrous_radius = radius;
    s.history_atrous_radius = radius;
    SvgfDenoiser device(rt, w, h, s);
    std::mt19937 rng(3);
    for (int f = 0; f < 3; ++f) {
      const GBuffer g = scene_gbuffer(w, h, 0.0f, rng);
      std::vector<glm::vec3> colour(g.pixel_count());
      for (std::size_t i = 0; i < colour.size(); ++i)
        colour[i] = g.has_surface(i)
                        ? glm::vec3(g.base_color_roughness[i]) * 0.7f + glm::vec3(g.emission[i])
                        : glm::vec3(g.emission[i]);
      const std::vector<glm::vec3> out = device.denoise(colour, g);
      for (std::size_t i = 0; i < out.size(); ++i)
        for (int c = 0; c < 3; ++c)
          ASSERT_NEAR(out[i][c], colour[i][c], 1e-5f * std::max(1.0f, colour[i][c]))
              << "frame " << f << " pixel " << i;
    }
  }
}

// What a denoiser is for, on a plane whose only edge is in its lighting (a shadow's: the depth
// and normal weights cannot see it, the luminance weight must): illumination 0.1 on the left half
// and 1 on the right, each frame's pixel that times a uniform noise of mean 1 (0.5 to 1.5), a
// still camera. After ten frames the denoised image's error against the noiseless one is a small
// fraction of the noisy frame's, and the dark side four pixels from the edge stays dark. The
// reference comparisons above cannot see a wrong weight function (the kernels and the reference
// share kernels/shared/svgf.h), nor can the flat and geometric-edge tests. The same frames with
// the luminance weight turned off (phi_luminance 1e6) must fail the edge check: the test's power.
struct ShadowEdgeResult {
  double error_ratio;  // MSE of the denoised frame / MSE of the noisy frame, against the truth
  double dark_near_edge, bright_near_edge;  // column means 4 pixels left / 3 right of the edge
};

ShadowEdgeResult denoise_a_shadow_edge(ClRuntime& rt, const SvgfSettings& s) {
  const int w = 64, h = 32, frames = 10;
  GBuffer g;
  g.resize(w, h);
  std::vector<float> truth(g.pixel_count());
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * w + x;
      g.flags[i] = 0;
      g.position_depth[i] = glm::vec4(0.01f * x, 0.01f * y, 2.0f, 2.0f);
      g.shading_normal[i] = glm::vec4(0, 0, 1, 0);
      g.base_color_roughness[i] = glm::vec4(1.0f, 1.0f, 1.0f, 0.5f);
      truth[i] = x < w / 2 ? 0.1f : 1.0f;
    }
  SvgfDenoiser device(rt, w, h, s);
  std::mt19937 rng(21);
  std::uniform_real_distribution<float> noise(0.5f, 1.5f);
  std::vector<glm::vec3> colour(g.pixel_count()), out;
  for (int f = 0; f < frames; ++f) {
    for (std::size_t i = 0; i < colour.size(); ++i) colour[i] = glm::vec3(truth[i] * noise(rng));
    out = device.denoise(colour, g);
  }
  double noisy_error = 0.0, denoised_error = 0.0, dark = 0.0, bright = 0.0;
  for (std::size_t i = 0; i < out.size(); ++i) {
    noisy_error += (colour[i].x - truth[i]) * (colour[i].x - truth[i]);
    denoised_error += (out[i].x - truth[i]) * (out[i].x - truth[i]);
    const int x = static_cast<int>(i % w);
    if (x == w / 2 - 4) dark += out[i].x / h;
    if (x == w / 2 + 3) bright += out[i].x / h;
  }
  return {denoised_error / noisy_error, dark, bright};
}

TEST(SvgfQuality, RemovesNoiseAndKeepsAnEdgeOfTheLighting) {
  ClRuntime rt;
  // The filters one pixel per work-item (kernels/shared/svgf.h's weights) and in vector lanes
  // (kernels/wide/svgf_wide.h's, the default on CPU devices).
  for (const int lanes : {1, 0}) {
    SCOPED_TRACE("lanes " + std::to_string(lanes));
    SvgfSettings s;
    s.lanes = lanes;
    const ShadowEdgeResult r = denoise_a_shadow_edge(rt, s);
    // Measured on PoCL: error ratio 0.055, dark 0.128, bright 0.972; without the luminance
    // weight 1.69, 0.512, 0.590 (the blur across the edge makes the image worse than the noisy
    // frame).
    EXPECT_LT(r.error_ratio, 0.1);
    EXPECT_LT(r.dark_near_edge, 0.2);
    EXPECT_GT(r.bright_near_edge, 0.85);
    SvgfSettings blind = s;
    blind.phi_luminance = 1e6f;
    const ShadowEdgeResult leaky = denoise_a_shadow_edge(rt, blind);
    EXPECT_GT(leaky.dark_near_edge, 0.2) << "the edge check cannot tell a filter blind to it";
    std::printf(
        "lanes %d: error ratio %.4f, dark %.4f, bright %.4f; without the luminance weight: "
        "%.4f, %.4f, %.4f\n",
        lanes, r.error_ratio, r.dark_near_edge, r.bright_near_edge, leaky.error_ratio,
        leaky.dark_near_edge, leaky.bright_near_edge);
  }
}

// A white plane facing the camera at depth 2, one surface: with one value in every pixel the
// filters are the identity, which the temporal tests rely on.
GBuffer white_plane_gbuffer(int w, int h) {
  GBuffer g;
  g.resize(w, h);
  for (std::size_t i = 0; i < g.pixel_count(); ++i) {
    g.flags[i] = 0;
    g.position_depth[i] = glm::vec4(0.01f * (i % w), 0.01f * (i / w), 2.0f, 2.0f);
    g.shading_normal[i] = glm::vec4(0, 0, 1, 0);
    g.base_color_roughness[i] = glm::vec4(1.0f, 1.0f, 1.0f, 0.5f);
  }
  return g;
}

// A plane facing the camera whose right half is a depth step (3 against 2) or, at equal depth,
// faces +x (a normal step): the two edge tests' surfaces.
GBuffer two_sided_gbuffer(int w, int h, bool normal_edge) {
  GBuffer g;
  g.resize(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * w + x;
      const bool right = x >= w / 2;
      const float depth = right && !normal_edge ? 3.0f : 2.0f;
      g.flags[i] = 0;
      g.position_depth[i] = glm::vec4(0.01f * x, 0.01f * y, depth, depth);
      g.shading_normal[i] = right && normal_edge ? glm::vec4(1, 0, 0, 0) : glm::vec4(0, 0, 1, 0);
      g.base_color_roughness[i] = glm::vec4(0.5f, 0.5f, 0.5f, 0.5f);
    }
  return g;
}

// Two constant regions side by side: a depth step, then a normal step at equal depth. Neither
// leaks into the other, though the a-trous taps reach 32 pixels across (16 with the 3x3 kernel).
TEST(SvgfKernels, EdgesOfDepthAndNormalAreNotBlurred) {
  ClRuntime rt;
  const int w = simulated(rt) ? 24 : 80, h = simulated(rt) ? 8 : 24;
  for (const int radius : {2, 1})
    for (const bool normal_edge : {false, true}) {
      SCOPED_TRACE(std::string(normal_edge ? "normal edge" : "depth edge") + ", a-trous radius " +
                   std::to_string(radius));
      const GBuffer g = two_sided_gbuffer(w, h, normal_edge);
      std::vector<glm::vec3> colour(g.pixel_count());
      for (std::size_t i = 0; i < colour.size(); ++i)
        colour[i] = static_cast<int>(i % w) >= w / 2 ? glm::vec3(2.0f, 1.0f, 0.5f)
                                                     : glm::vec3(0.1f, 0.2f, 0.3f);
      SvgfSettings s;
      s.atrous_radius = radius;
      s.history_atrous_radius = radius;
      SvgfDenoiser device(rt, w, h, s);
      const std::vector<glm::vec3> out = device.denoise(colour, g);
      for (std::size_t i = 0; i < out.size(); ++i)
        for (int c = 0; c < 3; ++c)
          ASSERT_NEAR(out[i][c], colour[i][c], 1e-5f) << "pixel " << i % w << "," << i / w;
    }
}

// The same two edges where only depth and normal can stop the filter: both sides about equally
// bright (luminance 0.186 and 0.185) and noisy (a grey factor in [0.5, 1.5] a pixel), so the
// luminance weight lets taps across; the sides differ in hue (red over green 0.5 on the left, 5
// on the right). A grey factor keeps each pixel's hue, so any mean of one side's pixels keeps it
// exactly, and a pixel beside the edge that took light from the other side shows it. (Noiseless
// sides of different brightness, as above, are kept apart by the luminance weight alone.)
TEST(SvgfKernels, EdgesOfDepthAndNormalStopTheFilterWhereLuminanceCannot) {
  ClRuntime rt;
  const int w = simulated(rt) ? 24 : 64, h = simulated(rt) ? 8 : 24;
  const glm::vec3 left(0.1f, 0.2f, 0.3f), right(0.5f, 0.1f, 0.1f);
  for (const int lanes : {1, 0})
    for (const bool normal_edge : {false, true}) {
      SCOPED_TRACE(std::string(normal_edge ? "normal edge" : "depth edge") + ", lanes " +
                   std::to_string(lanes));
      const GBuffer g = two_sided_gbuffer(w, h, normal_edge);
      SvgfSettings s;
      s.lanes = lanes;
      SvgfDenoiser device(rt, w, h, s);
      std::mt19937 rng(5);
      std::uniform_real_distribution<float> factor(0.5f, 1.5f);
      std::vector<glm::vec3> out;
      for (int f = 0; f < 3; ++f) {
        std::vector<glm::vec3> colour(g.pixel_count());
        for (std::size_t i = 0; i < colour.size(); ++i)
          colour[i] = (static_cast<int>(i % w) >= w / 2 ? right : left) * factor(rng);
        out = device.denoise(colour, g);
      }
      for (int y = 0; y < h; ++y)
        for (int x = w / 2 - 2; x < w / 2 + 2; ++x) {
          const glm::vec3 c = out[static_cast<std::size_t>(y) * w + x];
          const float hue = x >= w / 2 ? right.r / right.g : left.r / left.g;
          ASSERT_NEAR(c.r / c.g, hue, 1e-3f * hue) << "pixel " << x << "," << y;
        }
    }
}

// The a-trous kernels' 1D weights (pg_svgf_atrous_weight, shared by the kernels and the host
// reference, so the reference comparisons cannot see them): the paper's B3 spline at radius 2
// (SVGF 4.3: 1/16, 1/4, 3/8, 1/4, 1/16), the linear B-spline at radius 1 (1/4, 1/2, 1/4); each
// sums to 1, so a flat image passes through.
TEST(SvgfKernels, AtrousWeightsAreTheSplines) {
  const float b3[] = {0.0625f, 0.25f, 0.375f, 0.25f, 0.0625f};
  const float linear[] = {0.25f, 0.5f, 0.25f};
  for (int offset = -2; offset <= 2; ++offset)
    EXPECT_EQ(shared::pg_svgf_atrous_weight(offset, 2), b3[offset + 2]) << offset;
  for (int offset = -1; offset <= 1; ++offset)
    EXPECT_EQ(shared::pg_svgf_atrous_weight(offset, 1), linear[offset + 1]) << offset;
}

// The squared tap distances the filters' 1 / phi_z tables fill (a constant per radius in
// kernels/shared/svgf.h) are those of their taps, and no others.
TEST(SvgfKernels, TapSquaredDistancesAreThoseOfTheTaps) {
  for (int radius = 0; radius <= 5; ++radius) {
    std::vector<int> expected(PG_SVGF_SQUARED_DISTANCES(radius) + 8, 0);
    for (int dy = -radius; dy <= radius; ++dy)
      for (int dx = -radius; dx <= radius; ++dx)
        expected[shared::pg_svgf_squared_distance(dx, dy)] = 1;
    for (int d2 = 0; d2 < static_cast<int>(expected.size()); ++d2)
      EXPECT_EQ(shared::pg_svgf_is_tap_squared_distance(d2, radius), expected[d2])
          << "radius " << radius << ", squared distance " << d2;
  }
}

// A static camera. The luminance moments are a purely temporal average: with alpha 0 the first
// moment is exactly the mean of all frames' luminance. The colour history is the filtered
// illumination (SVGF feeds back the first a-trous output), so its expectation, not its value, is
// the mean of the inputs: tested over independent runs, with alpha 0 and the paper's 0.2.
TEST(SvgfKernels, TemporalAccumulationConvergesToTheMean) {
  ClRuntime rt;
  const int w = simulated(rt) ? 16 : 64, h = simulated(rt) ? 8 : 32, frames = 12;
  const int runs = simulated(rt) ? 3 : 10;
  const GBuffer g = white_plane_gbuffer(w, h);
  for (const float alpha : {0.0f, 0.2f}) {
    SCOPED_TRACE("alpha " + std::to_string(alpha));
    SvgfSettings s;
    s.alpha_colour = alpha;
    s.alpha_moments = alpha;
    s.max_history = 64;
    std::vector<double> image_means;
    for (int run = 0; run < runs; ++run) {
      SvgfDenoiser device(rt, w, h, s);
      std::mt19937 rng(11 + run);
      std::uniform_real_distribution<float> unit(0.0f, 1.0f);  // mean 1/2
      std::vector<double> sum(g.pixel_count(), 0.0);
      for (int f = 0; f < frames; ++f) {
        std::vector<glm::vec3> colour(g.pixel_count());
        for (std::size_t i = 0; i < colour.size(); ++i) {
          colour[i] = glm::vec3(unit(rng));
          sum[i] += shared::pg_luminance(colour[i]);
        }
        device.denoise(colour, g);
      }
      const std::vector<glm::vec4> integrated = device.read(SvgfStage::Integrated);
      const std::vector<glm::vec4> moments = device.read(SvgfStage::Moments);
      double mean = 0.0;
      for (std::size_t i = 0; i < integrated.size(); ++i) {
        ASSERT_EQ(moments[i].z, static_cast<float>(frames));
        if (alpha == 0.0f) {
          ASSERT_NEAR(moments[i].x, sum[i] / frames, 1e-5) << "pixel " << i;
        }
        mean += integrated[i].x;
      }
      image_means.push_back(mean / static_cast<double>(integrated.size()));
    }
    double m = 0.0, v = 0.0;
    for (double x : image_means) m += x;
    m /= runs;
    for (double x : image_means) v += (x - m) * (x - m);
    const double se = std::sqrt(v / (runs - 1) / runs);
    EXPECT_NEAR(m, 0.5, 4.0 * se + 1e-6) << "standard error " << se;
  }
}

// The temporal pass against its recursion worked out here in double precision, on a plane where
// every pixel sees one grey value v_f in frame f (so every filter is the identity): colour and
// moments each blend with their own weight, max(alpha, 1 / length), the length capped at
// max_history; the variance is m2 - m1^2 once the history is min_history frames long. The values
// are not symmetric about their mean, so a blend in the wrong direction, or the colour's alpha
// used for the moments, shows. Then a value held for several frames: its variance must be exactly
// 0 (m2 is v*v rounded, and so is m1*m1; a multiply-add fused into m2 - m1*m1 leaves 2^-24 v^2,
// which turned the luminance weight of a noiseless static pixel from a wall into a slope).
TEST(SvgfKernels, TemporalAccumulationFollowsItsRecursion) {
  ClRuntime rt;
  const int w = 16, h = 8;
  const GBuffer g = white_plane_gbuffer(w, h);
  SvgfSettings s;
  s.alpha_colour = 0.2f;
  s.alpha_moments = 0.5f;
  s.max_history = 3;
  s.min_history = 2;
  SvgfDenoiser device(rt, w, h, s);
  const float values[] = {0.1f, 3.0f, 0.2f, 0.3f, 5.0f, 0.15f};
  double c = 0.0, m1 = 0.0, m2 = 0.0;
  for (int f = 0; f < 6; ++f) {
    SCOPED_TRACE("frame " + std::to_string(f));
    const float v = values[f];
    device.denoise(std::vector<glm::vec3>(g.pixel_count(), glm::vec3(v)), g);
    const double length = std::min(f + 1, 3);
    const double l = shared::pg_luminance(glm::vec3(v));
    const double a_colour = std::max(0.2, 1.0 / length), a_moments = std::max(0.5, 1.0 / length);
    c += (v - c) * a_colour;
    m1 += (l - m1) * a_moments;
    m2 += (l * l - m2) * a_moments;
    const std::vector<glm::vec4> integrated = device.read(SvgfStage::Integrated);
    const std::vector<glm::vec4> moments = device.read(SvgfStage::Moments);
    const std::vector<glm::vec4> illumination = device.read(SvgfStage::Illumination);
    for (std::size_t i = 0; i < g.pixel_count(); i += 37) {
      ASSERT_NEAR(integrated[i].x, c, 1e-5 * std::max(1.0, c)) << "pixel " << i;
      ASSERT_NEAR(moments[i].x, m1, 1e-5 * std::max(1.0, m1)) << "pixel " << i;
      ASSERT_NEAR(moments[i].y, m2, 1e-5 * std::max(1.0, m2)) << "pixel " << i;
      ASSERT_EQ(moments[i].z, static_cast<float>(length)) << "pixel " << i;
      if (f >= 1) {  // length >= min_history: the temporal variance, no boost
        ASSERT_NEAR(illumination[i].w, m2 - m1 * m1, 1e-4 * std::max(1.0, m2)) << "pixel " << i;
      }
    }
  }
  SvgfDenoiser held(rt, w, h, s);  // 100.01 from the first frame on: the history is that value
  for (int f = 0; f < 3; ++f) {
    held.denoise(std::vector<glm::vec3>(g.pixel_count(), glm::vec3(100.01f)), g);
    if (f == 0) continue;  // a one-frame history takes the spatial estimate
    const std::vector<glm::vec4> illumination = held.read(SvgfStage::Illumination);
    for (std::size_t i = 0; i < g.pixel_count(); ++i)
      ASSERT_EQ(illumination[i].w, 0.0f) << "frame " << f << " pixel " << i;
  }
}

// A G-buffer the guider already copied to the device (GuidedFirstBounce::device_gbuffer_of) is
// read there: the same frames bit for bit as uploading it again, with 32 bytes a pixel going up
// instead of 96, and last frame's surfaces kept although the device G-buffer is rewritten.
TEST(SvgfKernels, GBufferOnTheDeviceEqualsUploadingIt) {
  ClRuntime rt;
  const int w = simulated(rt) ? 19 : 61, h = simulated(rt) ? 11 : 29;
  SvgfDenoiser uploading(rt, w, h, SvgfSettings{}, false);
  SvgfDenoiser sharing(rt, w, h, SvgfSettings{}, false);
  const GuiderGBuffer on_device = make_guider_gbuffer(rt.context(), w, h);
  std::mt19937 rng(13);
  for (int f = 0; f < 6; ++f) {
    const GBuffer g = scene_gbuffer(w, h, 2.3f * static_cast<float>(f), rng);
    const std::vector<glm::vec3> colour = noisy_colour(g, rng);
    enqueue_upload(rt.queue(), g, on_device);
    rt.queue().finish();
    const std::vector<glm::vec3> a = uploading.denoise(colour, g);
    const std::vector<glm::vec3> b = sharing.denoise(colour, g, &on_device);
    // Up: the colour (12 bytes), emission, position, normal, base colour (16 each), flags and
    // material (4 each), motion (8), or the first two alone; down: the colour (12).
    EXPECT_EQ(uploading.host_device_bytes_per_pixel(), 104.0);
    EXPECT_EQ(sharing.host_device_bytes_per_pixel(), 40.0);
    ASSERT_EQ(a.size(), b.size());
    std::size_t differ = 0;
    for (std::size_t i = 0; i < a.size(); ++i) differ += a[i] != b[i];
    EXPECT_EQ(differ, 0u) << "frame " << f;
  }
  const GuiderGBuffer small = make_guider_gbuffer(rt.context(), w, h - 1);
  std::mt19937 rng2(1);
  const GBuffer g = scene_gbuffer(w, h, 0.0f, rng2);
  EXPECT_THROW(sharing.denoise(noisy_colour(g, rng2), g, &small), InputError);
  // A larger image's buffers, whose rows the kernels would read at this width, and buffers of
  // another OpenCL context (undefined in OpenCL; on another platform another driver's object).
  const GuiderGBuffer larger = make_guider_gbuffer(rt.context(), 2 * w, 2 * h);
  EXPECT_THROW(sharing.denoise(noisy_colour(g, rng2), g, &larger), InputError);
  ClRuntime other;
  const GuiderGBuffer foreign = make_guider_gbuffer(other.context(), w, h);
  try {
    sharing.denoise(noisy_colour(g, rng2), g, &foreign);
    ADD_FAILURE() << "another context's G-buffer accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("another OpenCL context"), std::string::npos) << e.what();
  }
}

// Reading the inputs in place (zero copy, where the device shares host memory) gives the same
// frames bit for bit as copying them, with the host rewriting one G-buffer and one colour buffer
// every frame as the renderer does: last frame's surfaces must have been kept on the device.
TEST(SvgfKernels, ZeroCopyEqualsCopying) {
  ClRuntime rt;
  const int w = simulated(rt) ? 19 : 61, h = simulated(rt) ? 11 : 29;
  SvgfDenoiser copying(rt, w, h, SvgfSettings{}, false);
  SvgfDenoiser in_place(rt, w, h, SvgfSettings{}, true);
  EXPECT_FALSE(copying.zero_copy());
  // RTPG_HOST_TRANSFER=packed (the tests' second run), pinned or pageable makes every denoiser
  // copy (the denoiser copies through pinned staging for all three).
  const char* env = std::getenv("RTPG_HOST_TRANSFER");
  const bool copies_forced = env && (std::string(env) == "pinned" || std::string(env) == "packed" ||
                                     std::string(env) == "pageable");
  EXPECT_EQ(in_place.zero_copy(), rt.info().host_unified_memory && !copies_forced);
  EXPECT_EQ(copying.host_device_bytes_per_pixel(), 104.0);
  EXPECT_EQ(in_place.host_device_bytes_per_pixel(), in_place.zero_copy() ? 0.0 : 104.0);
  std::mt19937 rng(11);
  GBuffer g = scene_gbuffer(w, h, 0.0f, rng);
  std::vector<glm::vec3> colour = noisy_colour(g, rng);
  for (int f = 0; f < 6; ++f) {
    const GBuffer next = scene_gbuffer(w, h, 2.3f * static_cast<float>(f), rng);
    const std::vector<glm::vec3> next_colour = noisy_colour(next, rng);
    g = next;  // copy assignment: the same host memory, rewritten
    colour = next_colour;
    const std::vector<glm::vec3> a = copying.denoise(colour, g);
    const std::vector<glm::vec3> b = in_place.denoise(colour, g);
    ASSERT_EQ(a.size(), b.size());
    std::size_t differ = 0;
    for (std::size_t i = 0; i < a.size(); ++i) differ += a[i] != b[i];
    EXPECT_EQ(differ, 0u) << "frame " << f << ", of " << a.size() << " pixels";
  }
}

// Boxes that moved 3 pixels over a still floor: history is kept where last frame showed the
// same surface at the back-projected position (length 2 after two frames) and dropped where it
// did not (floor the boxes uncovered, box pixels that came in across the image border: 1).
// History is kept where last frame's pixel under the motion vector shows the same surface; where
// it does not, with history_fallback (the default) where one of its 3x3 neighbours does, and
// nowhere else.
TEST(SvgfKernels, ReprojectionKeepsHistoryOnlyOnTheSameSurface) {
  ClRuntime rt;
  const int w = simulated(rt) ? 24 : 64, h = simulated(rt) ? 12 : 32;
  for (int fallback : {0, 1}) {
    SCOPED_TRACE("history_fallback " + std::to_string(fallback));
    std::mt19937 rng(5);
    const GBuffer g0 = scene_gbuffer(w, h, 0.0f, rng);
    const GBuffer g1 = scene_gbuffer(w, h, 3.0f, rng);
    SvgfSettings settings;
    settings.history_fallback = fallback;
    SvgfDenoiser device(rt, w, h, settings);
    SvgfReference host(w, h, settings);
    for (const GBuffer* g : {&g0, &g1}) {
      const std::vector<glm::vec3> colour = noisy_colour(*g, rng);
      device.denoise(colour, *g);
      host.denoise(colour, *g);
    }
    const std::vector<glm::vec4> moments = device.read(SvgfStage::Moments);
    // Does frame 0's pixel (px, py) show frame 1's pixel i's surface?
    const auto same_at = [&](std::size_t i, int px, int py) {
      if (px < 0 || py < 0 || px >= w || py >= h) return false;
      const std::size_t j = static_cast<std::size_t>(py) * w + px;
      return g0.has_surface(j) && g0.material[j] == g1.material[i] &&
             std::fabs(g0.position_depth[j].w - g1.position_depth[i].w) <
                 0.05f * g1.position_depth[i].w;
    };
    int kept = 0, dropped = 0, from_neighbours = 0;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const std::size_t i = static_cast<std::size_t>(y) * w + x;
        if (!g1.has_surface(i)) {
          EXPECT_EQ(moments[i].z, 0.0f);
          continue;
        }
        // Motion is a whole number of pixels (0 or -3): one bilinear tap, the pixel it points at.
        const int px = x + static_cast<int>(g1.motion[i].x);
        bool same = same_at(i, px, y);
        if (!same && fallback != 0) {
          for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) same = same || same_at(i, px + dx, y + dy);
          from_neighbours += same;
        }
        EXPECT_EQ(moments[i].z, same ? 2.0f : 1.0f) << "pixel " << x << "," << y;
        (same ? kept : dropped)++;
      }
    EXPECT_GT(kept, 0);
    EXPECT_GT(dropped, 0);
    if (fallback != 0) {
      EXPECT_GT(from_neighbours, 0);
    }
    expect_close(moments, host.stage(SvgfStage::Moments), "moments", 2e-4f);
  }
}

// Every row of the denoiser's settings table that its kernels use reaches their block (a field
// the conversion forgot would pass every host-reference test, which reads the same block); the
// iteration count, the a-trous radii, the history's iteration, the work-group size and the lanes
// shape the passes and the kernels' build instead.
TEST(SvgfSettingsTable, EveryKernelSettingReachesTheKernelsBlock) {
  const std::vector<std::string> not_in_block = {
      "iterations", "atrous_radius", "history_atrous_radius", "history_iteration", "local_x",
      "local_y",    "lanes"};
  const shared::pg_svgf_settings defaults = to_kernel_settings(SvgfSettings{});
  for (const SvgfSettingInfo& row : svgf_settings_table()) {
    SCOPED_TRACE(row.name);
    const auto s = test::with_row_changed<SvgfSettings>(row, [](const auto& c) {
      try {
        validate(c);
        return true;
      } catch (const InputError&) {
        return false;  // a value the other settings do not allow with it
      }
    });
    ASSERT_TRUE(s.has_value()) << "no valid value away from the default";
    const shared::pg_svgf_settings k = to_kernel_settings(*s);
    const bool differs = std::memcmp(&k, &defaults, sizeof k) != 0;
    const bool in_block =
        std::find(not_in_block.begin(), not_in_block.end(), row.name) == not_in_block.end();
    EXPECT_EQ(differs, in_block) << "at " << row.get(*s);
  }
}

TEST(SvgfKernels, BadInputIsAClearError) {
  ClRuntime rt;
  SvgfSettings zero;
  zero.iterations = 0;
  EXPECT_THROW(SvgfDenoiser(rt, 8, 8, zero), InputError);
  // The settings are refused with an InputError whose message contains `names`.
  const auto expect_refused = [&](const SvgfSettings& bad, const std::string& names) {
    try {
      SvgfDenoiser d(rt, 8, 8, bad);
      ADD_FAILURE() << names << " accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(names), std::string::npos) << e.what();
    }
  };
  SvgfSettings late;
  late.history_iteration = 5;
  expect_refused(late, "history_iteration");
  SvgfSettings short_history;  // a cap below min_history: the spatial estimate for good
  short_history.max_history = 3;
  short_history.min_history = 4;
  expect_refused(short_history, "max_history (3) must be at least min_history (4)");
  EXPECT_THROW(SvgfDenoiser(rt, 0, 8), InputError);
  EXPECT_THROW(SvgfDenoiser(rt, 70000, 1), InputError);  // a side beyond rtpg/image_size.h's
  SvgfSettings half_auto;  // a work-group size of 0 is per device in both directions or neither
  half_auto.local_x = 0;
  half_auto.local_y = 8;
  expect_refused(half_auto, "local_x = 0 and local_y = 8");
  SvgfSettings three_lanes;
  three_lanes.lanes = 3;
  expect_refused(three_lanes, "lanes = 3");
  SvgfSettings nan;
  nan.phi_luminance = std::nanf("");
  EXPECT_THROW(SvgfReference(8, 8, nan), InputError);
  SvgfDenoiser d(rt, 8, 8);
  GBuffer g;
  g.resize(8, 8);
  try {
    d.denoise(std::vector<glm::vec3>(63), g);
    ADD_FAILURE() << "63 pixels accepted for 8x8";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("63 colour pixels"), std::string::npos) << e.what();
  }
  GBuffer small;
  small.resize(8, 7);
  EXPECT_THROW(d.denoise(std::vector<glm::vec3>(64), small), InputError);
  // Each channel the denoiser reads must hold a pixel's worth for every pixel: a short one was
  // read past its end where the device reads host memory in place, and left last frame's data
  // where it copies. Both kinds of denoiser, each channel short and empty.
  for (const bool zero_copy : {true, false}) {
    SvgfDenoiser denoiser(rt, 8, 8, SvgfSettings{}, zero_copy);
    const auto expect_short_refused = [&](auto member, const char* channel) {
      for (const std::size_t size : {std::size_t{32}, std::size_t{0}}) {
        GBuffer shortened;
        shortened.resize(8, 8);
        (shortened.*member).resize(size);
        try {
          denoiser.denoise(std::vector<glm::vec3>(64), shortened);
          ADD_FAILURE() << channel << " of " << size << " pixels accepted";
        } catch (const InputError& e) {
          EXPECT_NE(std::string(e.what()).find(channel), std::string::npos) << e.what();
        }
      }
    };
    expect_short_refused(&GBuffer::emission, "emission");
    expect_short_refused(&GBuffer::position_depth, "position_depth");
    expect_short_refused(&GBuffer::shading_normal, "shading_normal");
    expect_short_refused(&GBuffer::base_color_roughness, "base_color_roughness");
    expect_short_refused(&GBuffer::flags, "flags");
    expect_short_refused(&GBuffer::material, "material");
    expect_short_refused(&GBuffer::motion, "motion");
  }
}

// Non-finite and huge colours (a broken or a firefly sample) give finite output everywhere.
TEST(SvgfKernels, ExtremeInputStaysFinite) {
  ClRuntime rt;
  const int w = simulated(rt) ? 16 : 48, h = simulated(rt) ? 12 : 32;
  std::mt19937 rng(9);
  SvgfDenoiser device(rt, w, h);
  for (int f = 0; f < 3; ++f) {
    const GBuffer g = scene_gbuffer(w, h, static_cast<float>(f), rng);
    std::vector<glm::vec3> colour = noisy_colour(g, rng);
    for (std::size_t i = 0; i < colour.size(); i += 7)
      colour[i] = i % 3 == 0   ? glm::vec3(std::nanf(""))
                  : i % 3 == 1 ? glm::vec3(3e38f, 1e30f, 0.0f)
                               : glm::vec3(INFINITY, 0.0f, -INFINITY);
    const std::vector<glm::vec3> out = device.denoise(colour, g);
    for (std::size_t i = 0; i < out.size(); ++i) {
      if (!g.has_surface(i)) continue;  // the sky is passed through as it came
      for (int c = 0; c < 3; ++c) ASSERT_TRUE(std::isfinite(out[i][c])) << "pixel " << i;
    }
  }
}

}  // namespace
}  // namespace rtpg
