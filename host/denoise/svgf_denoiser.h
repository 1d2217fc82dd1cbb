// SVGF on the OpenCL device (docs/denoising.md): per frame, the noisy colour and the G-buffer go
// up (or are read in place where the device shares host memory), four kernels run
// (kernels/svgf_temporal.cl, svgf_variance.cl, svgf_atrous.cl once per iteration,
// svgf_remodulate.cl) and the denoised colour comes back. The history (filtered illumination,
// moments, last frame's surfaces) stays on the device between frames.
#pragma once

#include <array>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "cl/work_groups.h"
#include "denoise/svgf_settings.h"
#include "denoise/svgf_stage.h"
#include "render/gbuffer.h"
#include "rtpg/cl_runtime.h"
#include "rtpg/guider.h"
#include "util/huge_pages.h"

namespace rtpg {

class PinnedStaging;

class SvgfDenoiser {
 public:
  // Throws InputError for settings out of range, a size below 1x1 or a work-group size the
  // device refuses. zero_copy: where the device shares host memory
  // (DeviceInfo::host_unified_memory) and RTPG_HOST_TRANSFER does not ask for copies
  // (resolve_host_transfer, host/render/host_transfer.h), denoise() reads the noisy colour and the
  // G-buffer in place (CL_MEM_USE_HOST_PTR) instead of copying them and writes the denoised
  // colour into the returned vector in place; the temporal pass keeps the channels the next
  // frame's history test needs on the device. Elsewhere they are copied through pinned staging
  // (host/render/pinned_staging.h) and the denoised colour is read back.
  SvgfDenoiser(ClRuntime& runtime, int width, int height, const SvgfSettings& settings = {},
               bool zero_copy = true);
  ~SvgfDenoiser();
  SvgfDenoiser(const SvgfDenoiser&) = delete;
  SvgfDenoiser& operator=(const SvgfDenoiser&) = delete;

  // Filters one frame of noisy colour seen through the G-buffer g, blocking; returns the
  // denoised colour (pixels without a surface keep their input), valid until the next
  // denoise(). Both are the renderer's image layout, three floats a pixel, read and written in
  // place where memory is shared (converting them to four floats and back on the host cost 2.7
  // ms a frame at 960x540; docs/denoising.md, "The colour in the renderer's layout").
  // on_device: g's channels already on the device (the guided sampler's copy of this frame's
  // G-buffer, GuidedFirstBounce::device_gbuffer_of): where denoise() would copy its inputs, it
  // reads the G-buffer's there and uploads only the colour and the emission (28 bytes a pixel
  // instead of 92). Throws InputError when the sizes do not match.
  const std::vector<glm::vec3>& denoise(const std::vector<glm::vec3>& colour, const GBuffer& g,
                                        const GuiderGBuffer* on_device = nullptr);
  // Forgets the history: the next frame starts anew (a camera cut).
  void reset() { has_history_ = false; }

  // Milliseconds of the last denoise() from profiling events: "svgf_upload", "svgf_temporal",
  // "svgf_variance", "svgf_atrous" (all iterations), "svgf_remodulate", "svgf_download".
  const std::map<std::string, double>& times_ms() const { return times_; }
  // Bytes copied between host and device per pixel by the last denoise() (before the first, by
  // one without on_device).
  double host_device_bytes_per_pixel() const;
  // Whether denoise() reads its inputs in place (the constructor's zero_copy on a device that
  // shares host memory).
  bool zero_copy() const { return zero_copy_; }

  // Downloads an intermediate image of the last frame (tests compare it with SvgfReference).
  std::vector<glm::vec4> read(SvgfStage stage);
  std::vector<float> read_depth_slope();

  int width() const { return width_; }
  int height() const { return height_; }
  const SvgfSettings& settings() const { return settings_; }
  // Pixels per work-item of the variance and a-trous kernels (settings().lanes, 0 resolved
  // per device).
  int lanes() const { return lanes_; }
  // The work-groups (settings().local_x and local_y, 0 resolved per device) of the pixel
  // kernels (temporal, remodulate) and of the filters (variance, a-trous).
  const WorkGroupShape& pixel_work_groups() const { return pixel_groups_; }
  const WorkGroupShape& filter_work_groups() const { return filter_groups_; }

 private:
  // Where the output is written in place: unmaps it before the device writes it again.
  void unmap_output();
  // Runs kernel over the image in work-groups of that shape, each work-item covering `lanes`
  // pixels of a row; blocking.
  double run(cl::Kernel& kernel, int lanes, const WorkGroupShape& shape);
  // The G-buffer channels the history test reads, this frame's (written by the temporal pass)
  // and last frame's (ping-pong).
  struct Surfaces {
    cl::Buffer position_depth, shading_normal, material;
  };

  ClRuntime& runtime_;
  ClRuntime::Use runtime_use_{runtime_};  // the runtime must outlive this
  int width_, height_;
  SvgfSettings settings_;
  int lanes_ = 1;
  WorkGroupShape pixel_groups_, filter_groups_;
  bool zero_copy_ = false;
  double upload_bytes_per_pixel_ = 0.0;     // the last denoise()'s
  std::unique_ptr<PinnedStaging> staging_;  // the uploads' way where !zero_copy_
  shared::pg_svgf_settings kernel_settings_;
  cl::Kernel temporal_, variance_, atrous_, remodulate_;
  // The a-trous kernel of the iterations up to the history iteration (atrous_ itself where both
  // radii are the same: SvgfSettings::history_atrous_radius).
  cl::Kernel history_atrous_;
  // Where memory is shared (zero_copy_), the storage of the denoiser's own images below, in
  // whole float4s: host memory in transparent huge pages that the device uses in place
  // (util/huge_pages.h; docs/denoising.md, "The denoiser's images in huge pages"). Declared
  // before the buffers, so that it outlives them.
  std::vector<LargeVector<glm::vec4>> host_images_;
  // The denoised colour, which output_ reads in place where zero_copy_ (declared before it, so
  // that it outlives it).
  std::vector<glm::vec3> output_host_;
  std::array<Surfaces, 2> surfaces_;
  std::array<cl::Buffer, 2> moments_;  // this frame's and last frame's
  int current_ = 0;
  bool has_history_ = false;
  // The inputs' device copies where !zero_copy_.
  cl::Buffer colour_, emission_, position_depth_, shading_normal_, base_color_roughness_, flags_,
      material_, motion_;
  cl::Buffer surface_, depth_slope_, integrated_, history_, output_;
  // The a-trous ping-pong ([0], [1]) and the variance pass's output ([2]).
  std::array<cl::Buffer, 3> illumination_;
  const cl::Buffer* filtered_ = nullptr;  // the last iteration's output
  void* mapped_output_ = nullptr;         // output_ mapped for reading, from denoise() to the next
  std::map<std::string, double> times_;
};

}  // namespace rtpg
