#include "denoise/svgf_reference.h"

#include <cmath>
#include <string>

#include "rtpg/errors.h"

namespace rtpg {
namespace {

namespace sh = shared;

glm::vec3 xyz(const glm::vec4& v) {
  return glm::vec3(v);
}

}  // namespace

void check_svgf_input(int width, int height, const std::vector<glm::vec3>& colour,
                      const GBuffer& g) {
  const std::string size = std::to_string(width) + "x" + std::to_string(height);
  if (g.width != width || g.height != height)
    throw InputError("svgf", "G-buffer is " + std::to_string(g.width) + "x" +
                                 std::to_string(g.height) + ", the denoiser " + size);
  const std::size_t n = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  if (colour.size() != n)
    throw InputError("svgf",
                     std::to_string(colour.size()) + " colour pixels for a " + size + " denoiser");
  // The channels the denoiser reads, each of one element a pixel: a shorter one would be read
  // past its end where the device reads host memory in place.
  const auto check = [&](std::size_t elements, const char* channel) {
    if (elements != n)
      throw InputError("svgf", std::string("the G-buffer's ") + channel + " channel holds " +
                                   std::to_string(elements) + " pixels, not the " + size +
                                   " image's " + std::to_string(n));
  };
  check(g.emission.size(), "emission");
  check(g.position_depth.size(), "position_depth");
  check(g.shading_normal.size(), "shading_normal");
  check(g.base_color_roughness.size(), "base_color_roughness");
  check(g.flags.size(), "flags");
  check(g.material.size(), "material");
  check(g.motion.size(), "motion");
}

SvgfReference::SvgfReference(int width, int height, const SvgfSettings& settings)
    : width_(width), height_(height), settings_(settings) {
  validate(settings);
  if (width <= 0 || height <= 0)
    throw InputError("svgf", "image size must be positive, got " + std::to_string(width) + "x" +
                                 std::to_string(height));
  kernel_settings_ = to_kernel_settings(settings);
  const std::size_t n = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  for (auto* v : {&surface_, &integrated_, &moments_, &illumination_, &filtered_, &history_,
                  &output_, &scratch_, &prev_position_depth_, &prev_normal_, &prev_moments_})
    v->assign(n, glm::vec4(0.0f));
  depth_slope_.assign(n, 0.0f);
  prev_material_.assign(n, 0u);
}

const std::vector<glm::vec4>& SvgfReference::stage(SvgfStage stage) const {
  switch (stage) {
    case SvgfStage::Surface:
      return surface_;
    case SvgfStage::Integrated:
      return integrated_;
    case SvgfStage::Moments:
      return moments_;
    case SvgfStage::Illumination:
      return illumination_;
    case SvgfStage::Filtered:
      return filtered_;
    case SvgfStage::History:
      return history_;
    case SvgfStage::Output:
      break;
  }
  return output_;
}

const std::vector<glm::vec3>& SvgfReference::denoise(const std::vector<glm::vec3>& colour,
                                                     const GBuffer& g) {
  check_svgf_input(width_, height_, colour, g);
  temporal(colour, g);
  variance();
  // Iterations ping-pong between filtered_ and scratch_, starting from illumination_.
  const std::vector<glm::vec4>* in = &illumination_;
  for (int k = 0; k < settings_.iterations; ++k) {
    std::vector<glm::vec4>& out = (k % 2 == 0) ? scratch_ : filtered_;
    atrous(*in, out, 1 << k,
           k <= settings_.history_iteration ? settings_.history_atrous_radius
                                            : settings_.atrous_radius);
    if (k == settings_.history_iteration) history_ = out;
    in = &out;
  }
  if (in != &filtered_) filtered_ = *in;
  remodulate(colour, g);
  prev_position_depth_.assign(g.position_depth.begin(), g.position_depth.end());
  prev_normal_.assign(g.shading_normal.begin(), g.shading_normal.end());
  prev_material_.assign(g.material.begin(), g.material.end());
  prev_moments_ = moments_;
  has_history_ = true;
  denoised_.resize(output_.size());
  for (std::size_t i = 0; i < output_.size(); ++i) denoised_[i] = glm::vec3(output_[i]);
  return denoised_;
}

void SvgfReference::temporal(const std::vector<glm::vec3>& colour, const GBuffer& g) {
  const sh::pg_svgf_settings& s = kernel_settings_;
  const sh::pg_svgf_view view = to_svgf_view(g.camera, height_);
  for (int y = 0; y < height_; ++y)
    for (int x = 0; x < width_; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * width_ + x;
      if (!sh::pg_svgf_has_surface(g.flags[i])) {
        surface_[i] = glm::vec4(0.0f, 0.0f, 1.0f, 0.0f);
        depth_slope_[i] = 0.0f;
        integrated_[i] = glm::vec4(0.0f);
        moments_[i] = glm::vec4(0.0f);
        continue;
      }
      const glm::vec4 pd = g.position_depth[i];
      const glm::vec3 n = xyz(g.shading_normal[i]);
      surface_[i] = glm::vec4(n, pd.w);
      const float z_left = x > 0 ? g.position_depth[i - 1].w : 0.0f;
      const float z_right = x + 1 < width_ ? g.position_depth[i + 1].w : 0.0f;
      const float z_down = y > 0 ? g.position_depth[i - width_].w : 0.0f;
      const float z_up = y + 1 < height_ ? g.position_depth[i + width_].w : 0.0f;
      depth_slope_[i] = s.depth_slope_from_normal
                            ? sh::pg_svgf_plane_slope(sh::float3(n.x, n.y, n.z),
                                                      sh::float3(pd.x, pd.y, pd.z), pd.w, view)
                            : sh::pg_svgf_depth_slope(pd.w, z_left, z_right, z_down, z_up);

      const glm::vec3 albedo = sh::pg_svgf_albedo(g.base_color_roughness[i], s.albedo_floor);
      const glm::vec3 illumination = sh::pg_svgf_demodulate(colour[i], xyz(g.emission[i]), albedo);
      const float luminance = sh::pg_luminance(illumination);

      glm::vec3 sum_history(0.0f);
      glm::vec4 sum_moments(0.0f);
      float sum_weight = 0.0f;
      if (has_history_) {
        const glm::vec2 position =
            glm::vec2(static_cast<float>(x), static_cast<float>(y)) + g.motion[i];
        for (int pass = 0; pass < 2; ++pass) {
          if (pass == 1) {
            if (sum_weight >= PG_SVGF_MIN_TAP_WEIGHT || s.history_fallback == 0u) break;
            sum_history = glm::vec3(0.0f);
            sum_moments = glm::vec4(0.0f);
            sum_weight = 0.0f;
          }
          for (int t = 0; t < sh::pg_svgf_history_taps(pass); ++t) {
            int px = 0, py = 0;
            const float w = sh::pg_svgf_history_tap(position, pass, t, &px, &py);
            if (w <= 0.0f || px < 0 || py < 0 || px >= width_ || py >= height_) continue;
            const std::size_t j = static_cast<std::size_t>(py) * width_ + px;
            if (!sh::pg_same_surface(pd, n, g.material[i], prev_position_depth_[j],
                                     xyz(prev_normal_[j]), prev_material_[j], s.reproject_position,
                                     s.reproject_normal))
              continue;
            sum_history += w * xyz(history_[j]);
            sum_moments += w * prev_moments_[j];
            sum_weight += w;
          }
        }
      }
      float length = 1.0f;
      glm::vec3 c = illumination;
      glm::vec2 mo(luminance, luminance * luminance);
      if (sum_weight >= PG_SVGF_MIN_TAP_WEIGHT) {
        const glm::vec3 history = sum_history / sum_weight;
        const glm::vec4 history_moments = sum_moments / sum_weight;
        length = std::fmin(history_moments.z + 1.0f, s.max_history);
        c = sh::pg_svgf_blend3(history, illumination,
                               sh::pg_svgf_blend_weight(s.alpha_colour, length));
        const float wm = sh::pg_svgf_blend_weight(s.alpha_moments, length);
        mo = glm::vec2(sh::pg_svgf_blend(history_moments.x, mo.x, wm),
                       sh::pg_svgf_blend(history_moments.y, mo.y, wm));
      }
      integrated_[i] = glm::vec4(c, 0.0f);
      moments_[i] = glm::vec4(mo.x, mo.y, length, 0.0f);
    }
}

void SvgfReference::variance() {
  const sh::pg_svgf_settings& s = kernel_settings_;
  for (int y = 0; y < height_; ++y)
    for (int x = 0; x < width_; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * width_ + x;
      const glm::vec4 sc = surface_[i];
      if (sc.w <= 0.0f) {
        illumination_[i] = glm::vec4(0.0f);
        continue;
      }
      const glm::vec4 mc = moments_[i];
      const glm::vec4 ic = integrated_[i];
      if (mc.z >= s.min_history) {
        illumination_[i] =
            glm::vec4(xyz(ic), sh::pg_svgf_variance(mc.x, mc.y, mc.z, s.min_history));
        continue;
      }
      const float slope = depth_slope_[i];
      const float lc = sh::pg_luminance(xyz(ic));
      glm::vec3 sum_c(0.0f);
      float sum_m1 = 0.0f, sum_m2 = 0.0f, sum_w = 0.0f;
      for (int dy = -3; dy <= 3; ++dy) {
        const int qy = y + dy;
        if (qy < 0 || qy >= height_) continue;
        for (int dx = -3; dx <= 3; ++dx) {
          const int qx = x + dx;
          if (qx < 0 || qx >= width_) continue;
          const std::size_t j = static_cast<std::size_t>(qy) * width_ + qx;
          const glm::vec4 iq = integrated_[j];
          const float distance = std::sqrt(static_cast<float>(dx * dx + dy * dy));
          const float w = sh::pg_svgf_edge_weight(
              sc, lc, surface_[j], sh::pg_luminance(xyz(iq)),
              sh::pg_svgf_inverse_phi_depth(slope, sc.w, distance, s), 0.0f, s);
          const glm::vec4 mq = moments_[j];
          sum_c += w * xyz(iq);
          sum_m1 += w * mq.x;
          sum_m2 += w * mq.y;
          sum_w += w;
        }
      }
      const float v = sh::pg_svgf_variance(sum_m1 / sum_w, sum_m2 / sum_w, mc.z, s.min_history);
      illumination_[i] = glm::vec4(sum_c / sum_w, v);
    }
}

void SvgfReference::atrous(const std::vector<glm::vec4>& in, std::vector<glm::vec4>& out, int step,
                           int radius) const {
  const sh::pg_svgf_settings& s = kernel_settings_;
  for (int y = 0; y < height_; ++y)
    for (int x = 0; x < width_; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * width_ + x;
      const glm::vec4 sc = surface_[i];
      const glm::vec4 c = in[i];
      if (sc.w <= 0.0f) {
        out[i] = c;
        continue;
      }
      float sum_g = 0.0f, sum_gv = 0.0f;
      for (int dy = -1; dy <= 1; ++dy) {
        const int qy = y + dy;
        if (qy < 0 || qy >= height_) continue;
        for (int dx = -1; dx <= 1; ++dx) {
          const int qx = x + dx;
          if (qx < 0 || qx >= width_) continue;
          const float gw = sh::pg_svgf_gauss3(dx, dy);
          sum_gv += gw * in[static_cast<std::size_t>(qy) * width_ + qx].w;
          sum_g += gw;
        }
      }
      const float inverse_phi_l =
          sh::pg_svgf_inverse_phi_luminance(std::sqrt(std::fmax(sum_gv / sum_g, 0.0f)), s);
      const float slope = depth_slope_[i];
      const float lc = sh::pg_luminance(xyz(c));
      glm::vec3 sum_c(0.0f);
      float sum_v = 0.0f, sum_w = 0.0f;
      const int r = radius;
      for (int dy = -r; dy <= r; ++dy) {
        const int qy = y + dy * step;
        if (qy < 0 || qy >= height_) continue;
        for (int dx = -r; dx <= r; ++dx) {
          const int qx = x + dx * step;
          if (qx < 0 || qx >= width_) continue;
          const std::size_t j = static_cast<std::size_t>(qy) * width_ + qx;
          const glm::vec4 q = in[j];
          const float distance =
              static_cast<float>(step) * std::sqrt(static_cast<float>(dx * dx + dy * dy));
          const float w =
              sh::pg_svgf_atrous_weight(dx, r) * sh::pg_svgf_atrous_weight(dy, r) *
              sh::pg_svgf_edge_weight(sc, lc, surface_[j], sh::pg_luminance(xyz(q)),
                                      sh::pg_svgf_inverse_phi_depth(slope, sc.w, distance, s),
                                      inverse_phi_l, s);
          sum_c += w * xyz(q);
          sum_v += w * w * q.w;
          sum_w += w;
        }
      }
      out[i] = glm::vec4(sum_c / sum_w, sum_v / (sum_w * sum_w));
    }
}

void SvgfReference::remodulate(const std::vector<glm::vec3>& colour, const GBuffer& g) {
  for (std::size_t i = 0; i < output_.size(); ++i) {
    if (!sh::pg_svgf_has_surface(g.flags[i])) {
      output_[i] = glm::vec4(colour[i], 1.0f);
      continue;
    }
    const glm::vec3 albedo =
        sh::pg_svgf_albedo(g.base_color_roughness[i], kernel_settings_.albedo_floor);
    output_[i] =
        glm::vec4(sh::pg_svgf_remodulate(xyz(filtered_[i]), xyz(g.emission[i]), albedo), 1.0f);
  }
}

}  // namespace rtpg
