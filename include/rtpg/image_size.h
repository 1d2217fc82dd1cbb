// The image sizes rtpg accepts, in one place for the renderer, the Guider and the SVGF denoiser.
#pragma once

#include <cstdint>
#include <string>

namespace rtpg {

// At most this many pixels: beyond it the buffers would not fit in memory, and the kernels' 32-bit
// indices of planar channels (up to 4 n) would overflow.
constexpr std::uint64_t kMaxImagePixels = 8192ull * 8192ull;
// At most this many pixels a side: the kernels and the host take a pixel's centre as float(x) +
// 0.5, exact below 2^23, and follow a motion vector (clamped to this many pixels either way:
// kernels/shared/gbuffer_packing.h, pg_bounded_motion) from there, so every position they form
// stays an exact float and its conversion to int a defined one (docs/robustness.md, "Image sizes").
constexpr int kMaxImageSide = 1 << 16;

// Why a width x height image is refused ("must be positive, got 0x8", ...), or "" where it is
// accepted.
// The scene's textures take their own limits (host/scene/image_loader.cpp).
inline std::string image_size_problem(int width, int height, int max_side = kMaxImageSide,
                                      std::uint64_t max_pixels = kMaxImagePixels) {
  const std::string size = std::to_string(width) + "x" + std::to_string(height);
  if (width <= 0 || height <= 0) return "must be positive, got " + size;
  if (width > max_side || height > max_side)
    return size + " is too large (at most " + std::to_string(max_side) + " pixels a side)";
  if (static_cast<std::uint64_t>(width) * static_cast<std::uint64_t>(height) > max_pixels)
    return size + " is too large (at most " + std::to_string(max_pixels) + " pixels)";
  return "";
}

}  // namespace rtpg
