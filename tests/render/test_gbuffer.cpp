// The renderer's G-buffer flags (host/render/renderer.cpp, build_gbuffer; their meaning:
// include/rtpg/guiding_layout.h), which decide where guiding applies (kernels/shared/
// guiding_pixel.h): every surface pixel's flags are those of the material it sees, emitters
// from the front, near-mirrors (roughness at most PG_MIN_ROUGHNESS) and materials marked
// transmissive; pixels without a surface are sky. The guiding kernels' tests make up their own
// flags, so only this test reads the renderer's.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>

#include "render/renderer.h"
#include "scene/scene_loader.h"

namespace rtpg {
namespace {

TEST(GBuffer, EachPixelsFlagsAreThoseOfTheMaterialItSees) {
  Scene scene = load_scene(std::string(RTPG_SOURCE_DIR) + "/scenes/cornell-box.json");
  // Two of the walls' materials changed: one rough and transmissive, one a near-mirror.
  int changed = 0;
  for (Material& m : scene.materials) {
    if (m.name == "red") {
      m.transmissive = true;
      m.roughness = 0.5f;
      ++changed;
    } else if (m.name == "green") {
      m.roughness = 0.01f;
      ++changed;
    }
  }
  ASSERT_EQ(changed, 2);
  RenderSettings settings;
  settings.width = 41;
  settings.height = 29;
  settings.path_tracer.max_bounces = 1;
  Renderer renderer(scene, settings);
  renderer.render_frame(0);
  const GBuffer& g = renderer.gbuffer();
  std::size_t sky = 0, emitter = 0, delta = 0, transmissive = 0, wrong = 0;
  for (std::size_t i = 0; i < g.pixel_count(); ++i) {
    if (!g.has_surface(i)) {
      ++sky;
      continue;
    }
    const Material& m = scene.materials.at(g.material[i]);
    std::uint32_t expected = 0;
    if (m.is_emissive()) expected |= PG_GBUF_EMITTER;  // the light faces the camera
    if (m.roughness <= PG_MIN_ROUGHNESS) expected |= PG_GBUF_DELTA;
    if (m.transmissive) expected |= PG_GBUF_TRANSMISSIVE;
    wrong += g.flags[i] != expected;
    emitter += (g.flags[i] & PG_GBUF_EMITTER) != 0;
    delta += (g.flags[i] & PG_GBUF_DELTA) != 0;
    transmissive += (g.flags[i] & PG_GBUF_TRANSMISSIVE) != 0;
  }
  EXPECT_EQ(wrong, 0u);
  EXPECT_GT(sky, 0u);
  EXPECT_GT(emitter, 0u);
  EXPECT_GT(delta, 10u);
  EXPECT_GT(transmissive, 10u);
}

}  // namespace
}  // namespace rtpg

namespace rtpg {
namespace {

// The renderer refuses the settings it cannot work with, naming them (the command line then names
// its flag): a size out of rtpg/image_size.h's range, no sample, more bounces than a path's depth
// byte records (kMaxPathBounces, 64: the world guide's per-path record; a deeper path wrapped
// around to depth 0 and the mark of a path not recording).
TEST(RendererSettings, RefusedWithTheSettingNamed) {
  const Scene scene = load_scene(std::string(RTPG_SOURCE_DIR) + "/scenes/cornell-box.json");
  const auto refused = [&](RenderSettings s, const std::string& setting) {
    try {
      Renderer renderer(scene, s);
      ADD_FAILURE() << setting << " accepted";
    } catch (const RenderSettingError& e) {
      EXPECT_EQ(e.setting(), setting) << e.what();
    }
  };
  RenderSettings s;
  s.width = 8;
  s.height = 8;
  RenderSettings wide = s;
  wide.width = 70000;
  refused(wide, "resolution");
  RenderSettings none = s;
  none.spp = 0;
  refused(none, "spp");
  RenderSettings deep = s;
  deep.path_tracer.max_bounces = kMaxPathBounces + 1;
  refused(deep, "max_bounces");
  deep.path_tracer.max_bounces = kMaxPathBounces;
  EXPECT_NO_THROW(Renderer(scene, deep));
}

}  // namespace
}  // namespace rtpg
