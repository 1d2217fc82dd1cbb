// Material keys, their ranges and which textures are colour (sRGB) and which are data.
#include "scene/material_json.h"

#include <string>

namespace rtpg {

namespace {

float read_unit(const JsonNode& node) {
  const float v = node.number();
  if (!(v >= 0.0f && v <= 1.0f)) node.fail("expected a value in [0, 1]");
  return v;
}

glm::vec3 read_colour(const JsonNode& node, bool at_most_one) {
  const glm::vec3 c = node.vec3();
  for (int i = 0; i < 3; ++i)
    if (!(c[i] >= 0.0f) || (at_most_one && c[i] > 1.0f))
      node.fail(at_most_one ? "components must lie in [0, 1]" : "components must not be negative");
  return c;
}

int read_texture(const JsonNode& node, ImageDecode decode, const TextureResolver& texture) {
  if (node.is_null()) return -1;
  if (!node.is_string()) node.fail_type("a file path or null");
  return texture(node, decode);
}

}  // namespace

void apply_material_fields(const JsonNode& node, Material& m, const TextureResolver& texture) {
  node.check_object({"description", "base_color", "roughness", "metallic", "specular", "emission",
                     "base_color_texture", "roughness_texture", "normal_texture", "bump_texture",
                     "bump_scale", "alpha_texture", "alpha_cutoff", "transmissive"});
  if (node.has("description")) node.child("description").string();  // a comment
  if (node.has("base_color")) m.base_color = read_colour(node.child("base_color"), true);
  if (node.has("roughness")) m.roughness = read_unit(node.child("roughness"));
  if (node.has("metallic")) m.metallic = read_unit(node.child("metallic"));
  if (node.has("specular")) m.specular = read_unit(node.child("specular"));
  if (node.has("emission")) m.emission = read_colour(node.child("emission"), false);
  if (node.has("bump_scale")) m.bump_scale = node.child("bump_scale").number();
  if (node.has("alpha_cutoff")) m.alpha_cutoff = read_unit(node.child("alpha_cutoff"));
  if (node.has("transmissive")) m.transmissive = node.child("transmissive").boolean();

  // Only the base colour is sRGB-encoded; alpha masks may be grey images without alpha.
  const ImageDecode colour{true, false}, data{false, false}, mask{false, true};
  if (node.has("base_color_texture"))
    m.base_color_texture = read_texture(node.child("base_color_texture"), colour, texture);
  if (node.has("roughness_texture")) {
    // A grey roughness map: every channel holds it, so the default channel (G) reads it. It
    // replaces a glTF metallicRoughness texture for roughness only.
    m.roughness_texture = read_texture(node.child("roughness_texture"), data, texture);
    m.roughness_channel = 1;
  }
  if (node.has("normal_texture"))
    m.normal_texture = read_texture(node.child("normal_texture"), data, texture);
  if (node.has("bump_texture"))
    m.bump_texture = read_texture(node.child("bump_texture"), data, texture);
  if (node.has("alpha_texture"))
    m.alpha_texture = read_texture(node.child("alpha_texture"), mask, texture);
}

}  // namespace rtpg
