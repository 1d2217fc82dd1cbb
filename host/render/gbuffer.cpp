#include "render/gbuffer.h"

namespace rtpg {

void GBuffer::resize(int w, int h) {
  width = w;
  height = h;
  const std::size_t n = pixel_count();
  position_depth.assign(n, glm::vec4(0.0f));
  shading_normal.assign(n, glm::vec4(0.0f, 0.0f, 1.0f, 0.0f));
  geometric_normal.assign(n, glm::vec4(0.0f, 0.0f, 1.0f, 0.0f));
  view_dir.assign(n, glm::vec4(0.0f, 0.0f, 1.0f, 0.0f));
  motion.assign(n, glm::vec2(0.0f));
  base_color_roughness.assign(n, glm::vec4(0.0f));
  metallic_specular.assign(n, glm::vec4(0.0f));
  emission.assign(n, glm::vec4(0.0f));
  material_id.assign(n, 0u);
  flags.assign(n, PG_GBUF_SKY);
}

shared::pg_material gbuffer_material(const GBuffer& g, std::size_t i) {
  shared::pg_material m;
  const glm::vec4 bc = g.base_color_roughness[i];
  m.base_color = shared::float3(bc.x, bc.y, bc.z);
  m.roughness = bc.w;
  m.metallic = g.metallic_specular[i].x;
  m.specular = g.metallic_specular[i].y;
  return m;
}

shared::pg_frame gbuffer_frame(const GBuffer& g, std::size_t i) {
  return shared::pg_frame_from_normal(glm::vec3(g.shading_normal[i]));
}

}  // namespace rtpg
