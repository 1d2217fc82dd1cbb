#include "render/renderer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <new>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "render/camera_rays.h"
#include "render/surface.h"
#include "rtpg/guiding_layout.h"
#include "shared/gbuffer_packing.h"
#include "shared/rng.h"
#include "rtpg/errors.h"
#include "rtpg/image_size.h"

namespace rtpg {
namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

}  // namespace

Renderer::Renderer(const Scene& scene, const RenderSettings& settings)
    : scene_(scene), settings_(settings) {
  const std::string size_problem = image_size_problem(settings.width, settings.height);
  if (!size_problem.empty()) throw RenderSettingError("resolution", size_problem);
  const std::uint64_t pixels = static_cast<std::uint64_t>(settings.width) * settings.height;
  if (settings.spp <= 0) throw RenderSettingError("spp", "must be at least 1");
  if (settings.path_tracer.max_bounces < 0 || settings.path_tracer.max_bounces > kMaxPathBounces)
    throw RenderSettingError("max_bounces", "must lie in [0, " + std::to_string(kMaxPathBounces) +
                                                "], got " +
                                                std::to_string(settings.path_tracer.max_bounces));
  if (!settings.camera_path.empty() && !scene.camera.paths.count(settings.camera_path))
    throw RenderSettingError("camera_path",
                             "scene has no camera path named '" + settings.camera_path + "'");
  if (settings.world_guide) {
    const int cells_log2 = settings.world_guide_settings.max_cells_log2;
    if (cells_log2 < 0 || cells_log2 > kMaxCellsLog2)
      throw RenderSettingError("world_guide_settings.max_cells_log2",
                               "must lie in [0, " + std::to_string(kMaxCellsLog2) + "], got " +
                                   std::to_string(cells_log2));
    // A vertex guided by a borrowed pixel mixture would be recorded in that pixel's frame, not
    // its cell's (the command line offers one or the other: --guide-vertices).
    if (settings.path_tracer.guide_secondary)
      throw RenderSettingError("world_guide",
                               "cannot be combined with path_tracer.guide_secondary");
  }
  try {
    gbuffers_[0].resize(settings.width, settings.height);
    image_.assign(pixels, glm::vec3(0.0f));
  } catch (const std::bad_alloc&) {
    throw RenderSettingError("resolution",
                             "not enough memory for " + std::to_string(pixels) + " pixels");
  }
  tracer_ = std::make_unique<EmbreeScene>(scene);
  triangles_ = std::make_unique<TriangleTable>(scene);
  lights_ = std::make_unique<Lights>(scene);
  path_tracer_ =
      std::make_unique<PathTracer>(scene, *tracer_, *triangles_, *lights_, settings.path_tracer);
  sampler_ = std::make_unique<BsdfFirstBounce>();
  if (settings.world_guide) {
    world_guide_ = std::make_unique<WorldGuide>(scene.bounds_min(), scene.bounds_max(),
                                                settings.world_guide_settings);
    path_tracer_->set_world_guide(world_guide_.get());
  }
}

Renderer::~Renderer() = default;

void Renderer::set_first_bounce_sampler(std::unique_ptr<FirstBounceSampler> sampler) {
  if (sampler->reads_gbuffers_in_place() && gbuffers_[1].pixel_count() == 0) {
    try {
      gbuffers_[1].resize(settings_.width, settings_.height);
    } catch (const std::bad_alloc&) {
      throw RenderSettingError("resolution", "not enough memory for a second G-buffer of " +
                                                 std::to_string(gbuffers_[0].pixel_count()) +
                                                 " pixels");
    }
  }
  sampler->expect_queries({settings_.path_tracer.first_bounce_mis == FirstBounceMis::mixture,
                           settings_.path_tracer.guide_secondary});
  vpls_.for_bus = sampler->sends_packed_vpls();
  sampler_ = std::move(sampler);
}

CameraView Renderer::camera_at(int frame) const {
  if (settings_.camera_path.empty()) return scene_.camera.view;
  const CameraPath& path = scene_.camera.paths.at(settings_.camera_path);
  const int at = settings_.camera_frame >= 0 ? settings_.camera_frame : frame;
  return path.at(static_cast<float>(at) / path.fps);
}

void Renderer::build_gbuffer(int frame, FrameStats& stats) {
  const int w = settings_.width, h = settings_.height;
  const float aspect = static_cast<float>(w) / static_cast<float>(h);
  const CameraFrame camera = make_camera_frame(camera_at(frame), aspect);
  const CameraFrame previous = make_camera_frame(camera_at(frame > 0 ? frame - 1 : 0), aspect);
  if (sampler_->reads_gbuffers_in_place()) current_gbuffer_ = 1 - current_gbuffer_;
  GBuffer& g = gbuffers_[current_gbuffer_];
  const std::size_t n = g.pixel_count();
  g.camera = camera;
  g.previous_camera = previous;
  camera_rays_.resize(n);
  camera_hits_.resize(n);

  auto start = Clock::now();
  g.jitter = CameraJitter{settings_.jitter, settings_.seed, static_cast<std::uint32_t>(frame)};
  make_camera_rays(camera, w, h, g.jitter, camera_rays_.data());
  tracer_->intersect_image(camera_rays_.data(), camera_hits_.data(), w, h);
  stats.time_ms["primary"] += ms_since(start);
  stats.primary_rays += n;

  start = Clock::now();
  const int rows_per_task = std::max(1, 4096 / std::max(w, 1));
  // A static camera (no path, or a path held at one frame) has exactly zero motion, whatever the
  // jitter.
  const bool static_camera =
      frame == 0 || settings_.camera_path.empty() || settings_.camera_frame >= 0;
  g.camera_moved = !static_camera;
  const bool load_surfaces_ahead = path_tracer_->loads_surfaces_ahead();
  tbb::parallel_for(tbb::blocked_range<int>(0, h, rows_per_task), [&](const auto& rows) {
    const std::size_t rows_end = static_cast<std::size_t>(rows.end()) * static_cast<std::size_t>(w);
    for (int y = rows.begin(); y != rows.end(); ++y)
      for (int x = 0; x < w; ++x) {
        const std::size_t i =
            static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x);
        if (load_surfaces_ahead)
          prefetch_surfaces_ahead(scene_, *triangles_, camera_hits_.data(), i, rows_end);
        const Ray& ray = camera_rays_[i];
        const Hit& hit = camera_hits_[i];
        const glm::vec3 dir = glm::normalize(ray.direction);
        g.motion[i] = glm::vec2(0.0f);
        if (!hit.valid()) {
          // Every channel written, as GBuffer::resize leaves a sky pixel: nothing of an older
          // frame stays behind (the frames may alternate between two G-buffers).
          g.flags[i] = PG_GBUF_SKY;
          g.position_depth[i] = glm::vec4(0.0f);
          g.shading_normal[i] = glm::vec4(0.0f, 0.0f, 1.0f, 0.0f);
          g.geometric_normal[i] = glm::vec4(0.0f, 0.0f, 1.0f, 0.0f);
          g.base_color_roughness[i] = glm::vec4(0.0f);
          g.metallic_specular[i] = glm::vec4(0.0f);
          g.material[i] = 0;
          g.emission[i] = glm::vec4(lights_->escaped_radiance(dir), 0.0f);
          g.view_dir[i] = glm::vec4(-dir, 0.0f);
          continue;
        }
        const SurfacePoint sp = make_surface_point(scene_, *triangles_, ray, hit);
        const float depth = glm::dot(sp.position - camera.position, camera.forward);
        g.position_depth[i] = glm::vec4(sp.position, depth);
        g.shading_normal[i] = glm::vec4(sp.shading_normal, 0.0f);
        g.geometric_normal[i] = glm::vec4(sp.geometric_normal, sp.offset_distance);
        g.view_dir[i] = glm::vec4(-dir, 0.0f);
        g.base_color_roughness[i] = glm::vec4(sp.material.base_color.x, sp.material.base_color.y,
                                              sp.material.base_color.z, sp.material.roughness);
        g.metallic_specular[i] = glm::vec4(sp.material.metallic, sp.material.specular, 0.0f, 0.0f);
        g.emission[i] = glm::vec4(sp.emission, 0.0f);
        g.material[i] = sp.material_id;
        std::uint32_t flags = 0;
        if (sp.emission.x > 0.0f || sp.emission.y > 0.0f || sp.emission.z > 0.0f)
          flags |= PG_GBUF_EMITTER;
        if (sp.material.roughness <= PG_MIN_ROUGHNESS) flags |= PG_GBUF_DELTA;
        if (sp.transmissive) flags |= PG_GBUF_TRANSMISSIVE;
        g.flags[i] = flags;
        float px = 0.0f, py = 0.0f;
        if (!static_camera && previous.project(sp.position, px, py))
          g.motion[i] = glm::vec2(shared::pg_bounded_motion(px * static_cast<float>(g.width) -
                                                            (static_cast<float>(x) + 0.5f)),
                                  shared::pg_bounded_motion(py * static_cast<float>(g.height) -
                                                            (static_cast<float>(y) + 0.5f)));
      }
  });
  stats.time_ms["gbuffer"] += ms_since(start);
}

FrameStats Renderer::render_frame(int index) {
  FrameStats stats;
  stats.index = index;
  const auto start = Clock::now();
  build_gbuffer(index, stats);
  const GBuffer& gbuffer = gbuffers_[current_gbuffer_];
  const std::size_t n = gbuffer.pixel_count();
  PassTimes times;
  RayCounts rays;
  const SampleCoordinates frame_at{settings_.seed, static_cast<std::uint32_t>(index), 0u};
  auto t = Clock::now();
  sampler_->begin_frame(gbuffer, frame_at);
  stats.time_ms["guiding_begin"] = ms_since(t);
  for (int s = 0; s < settings_.spp; ++s) {
    SampleCoordinates at{settings_.seed, static_cast<std::uint32_t>(index),
                         static_cast<std::uint32_t>(s)};
    const bool inline_bsdf = sampler_->samples_the_bsdf();
    FirstBounceSamples first;
    PathTracer::FirstBounceSource source;
    if (!inline_bsdf) {
      const SampleCoordinates first_at =
          first_bounce_coordinates(at, settings_.path_tracer.shared_randoms);
      t = Clock::now();
      // The primary hit's light samples can be made while a device samples, unless their MIS
      // weight asks the sampler for its density (FirstBounceMis::mixture).
      if (sampler_->samples_beside_the_host() &&
          settings_.path_tracer.first_bounce_mis == FirstBounceMis::bsdf) {
        sampler_->start_sample(gbuffer, first_at);
        source.await = [&] {
          const auto wait = Clock::now();
          const FirstBounceSamples samples = sampler_->finish_sample();
          stats.time_ms["first_bounce"] += ms_since(wait);
          return samples;
        };
      } else {
        first = sampler_->sample(gbuffer, first_at);
        source.ready = &first;
      }
      stats.time_ms["first_bounce"] += ms_since(t);
    }
    const bool keep_vpls = s == 0 && sampler_->wants_vpls();
    path_tracer_->trace(gbuffer, source, *sampler_, at, pass_, keep_vpls ? &vpls_ : nullptr,
                        stats.nonfinite_samples, rays, times);
    t = Clock::now();
    if (settings_.spp == 1) {
      // One sample: the pass is the image (x * 1 + 0 is x), so the buffers trade places.
      image_.swap(pass_);
      stats.time_ms["accumulate"] += ms_since(t);
      continue;
    }
    const float weight = 1.0f / static_cast<float>(settings_.spp);
    // The first sample starts the sum from zero here, in parallel, instead of a serial fill of
    // the image before the loop (docs/host-path-tracer.md, "Empty shadow rays skipped;
    // per-frame fills").
    const bool first_sample = s == 0;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 16384), [&](const auto& r) {
      for (std::size_t i = r.begin(); i != r.end(); ++i) {
        const glm::vec3 sum = first_sample ? glm::vec3(0.0f) : image_[i];
        image_[i] = sum + pass_[i] * weight;
      }
    });
    stats.time_ms["accumulate"] += ms_since(t);
  }
  // Training changes the model, so it waits for the frame's last sample: every sample of the
  // frame is drawn from one model, the one next-event MIS at the primary hit weighs against.
  if (sampler_->wants_vpls()) {
    t = Clock::now();
    sampler_->end_frame(gbuffer, vpls_, frame_at);
    stats.time_ms["guiding_end"] = ms_since(t);
  }
  if (world_guide_) {
    // After the frame's last sample, as the first-bounce sampler's training: every sample of
    // the frame drew from one set of cells.
    t = Clock::now();
    world_guide_->train(path_tracer_->world_samples());
    path_tracer_->clear_world_samples();
    stats.time_ms["world_train"] = ms_since(t);
    stats.extra["world_cells"] = static_cast<double>(world_guide_->cell_count());
    stats.extra["world_samples"] = static_cast<double>(world_guide_->samples_last_frame());
    stats.extra["world_mean_pi"] = world_guide_->mean_pi();
    stats.extra["world_at_pi_min"] = world_guide_->fraction_at_pi_min();
  }
  stats.time_ms["trace"] = times.trace_ms;
  if (path_tracer_->grouped_rays()) stats.time_ms["group_rays"] = times.group_ms;
  stats.extra["bounce_rays_grouped"] = path_tracer_->grouped_rays() ? 1.0 : 0.0;
  stats.time_ms["shade"] = times.shade_ms;
  stats.time_ms["compact"] = times.compact_ms;
  stats.secondary_rays = rays.secondary;
  stats.shadow_rays = rays.shadow;
  stats.guided_vertices = rays.guided_vertices;
  sampler_->report(stats.time_ms, stats.extra);
  stats.time_ms["total"] = ms_since(start);
  return stats;
}

}  // namespace rtpg
