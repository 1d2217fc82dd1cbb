#include "render/gbuffer.h"

#include "shared/guiding_pixel.h"

namespace rtpg {

void GBuffer::resize(int w, int h) {
  width = w;
  height = h;
  const std::size_t n = pixel_count();
#define RTPG_CLEAR(name, type, bytes) name.assign(n, shared::type(0));
  PG_GBUFFER_CHANNELS(RTPG_CLEAR)
#undef RTPG_CLEAR
  geometric_normal.assign(n, glm::vec4(0.0f, 0.0f, 1.0f, 0.0f));
  emission.assign(n, glm::vec4(0.0f));
  // Unit vectors stay unit on pixels that no hit overwrites.
  shading_normal.assign(n, glm::vec4(0.0f, 0.0f, 1.0f, 0.0f));
  view_dir.assign(n, glm::vec4(0.0f, 0.0f, 1.0f, 0.0f));
  flags.assign(n, PG_GBUF_SKY);
}

shared::pg_material gbuffer_material(const GBuffer& g, std::size_t i) {
  return shared::pg_material_from_gbuffer(g.base_color_roughness[i], g.metallic_specular[i]);
}

shared::pg_frame gbuffer_frame(const GBuffer& g, std::size_t i) {
  return shared::pg_frame_from_normal(glm::vec3(g.shading_normal[i]));
}

namespace {

pg_pinhole_camera pinhole(const CameraFrame& c) {
  return pg_pinhole_camera{c.position.x, c.position.y, c.position.z,     c.right.x, c.right.y,
                           c.right.z,    c.up.x,       c.up.y,           c.up.z,    c.forward.x,
                           c.forward.y,  c.forward.z,  c.tan_half_fov_y, c.aspect};
}

}  // namespace

pg_gbuffer_cameras gbuffer_cameras(const GBuffer& g) {
  return pg_gbuffer_cameras{
      pinhole(g.camera),      pinhole(g.previous_camera), g.width,       g.height,
      g.camera_moved ? 1 : 0, g.jitter.enabled ? 1 : 0,   g.jitter.seed, g.jitter.frame};
}

}  // namespace rtpg
