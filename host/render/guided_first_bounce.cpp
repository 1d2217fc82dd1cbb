#include "render/guided_first_bounce.h"

#include <chrono>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include "rtpg/cl_runtime.h"

namespace rtpg {
namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

// Pixel i's guiding distribution from the state read back after reprojection.
void init_distribution(GuidingDistribution& d, const GBuffer& g, const std::vector<float>& state,
                       std::size_t i) {
  d.init(&state[i * PG_STATE_FLOATS_PER_PIXEL], &g.shading_normal[i].x, &g.view_dir[i].x,
         &g.base_color_roughness[i].x, &g.metallic_specular[i].x, g.flags[i]);
}

}  // namespace

GuidedFirstBounce::GuidedFirstBounce(ClRuntime& runtime, int width, int height,
                                     const GuidingSettings& settings)
    : runtime_(runtime), guider_(std::make_unique<Guider>(runtime, width, height, settings)) {
  for (GuiderGBuffer& g : gbuffers_) g = make_guider_gbuffer(runtime.context(), width, height);
  vpls_ = make_guider_vpls(runtime.context(), width, height);
  samples_ = make_guider_samples(runtime.context(), width, height);
}

GuidedFirstBounce::~GuidedFirstBounce() = default;

void GuidedFirstBounce::begin_frame(const GBuffer& g, const SampleCoordinates& at) {
  auto t = Clock::now();
  current_ = 1 - current_;
  enqueue_upload(runtime_.queue(), g, gbuffers_[current_]);
  translate_cl_errors([&] { runtime_.queue().finish(); });
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
  // Share of surface pixels sampling a trained model, and their mean pi (statistics only).
  struct Counts {
    std::size_t surfaces = 0, guided = 0;
    double pi_sum = 0.0;
  };
  const Counts counts = tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, g.pixel_count(), 8192), Counts{},
      [&](const tbb::blocked_range<std::size_t>& r, Counts c) {
        GuidingDistribution d(guider_->kernel_settings());
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
          if (!g.has_surface(i)) continue;
          ++c.surfaces;
          init_distribution(d, g, state_, i);
          if (!d.guided()) continue;
          ++c.guided;
          c.pi_sum += d.mixing_weight();
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
  host_samples_.direction_pdf.resize(n);
  host_samples_.strategy.resize(n);
  const auto t = Clock::now();
  enqueue_download(runtime_.queue(), samples_, host_samples_);
  translate_cl_errors([&] { runtime_.queue().finish(); });
  readback_ms_ += ms_since(t);
  out.resize(n);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 8192), [&](const auto& r) {
    for (std::size_t i = r.begin(); i != r.end(); ++i) {
      const glm::vec4 d = host_samples_.direction_pdf[i];
      out[i].direction = glm::vec3(d);
      out[i].pdf = d.w > 0.0f && std::isfinite(d.w) ? d.w : 0.0f;
      const std::uint32_t s = host_samples_.strategy[i];
      out[i].strategy = s == PG_STRATEGY_GUIDE  ? kStrategyGuide
                        : s == PG_STRATEGY_BSDF ? kStrategyBsdf
                                                : kStrategyNone;
    }
  });
}

float GuidedFirstBounce::pdf(const GBuffer& g, std::size_t i, const glm::vec3& wi) const {
  GuidingDistribution d(guider_->kernel_settings());
  init_distribution(d, g, state_, i);
  return d.pdf(&wi.x);
}

void GuidedFirstBounce::end_frame(const GBuffer& g, const VplBuffer& vpls,
                                  const SampleCoordinates& at) {
  if (!training_) return;
  const auto t = Clock::now();
  enqueue_upload(runtime_.queue(), vpls, vpls_);
  translate_cl_errors([&] { runtime_.queue().finish(); });
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
