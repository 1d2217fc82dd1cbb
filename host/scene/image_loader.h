// Reads image files (png, jpg, tga, hdr, exr, ... anything OpenImageIO reads) into linear
// float RGBA textures.
#pragma once

#include <cstddef>
#include <string>

#include "scene/texture.h"

namespace rtpg {

struct ImageDecode {
  // 8/16-bit colour images are sRGB-encoded: decode them to linear. Leave false for data
  // (roughness, metallic, normal, bump, alpha), which is stored linearly. Float formats
  // (hdr, exr) are always linear. The alpha channel is never sRGB-decoded.
  bool srgb = false;
  // An alpha mask: when the file has no alpha channel, or one that is opaque in every texel,
  // its first channel (a grey mask such as an OBJ map_d) becomes the alpha, since alpha testing
  // reads the alpha channel.
  bool mask = false;
  // A material's texture (a colour, roughness, metallic, normal, bump or alpha map): a float
  // image's values must lie in [0, 1], as 8- and 16-bit ones do by their encoding (an albedo
  // above 1 would create energy). False for an environment map, whose radiance is unbounded.
  bool unit_range = true;
};

// Grey images expand to RGB; alpha is 1 where the file has none. Throws
// InputError(path, reason) when the file is missing, unreadable or corrupt.
Texture load_image(const std::string& path, ImageDecode decode);

// The same for an image held in memory (a texture embedded in a glTF/GLB file). `name` is for
// messages; its extension (e.g. "mesh.glb[*0].png") selects the decoder.
Texture load_image_from_memory(const std::string& name, const void* data, std::size_t size,
                               ImageDecode decode);

}  // namespace rtpg
