// Every setting of the SVGF denoiser (docs/denoising.md), its default, bounds and meaning, in one
// table: the command line builds its --svgf-* flags from it, the denoiser validates against it
// and the stats JSON records every row. The kernels receive the settings as one
// pg_svgf_settings block (kernels/shared/svgf.h).
#pragma once

#include <vector>

#include "rtpg/setting_info.h"
#include "scene/camera.h"
#include "shared/svgf.h"

namespace rtpg {

struct SvgfSettings {
  // Defaults are the paper's (Schied et al. 2017, section 5) where it gives one.
  float alpha_colour = 0.2f;         // temporal blend weight of the new frame's illumination
  float alpha_moments = 0.2f;        // ... of its luminance moments
  int max_history = 32;              // history length cap (frames)
  int min_history = 4;               // shorter histories estimate variance spatially (7x7)
  float phi_depth = 1.0f;            // sigma_z: depth weight scale, times the depth gradient
  int phi_normal = 128;              // sigma_n: exponent of the normal weight
  float phi_luminance = 4.0f;        // sigma_l: luminance weight scale, times the std. dev.
  float reproject_position = 0.05f;  // history test, as guiding's: relative position change
  float reproject_normal = 0.9f;     // ... and normal cosine
  float albedo_floor = 1e-3f;        // demodulation divides by max(albedo, albedo_floor)
  // 1: where none of the bilinear taps of last frame shows this pixel's surface, the same-surface
  // pixels of the 3x3 around the back-projected one, equally weighted (the fallback of SVGF's
  // reference implementation; docs/denoising.md, "History from the neighbourhood"); 0: the
  // history restarts there.
  int history_fallback = 1;
  // 1: the depth weight's slope is that of the plane through the pixel with its normal
  // (pg_svgf_plane_slope); 0: from the neighbours' depths, which the camera's per-pixel jitter
  // puts 0 to 2 pixels apart (docs/denoising.md, "Where we deviate").
  int depth_slope_from_normal = 0;
  int iterations = 5;  // a-trous iterations (steps 1, 2, 4, ...)
  // The a-trous kernel's radius: 2, the paper's 5x5 B3 spline; 1, a 3x3 kernel (1/4, 1/2, 1/4)
  // at 44% of the 5x5's cost per iteration (docs/denoising.md, "A 3x3 a-trous kernel"), in the
  // iterations after history_iteration; history_atrous_radius in those up to it (whose output
  // becomes next frame's history).
  int atrous_radius = 2;
  int history_atrous_radius = 2;
  int history_iteration = 0;     // the iteration whose output is next frame's history
  int local_x = 0, local_y = 0;  // work-group size of the kernels; 0 and 0 = per device:
                                 // on CPUs every kernel in rows (each reads its neighbours
                                 // from global memory); 16x16 elsewhere (host/cl/work_groups.h)
  // Pixels per work-item of the variance and a-trous kernels: 1 (svgf_variance.cl,
  // svgf_atrous.cl), or 2, 4, 8, 16 in vector lanes (svgf_variance_wide.cl,
  // svgf_atrous_wide.cl); 0 = the device's SIMD width on CPUs, 1 elsewhere
  // (DeviceInfo::simd_lanes).
  int lanes = 0;
};

using SvgfSettingInfo = SettingInfo<SvgfSettings>;

// Every numeric field of SvgfSettings, in declaration order.
const std::vector<SvgfSettingInfo>& svgf_settings_table();

// Throws InputError ("svgf settings", "<name> = <value> is outside <range>") for a value outside
// its row's range, a history iteration beyond the last iteration, or lanes not 0 or a
// power of two.
void validate(const SvgfSettings& settings);

shared::pg_svgf_settings to_kernel_settings(const SvgfSettings& settings);
// The camera of an image `height` pixels high as pg_svgf_plane_slope takes it.
shared::pg_svgf_view to_svgf_view(const CameraFrame& camera, int height);

}  // namespace rtpg
