// One frame, as data flows (docs/design.md, "One frame"): camera rays -> Embree primary hits ->
// G-buffer -> first-bounce sampler -> host path tracer -> (guiding: training on the VPLs).
// The renderer is the one place that joins scene, tracer and first-bounce sampler.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "render/first_bounce.h"
#include "render/gbuffer.h"
#include "render/lights.h"
#include "render/path_tracer.h"
#include "render/surface.h"
#include "render/world_guide.h"
#include "rtpg/errors.h"
#include "scene/scene.h"
#include "trace/embree_scene.h"
#include "util/huge_pages.h"

namespace rtpg {

struct RenderSettings {
  int width = 640, height = 360;
  int spp = 1;  // paths per pixel per frame (sharing one G-buffer)
  std::uint32_t seed = 0;
  bool jitter = true;       // sub-pixel jitter of the camera ray, new every frame
  std::string camera_path;  // "" = static camera
  int camera_frame = -1;    // >= 0: the camera stays at this frame of the path (references)
  PathTracerSettings path_tracer;
  // Later vertices guided by the world-space guide (render/world_guide.h), trained at the end
  // of every frame from its later vertices' bounces.
  bool world_guide = false;
  WorldGuideSettings world_guide_settings;
};

struct FrameStats {
  int index = 0;
  std::map<std::string, double> time_ms;  // "total", "primary", "gbuffer", "first_bounce", "trace",
                                          // "shade", "compact" (PassTimes), kernels
  std::uint64_t nonfinite_samples = 0;
  std::uint64_t primary_rays = 0, secondary_rays = 0, shadow_rays = 0;
  std::uint64_t guided_vertices = 0;    // later path vertices that sampled a borrowed guide
  std::map<std::string, double> extra;  // sampler-specific figures (e.g. guided fraction)
};

// A RenderSettings field the renderer cannot work with: what() reads "<setting>: <problem>"
// (setting: resolution, spp, camera_path); the command line names its flag instead.
class RenderSettingError : public InputError {
 public:
  RenderSettingError(const std::string& setting, const std::string& problem)
      : InputError(setting, problem), setting_(setting), problem_(problem) {}
  const std::string& setting() const { return setting_; }
  const std::string& problem() const { return problem_; }

 private:
  std::string setting_, problem_;
};

class Renderer {
 public:
  // Throws RenderSettingError when the resolution is zero or too large to allocate, spp is
  // below 1 or the camera path does not exist.
  Renderer(const Scene& scene, const RenderSettings& settings);
  ~Renderer();

  // Replaces the first-bounce strategy (default: BSDF sampling on the host).
  void set_first_bounce_sampler(std::unique_ptr<FirstBounceSampler> sampler);
  FirstBounceSampler& first_bounce_sampler() { return *sampler_; }

  // Renders frame `index` (camera at index / fps on the camera path): image() is its mean over
  // spp samples.
  FrameStats render_frame(int index);

  const std::vector<glm::vec3>& image() const { return image_; }
  const GBuffer& gbuffer() const { return gbuffers_[current_gbuffer_]; }  // the last frame's
  const VplBuffer& vpls() const { return vpls_; }
  const RenderSettings& settings() const { return settings_; }
  const EmbreeScene& tracer() const { return *tracer_; }
  const Lights& lights() const { return *lights_; }
  CameraView camera_at(int frame) const;

 private:
  void build_gbuffer(int frame, FrameStats& stats);

  const Scene& scene_;
  RenderSettings settings_;
  std::unique_ptr<EmbreeScene> tracer_;
  std::unique_ptr<TriangleTable> triangles_;  // built with the BVH, from the same positions
  std::unique_ptr<Lights> lights_;
  std::unique_ptr<PathTracer> path_tracer_;
  std::unique_ptr<WorldGuide> world_guide_;  // with settings_.world_guide
  // The frame's G-buffer is gbuffers_[current_gbuffer_]; the second is allocated only for a
  // sampler that reads G-buffers in place (FirstBounceSampler::reads_gbuffers_in_place), and
  // then the frames alternate between the two.
  GBuffer gbuffers_[2];
  int current_gbuffer_ = 0;
  VplBuffer vpls_;
  // Declared after the buffers it may read, so that it is destroyed before them: a guided
  // sampler can leave the last frame's training running on the device, reading the G-buffer and
  // the VPLs in place, and its destructor waits for it (GuidedFirstBounce, Overlap).
  std::unique_ptr<FirstBounceSampler> sampler_;
  std::vector<glm::vec3> image_, pass_;
  LargeVector<Ray> camera_rays_;
  LargeVector<Hit> camera_hits_;
};

}  // namespace rtpg
