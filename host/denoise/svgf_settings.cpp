#include "denoise/svgf_settings.h"

#include <cstdint>
#include <limits>

#include "rtpg/errors.h"

namespace rtpg {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
using S = SvgfSettings;
constexpr auto real = &SvgfSettingInfo::real;
constexpr auto integer = &SvgfSettingInfo::integer;

}  // namespace

const std::vector<SvgfSettingInfo>& svgf_settings_table() {
  static const std::vector<SvgfSettingInfo> table = {
      real("alpha_colour", &S::alpha_colour, 0, 1, false, false,
           "Temporal blend weight of the new frame's illumination; the weight is at least "
           "1 / history length (0: the mean of the history until max_history frames, then "
           "1 / max_history)"),
      real("alpha_moments", &S::alpha_moments, 0, 1, false, false,
           "Temporal blend weight of the new frame's luminance moments"),
      integer("max_history", &S::max_history, 1, 1e6, "History length cap in frames"),
      integer("min_history", &S::min_history, 1, 1e6,
              "Shorter histories estimate the variance spatially (7x7)"),
      real("phi_depth", &S::phi_depth, 0, kInf, true, false,
           "Depth weight scale (sigma_z), times the depth gradient"),
      integer("phi_normal", &S::phi_normal, 0, 4096, "Exponent of the normal weight (sigma_n)"),
      real("phi_luminance", &S::phi_luminance, 0, kInf, true, false,
           "Luminance weight scale (sigma_l), times the standard deviation"),
      real("reproject_position", &S::reproject_position, 0, kInf, false, false,
           "Position change, relative to the depth, that rejects history"),
      real("reproject_normal", &S::reproject_normal, -1, 1, false, false,
           "Normal cosine below which history is rejected"),
      real("albedo_floor", &S::albedo_floor, 0, 1, true, false,
           "Demodulation divides by max(albedo, this)"),
      integer("history_fallback", &S::history_fallback, 0, 1,
              "1: where no bilinear tap keeps history, the 3x3 neighbourhood's same-surface pixels "
              "(SVGF's reference implementation); 0: the history restarts there"),
      integer("depth_slope_from_normal", &S::depth_slope_from_normal, 0, 1,
              "1: the depth weight's slope from the pixel's plane (normal and camera); 0: from the "
              "neighbours' depths"),
      integer("iterations", &S::iterations, 1, 12, "A-trous iterations (steps 1, 2, 4, ...)"),
      integer("atrous_radius", &S::atrous_radius, 1, 2,
              "A-trous kernel radius after the history iteration: 2 the paper's 5x5 B3 spline, 1 a "
              "3x3 (1/4, 1/2, 1/4)"),
      integer("history_atrous_radius", &S::history_atrous_radius, 1, 2,
              "A-trous kernel radius up to the history iteration (2 or 1, as atrous_radius)"),
      integer("history_iteration", &S::history_iteration, 0, 11,
              "The a-trous iteration (from 0) whose output is the next frame's history"),
      integer("local_x", &S::local_x, 0, 65536,
              "Work-group width of the kernels (0 with local_y 0: per device)"),
      integer("local_y", &S::local_y, 0, 65536,
              "Work-group height of the kernels (0 with local_x 0: per device)"),
      integer("lanes", &S::lanes, 0, 16,
              "Pixels per work-item of the variance and a-trous kernels: 1, 2, 4, 8 or 16 (0: the "
              "SIMD width on CPUs, else 1)"),
  };
  return table;
}

void validate(const SvgfSettings& s) {
  for (const SvgfSettingInfo& row : svgf_settings_table()) {
    const double v = row.get(s);
    if (!row.in_range(v))
      throw InputError("svgf settings", std::string(row.name) + " = " + setting_number(v) +
                                            " is outside " + row.range_text());
  }
  if (s.history_iteration >= s.iterations)
    throw InputError("svgf settings", "history_iteration (" + std::to_string(s.history_iteration) +
                                          ") must be below iterations (" +
                                          std::to_string(s.iterations) + ")");
  // A history capped below min_history would never reach it: every pixel would take the spatial
  // estimate every frame, for good.
  if (s.max_history < s.min_history)
    throw InputError("svgf settings", "max_history (" + std::to_string(s.max_history) +
                                          ") must be at least min_history (" +
                                          std::to_string(s.min_history) + ")");
  if ((s.local_x == 0) != (s.local_y == 0))
    throw InputError("svgf settings", "local_x = " + std::to_string(s.local_x) +
                                          " and local_y = " + std::to_string(s.local_y) +
                                          ": both 0 (per device) or neither");
  if (s.lanes & (s.lanes - 1))
    throw InputError("svgf settings", "lanes = " + std::to_string(s.lanes) +
                                          " must be 0 (auto) or a power of two: 1, 2, 4, 8 or 16");
}

shared::pg_svgf_settings to_kernel_settings(const SvgfSettings& c) {
  shared::pg_svgf_settings p{};
  p.alpha_colour = c.alpha_colour;
  p.alpha_moments = c.alpha_moments;
  p.max_history = static_cast<float>(c.max_history);
  p.min_history = static_cast<float>(c.min_history);
  p.phi_depth = c.phi_depth;
  p.phi_normal = static_cast<std::uint32_t>(c.phi_normal);
  p.phi_luminance = c.phi_luminance;
  p.reproject_position = c.reproject_position;
  p.reproject_normal = c.reproject_normal;
  p.albedo_floor = c.albedo_floor;
  p.history_fallback = static_cast<std::uint32_t>(c.history_fallback);
  p.depth_slope_from_normal = static_cast<std::uint32_t>(c.depth_slope_from_normal);
  return p;
}

shared::pg_svgf_view to_svgf_view(const CameraFrame& camera, int height) {
  return shared::pg_svgf_view{
      camera.position.x, camera.position.y,
      camera.position.z, camera.right.x,
      camera.right.y,    camera.right.z,
      camera.up.x,       camera.up.y,
      camera.up.z,       2.0f * camera.tan_half_fov_y / static_cast<float>(height)};
}

}  // namespace rtpg
