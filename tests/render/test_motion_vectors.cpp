// The renderer's motion vectors (host/render/renderer.cpp, G-buffer `motion`): for every pixel
// that sees a surface, the offset in pixels from the pixel's centre to where that surface point
// was on the previous frame's film, which the reprojection of guiding states follows
// (docs/guiding.md). Checked against an independent projection: GLM's lookAt and perspective
// matrices of the previous frame's camera view, not the renderer's CameraFrame.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include <glm/gtc/matrix_transform.hpp>

#include "render/gbuffer.h"
#include "render/renderer.h"
#include "shared/gbuffer_packing.h"
#include "same_image.h"
#include "scene/scene_loader.h"
#include "scene/shapes.h"

namespace rtpg {
namespace {

Scene cornell_box() {
  return load_scene(std::string(RTPG_SOURCE_DIR) + "/scenes/cornell-box.json");
}

// Film position of p in the view, (0,0) = top-left corner, (1,1) = bottom-right; false if
// behind the camera.
bool project_with_glm(const CameraView& view, float aspect, const glm::vec3& p, glm::dvec2& out) {
  const glm::dmat4 clip_from_world =
      glm::perspective(double(view.fov_y), double(aspect), 1e-3, 1e3) *
      glm::lookAt(glm::dvec3(view.position), glm::dvec3(view.look_at), glm::dvec3(view.up));
  const glm::dvec4 c = clip_from_world * glm::dvec4(glm::dvec3(p), 1.0);
  if (!(c.w > 0.0)) return false;
  out = glm::dvec2(0.5 * (c.x / c.w + 1.0), 0.5 * (1.0 - c.y / c.w));
  return true;
}

// An odd, non-square size with jitter on, along the scene's camera path: the motion of pixel
// (x, y) is the previous frame's film position of its surface point times the image size,
// minus the pixel's centre (x + 0.5, y + 0.5), whatever the jitter of its ray.
TEST(MotionVectors, EqualTheProjectionIntoThePreviousFrame) {
  const Scene scene = cornell_box();
  RenderSettings settings;
  settings.width = 37;
  settings.height = 23;
  settings.camera_path = "pan";
  settings.path_tracer.max_bounces = 1;
  Renderer renderer(scene, settings);
  const CameraPath& path = scene.camera.paths.at("pan");
  const float aspect = float(settings.width) / float(settings.height);
  double largest_motion = 0.0, largest_error = 0.0;
  int checked = 0;
  for (int f = 0; f < 6; ++f) {
    renderer.render_frame(f);
    const GBuffer& g = renderer.gbuffer();
    const CameraView previous = path.at(float(f > 0 ? f - 1 : 0) / path.fps);
    for (int y = 0; y < g.height; ++y)
      for (int x = 0; x < g.width; ++x) {
        const std::size_t i = std::size_t(y) * g.width + x;
        if (!g.has_surface(i)) {
          EXPECT_EQ(g.motion[i], glm::vec2(0.0f)) << "sky pixel " << x << "," << y;
          continue;
        }
        if (f == 0) {
          EXPECT_EQ(g.motion[i], glm::vec2(0.0f)) << "frame 0 has no previous frame";
          continue;
        }
        glm::dvec2 film;
        ASSERT_TRUE(project_with_glm(previous, aspect, glm::vec3(g.position_depth[i]), film));
        const glm::dvec2 expected(film.x * g.width - (x + 0.5), film.y * g.height - (y + 0.5));
        const glm::dvec2 error = glm::dvec2(g.motion[i]) - expected;
        largest_error = std::max(largest_error, std::max(std::fabs(error.x), std::fabs(error.y)));
        largest_motion = std::max(largest_motion, glm::length(expected));
        ASSERT_NEAR(g.motion[i].x, expected.x, 2e-3) << "frame " << f << " pixel " << x << "," << y;
        ASSERT_NEAR(g.motion[i].y, expected.y, 2e-3) << "frame " << f << " pixel " << x << "," << y;
        ++checked;
      }
  }
  // The path moves the camera by more than a pixel per frame here, so a sign or axis error
  // could not hide in the tolerance.
  EXPECT_GT(largest_motion, 0.5);
  EXPECT_GT(checked, 5 * 37 * 23 / 2);
  std::printf("motion vectors: %d pixels, largest motion %.3f px, largest error %.2e px\n", checked,
              largest_motion, largest_error);
}

// A camera that backs away from a wall it stood 1e-12 in front of: the wall's points lie just in
// front of the previous camera's plane, where the projection divides by about 1e-12, and their
// motion is clamped to 65536 pixels either way (pg_bounded_motion, kernels/shared/
// gbuffer_packing.h) instead of reaching about 1e13 pixels, beyond the int the kernels convert a
// position to (docs/robustness.md, "Image sizes"). Every motion is finite and within the bound,
// and most of the wall's pixels take the bound itself.
TEST(MotionVectors, ClampedWherePointsWereJustInFrontOfTheCamera) {
  Scene scene;
  scene.materials.push_back(Material{});
  // A 20 x 20 wall in the plane z = -1e-12, facing +z.
  scene.meshes.push_back(
      make_quad({-10.0f, -10.0f, -1e-12f}, {20.0f, 0.0f, 0.0f}, {0.0f, 20.0f, 0.0f}));
  CameraPath path;
  path.times = {0.0f, 1.0f / 30.0f};
  CameraView near_view, far_view;
  near_view.position = glm::vec3(0.0f);
  near_view.look_at = glm::vec3(0.0f, 0.0f, -1.0f);
  far_view.position = glm::vec3(0.0f, 0.0f, 5.0f);
  far_view.look_at = glm::vec3(0.0f, 0.0f, -1.0f);
  path.views = {near_view, far_view};
  scene.camera.view = near_view;
  scene.camera.paths["back"] = path;
  RenderSettings settings;
  settings.width = 33;
  settings.height = 21;
  settings.camera_path = "back";
  settings.path_tracer.max_bounces = 1;
  Renderer renderer(scene, settings);
  renderer.render_frame(0);
  renderer.render_frame(1);
  const GBuffer& g = renderer.gbuffer();
  int surfaces = 0, at_bound = 0;
  for (std::size_t i = 0; i < g.pixel_count(); ++i) {
    if (!g.has_surface(i)) continue;
    ++surfaces;
    for (const float m : {g.motion[i].x, g.motion[i].y}) {
      ASSERT_TRUE(std::isfinite(m)) << "pixel " << i;
      ASSERT_LE(std::fabs(m), 65536.0f) << "pixel " << i;
    }
    if (std::fabs(g.motion[i].x) == 65536.0f || std::fabs(g.motion[i].y) == 65536.0f) ++at_bound;
  }
  EXPECT_EQ(surfaces, 33 * 21);
  EXPECT_GT(at_bound, surfaces / 2);
  // The device's own motion (pg_gbuffer_motion, from a packed G-buffer's depth) is bounded the
  // same way: the wall's pixels at the bound where the host's are.
  const pg_gbuffer_cameras cameras = gbuffer_cameras(g);
  for (int y = 0; y < g.height; ++y)
    for (int x = 0; x < g.width; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * g.width + x;
      const glm::vec4 p = g.position_depth[i];
      const shared::float2 m =
          shared::pg_gbuffer_motion(cameras, shared::float3(p.x, p.y, p.z),
                                    static_cast<shared::uint>(x), static_cast<shared::uint>(y));
      for (int c = 0; c < 2; ++c) {
        const float device = c == 0 ? m.x : m.y, host = g.motion[i][c];
        ASSERT_TRUE(std::isfinite(device) && std::fabs(device) <= 65536.0f) << x << "," << y;
        if (std::fabs(host) == 65536.0f) {
          EXPECT_EQ(device, host) << x << "," << y;
        }
      }
    }
}

// A static camera has zero motion on every frame, jitter or not: no camera path, or a path
// held at one of its frames (how references are rendered).
TEST(MotionVectors, ZeroForAStaticCamera) {
  const Scene scene = cornell_box();
  for (const int held_frame : {-1, 3}) {
    SCOPED_TRACE(held_frame);
    RenderSettings settings;
    settings.width = 19;
    settings.height = 31;
    settings.path_tracer.max_bounces = 1;
    if (held_frame >= 0) {
      settings.camera_path = "pan";
      settings.camera_frame = held_frame;
    }
    Renderer renderer(scene, settings);
    for (int f = 0; f < 3; ++f) {
      renderer.render_frame(f);
      for (const glm::vec2& m : renderer.gbuffer().motion) ASSERT_EQ(m, glm::vec2(0.0f));
    }
  }
}

// A camera path held at one frame (RenderSettings::camera_frame, `rtpg reference --camera-path P
// --frame N`: the references of moving-camera frames) renders that frame's view in every frame:
// without jitter, the G-buffer's surfaces and view directions of any frame equal, to the bit,
// those of frame N rendered along the path, and differ from frame 0's (the pan moves more than
// a pixel a frame, so a pose that followed the frame index or stayed at the path's start fails).
TEST(MotionVectors, AHeldCameraFrameIsThatFramesView) {
  const Scene scene = cornell_box();
  RenderSettings settings;
  settings.width = 29;
  settings.height = 17;
  settings.jitter = false;
  settings.path_tracer.max_bounces = 1;
  settings.camera_path = "pan";
  Renderer moving(scene, settings);
  moving.render_frame(0);
  const GBuffer first = moving.gbuffer();
  moving.render_frame(3);
  const GBuffer third = moving.gbuffer();
  settings.camera_frame = 3;
  Renderer held(scene, settings);
  for (int f : {0, 1, 5}) {
    held.render_frame(f);
    const GBuffer& g = held.gbuffer();
    ASSERT_EQ(g.pixel_count(), third.pixel_count());
    std::size_t differing_from_third = 0, differing_from_first = 0;
    for (std::size_t i = 0; i < g.pixel_count(); ++i) {
      differing_from_third += !same_bits(g.position_depth[i], third.position_depth[i]) ||
                              !same_bits(g.view_dir[i], third.view_dir[i]);
      differing_from_first += !same_bits(g.position_depth[i], first.position_depth[i]);
    }
    EXPECT_EQ(differing_from_third, 0u) << "frame " << f;
    EXPECT_GT(differing_from_first, g.pixel_count() / 4) << "frame " << f;
  }
}

}  // namespace
}  // namespace rtpg
