#include "render/guided_first_bounce.h"

#include <chrono>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include "cl/cl_runtime.h"
#include "guiding/guiding_params.h"
#include "render/path_tracer.h"
#include "shared/guiding_pixel.h"
#include "shared/pmm.h"

namespace rtpg {
namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

template <typename T>
void write(cl::CommandQueue& q, const cl::Buffer& b, const std::vector<T>& v) {
  q.enqueueWriteBuffer(b, CL_FALSE, 0, v.size() * sizeof(T), v.data());
}

shared::pg_pmm_state state_at(const std::vector<float>& s, std::size_t i) {
  shared::pg_pmm_state st;
  st.s0 = glm::vec4(s[i * 8 + 0], s[i * 8 + 1], s[i * 8 + 2], s[i * 8 + 3]);
  st.s1 = glm::vec4(s[i * 8 + 4], s[i * 8 + 5], s[i * 8 + 6], s[i * 8 + 7]);
  return st;
}

}  // namespace

GuidedFirstBounce::GuidedFirstBounce(ClRuntime& runtime, int width, int height,
                                     const GuidingConfig& config)
    : runtime_(runtime), guider_(std::make_unique<Guider>(runtime, width, height, config)) {
  const std::size_t n = static_cast<std::size_t>(width) * height;
  cl::Context& ctx = runtime.context();
  for (GuiderGBuffer& g : gbuffers_) {
    g.position_depth = cl::Buffer(ctx, CL_MEM_READ_ONLY, n * 16);
    g.shading_normal = cl::Buffer(ctx, CL_MEM_READ_ONLY, n * 16);
    g.view_dir = cl::Buffer(ctx, CL_MEM_READ_ONLY, n * 16);
    g.base_color_roughness = cl::Buffer(ctx, CL_MEM_READ_ONLY, n * 16);
    g.metallic_specular = cl::Buffer(ctx, CL_MEM_READ_ONLY, n * 16);
    g.flags = cl::Buffer(ctx, CL_MEM_READ_ONLY, n * 4);
    g.material = cl::Buffer(ctx, CL_MEM_READ_ONLY, n * 4);
    g.motion = cl::Buffer(ctx, CL_MEM_READ_ONLY, n * 8);
  }
  vpls_.position = cl::Buffer(ctx, CL_MEM_READ_ONLY, n * 16);
  vpls_.normal = cl::Buffer(ctx, CL_MEM_READ_ONLY, n * 16);
  vpls_.radiance_info = cl::Buffer(ctx, CL_MEM_READ_ONLY, n * 16);
  samples_.direction_pdf = cl::Buffer(ctx, CL_MEM_WRITE_ONLY, n * 16);
  samples_.strategy = cl::Buffer(ctx, CL_MEM_WRITE_ONLY, n * 4);
}

GuidedFirstBounce::~GuidedFirstBounce() = default;

void GuidedFirstBounce::upload(const GBuffer& g, GuiderGBuffer& dst) {
  cl::CommandQueue& q = runtime_.queue();
  write(q, dst.position_depth, g.position_depth);
  write(q, dst.shading_normal, g.shading_normal);
  write(q, dst.view_dir, g.view_dir);
  write(q, dst.base_color_roughness, g.base_color_roughness);
  write(q, dst.metallic_specular, g.metallic_specular);
  write(q, dst.flags, g.flags);
  write(q, dst.material, g.material_id);
  write(q, dst.motion, g.motion);
}

void GuidedFirstBounce::begin_frame(const GBuffer& g, const SampleCoordinates& at) {
  auto t = Clock::now();
  current_ = 1 - current_;
  upload(g, gbuffers_[current_]);
  runtime_.queue().finish();
  upload_ms_ = ms_since(t);
  if (have_previous_) {
    guider_->reproject(gbuffers_[current_], gbuffers_[1 - current_]);
  } else {
    guider_->reset();
  }
  have_previous_ = true;
  t = Clock::now();
  guider_->read_state(state_);
  readback_ms_ = ms_since(t);
  sample_ms_ = 0.0;
  const shared::pg_guiding_params p = make_guiding_params(guider_->config());
  // Share of surface pixels sampling a trained model, and their mean pi (statistics only).
  struct Counts {
    std::size_t surfaces = 0, guided = 0;
    double pi_sum = 0.0;
  };
  const Counts counts = tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, g.pixel_count(), 8192), Counts{},
      [&](const tbb::blocked_range<std::size_t>& r, Counts c) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
          if (!g.has_surface(i)) continue;
          ++c.surfaces;
          if (!shared::pg_guiding_applies(g.flags[i], g.base_color_roughness[i].w, p)) continue;
          const shared::pg_pmm_model m = shared::pg_pmm_model_from_state(state_at(state_, i), p);
          if (!m.valid) continue;
          ++c.guided;
          c.pi_sum += m.pi;
        }
        return c;
      },
      [](Counts a, const Counts& b) {
        a.surfaces += b.surfaces;
        a.guided += b.guided;
        a.pi_sum += b.pi_sum;
        return a;
      });
  const std::size_t surfaces = counts.surfaces, guided = counts.guided;
  const double pi_sum = counts.pi_sum;
  guided_fraction_ = surfaces ? static_cast<double>(guided) / static_cast<double>(surfaces) : 0.0;
  mean_pi_ = guided ? pi_sum / static_cast<double>(guided) : 0.0;
  trained_fraction_ = 0.0;
}

void GuidedFirstBounce::sample(const GBuffer& g, const SampleCoordinates& at,
                               std::vector<FirstBounceSample>& out) {
  guider_->sample(gbuffers_[current_], at.seed, at.frame, at.sample, samples_);
  sample_ms_ += guider_->last_times().sample_ms;
  const std::size_t n = g.pixel_count();
  direction_pdf_.resize(n);
  strategy_.resize(n);
  const auto t = Clock::now();
  runtime_.queue().enqueueReadBuffer(samples_.direction_pdf, CL_FALSE, 0, n * 16,
                                     direction_pdf_.data());
  runtime_.queue().enqueueReadBuffer(samples_.strategy, CL_TRUE, 0, n * 4, strategy_.data());
  readback_ms_ += ms_since(t);
  out.resize(n);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 8192), [&](const auto& r) {
    for (std::size_t i = r.begin(); i != r.end(); ++i) {
      const glm::vec4 d = direction_pdf_[i];
      out[i].direction = glm::vec3(d);
      out[i].pdf = d.w > 0.0f && std::isfinite(d.w) ? d.w : 0.0f;
      out[i].strategy = strategy_[i] == PG_STRATEGY_GUIDE  ? kStrategyGuide
                        : strategy_[i] == PG_STRATEGY_BSDF ? kStrategyBsdf
                                                           : kStrategyNone;
    }
  });
}

float GuidedFirstBounce::pdf(const GBuffer& g, std::size_t i, const glm::vec3& wi) const {
  const shared::pg_guiding_params p = make_guiding_params(guider_->config());
  const shared::pg_frame frame = gbuffer_frame(g, i);
  const glm::vec3 wo = shared::pg_to_local(frame, glm::vec3(g.view_dir[i]));
  const shared::pg_lobes lobes = shared::pg_make_lobes(gbuffer_material(g, i), wo);
  shared::pg_pmm_state st = shared::pg_pmm_initial_state();
  if (shared::pg_guiding_applies(g.flags[i], g.base_color_roughness[i].w, p))
    st = state_at(state_, i);
  const shared::pg_pmm_model model = shared::pg_pmm_model_from_state(st, p);
  return shared::pg_pmm_pdf(model, lobes, wo, shared::pg_to_local(frame, wi));
}

void GuidedFirstBounce::end_frame(const GBuffer& g, const VplBuffer& vpls,
                                  const SampleCoordinates& at) {
  if (!training_) return;
  const auto t = Clock::now();
  cl::CommandQueue& q = runtime_.queue();
  write(q, vpls_.position, vpls.position);
  write(q, vpls_.normal, vpls.normal);
  write(q, vpls_.radiance_info, vpls.radiance);
  q.finish();
  upload_ms_ += ms_since(t);
  guider_->train(gbuffers_[current_], vpls_, at.seed, at.frame);
  std::size_t surfaces = 0;
  for (std::size_t i = 0; i < g.pixel_count(); ++i) surfaces += g.has_surface(i);
  trained_fraction_ =
      surfaces ? static_cast<double>(guider_->count_trained()) / static_cast<double>(surfaces)
               : 0.0;
}

void GuidedFirstBounce::report(std::map<std::string, double>& time_ms,
                               std::map<std::string, double>& extra) {
  const GuiderTimes& k = guider_->last_times();
  time_ms["reproject"] = have_previous_ ? k.reproject_ms : 0.0;
  time_ms["sample"] = sample_ms_;
  time_ms["train"] = k.train_ms;
  time_ms["upload"] = upload_ms_;
  time_ms["readback"] = readback_ms_;
  extra["guided_fraction"] = guided_fraction_;
  extra["trained_fraction"] = trained_fraction_;
  extra["mean_pi"] = mean_pi_;
}

}  // namespace rtpg
