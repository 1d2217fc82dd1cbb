// The exchangeable step of the integrator: how the first bounce direction at the primary
// hit is chosen. Plain path tracing samples the BSDF (BsdfFirstBounce); guiding replaces it
// with the mixture of the paper (eq. 2) without touching the rest of the path tracer.
#pragma once

#include <cmath>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "render/gbuffer.h"
#include "rtpg/guiding_layout.h"
#include "shared/pmm.h"
#include "shared/sample_packing.h"

namespace rtpg {

// Which strategy produced a first-bounce direction (the paper trains only on kBsdf samples).
enum FirstBounceStrategy : std::uint32_t {
  kStrategyNone = 0,
  kStrategyBsdf = 1,
  kStrategyGuide = 2
};
static_assert(kStrategyNone == PG_STRATEGY_NONE && kStrategyBsdf == PG_STRATEGY_BSDF &&
                  kStrategyGuide == PG_STRATEGY_GUIDE,
              "the sample kernel's strategies are read in place as FirstBounceStrategy");

struct FirstBounceSample {
  glm::vec3 direction{0.0f};  // world space, unit
  float pdf = 0.0f;           // solid-angle density of the whole sampler; 0 = no sample
  std::uint32_t strategy = kStrategyNone;
};

// One pass's first-bounce samples, in the sampler's own memory (valid until its next sample()
// or end_frame()): pixel i's direction (world space, unit) and the whole sampler's solid-angle
// density in direction_pdf[i] (a density not above 0, or not finite: no sample), and its
// FirstBounceStrategy in strategy[i]. The guided sampler hands out the sample kernel's output
// as it lies (include/rtpg/guiding_layout.h: PG_STRATEGY_* equal FirstBounceStrategy), or, where
// they crossed the bus packed (HostTransfer::packed), the packed channels instead
// (PG_PACKED_SAMPLE_CHANNELS; direction_pdf and strategy null). at() reads either.
struct FirstBounceSamples {
  const glm::vec4* direction_pdf = nullptr;
  const std::uint32_t* strategy = nullptr;
  const glm::vec2* packed_direction = nullptr;
  const float* packed_pdf_strategy = nullptr;
  // Inline: the path tracer reads every pixel's sample through it.
  FirstBounceSample at(std::size_t i) const {
    FirstBounceSample s;
    if (direction_pdf != nullptr) {
      const glm::vec4 d = direction_pdf[i];
      s.direction = glm::vec3(d);
      s.pdf = d.w;
      s.strategy = strategy[i];
    } else {
      s.direction = shared::pg_unpack_direction(packed_direction[i]);
      s.pdf = shared::pg_sample_density_of(packed_pdf_strategy[i]);
      s.strategy = shared::pg_sample_strategy_of(packed_pdf_strategy[i]);
    }
    if (!std::isfinite(s.pdf)) s.pdf = 0.0f;  // no sample
    return s;
  }
};

struct SampleCoordinates {
  std::uint32_t seed = 0, frame = 0, sample = 0;
};

struct VplBuffer;

// Pixel i's guiding mixture as a later path vertex borrows it (guiding beyond the first
// bounce, docs/guiding.md): the Gaussian lives in the square of pixel i's hemisphere frame.
struct PixelGuide {
  shared::pg_pmm_model model;  // model.valid == 0: the pixel has no trained Gaussian
  shared::pg_frame frame;      // pixel i's shading frame
};

class FirstBounceSampler {
 public:
  virtual ~FirstBounceSampler() = default;
  // Before the frame's first sample(): the G-buffer of the frame is final (guiding
  // reprojects its state here).
  virtual void begin_frame(const GBuffer& gbuffer, const SampleCoordinates& at) {}
  // After the frame's last sample, with the VPLs of its first path-tracing pass (guiding
  // trains here; every sample of a frame uses the model begin_frame made).
  virtual void end_frame(const GBuffer& gbuffer, const VplBuffer& vpls,
                         const SampleCoordinates& at) {}
  virtual bool wants_vpls() const { return false; }
  // Whether end_frame sends the VPLs over a bus packed (VplBuffer::for_bus: the path tracer
  // then writes their packed form too).
  virtual bool sends_packed_vpls() const { return false; }
  // True when the sampler reads the G-buffer in place from begin_frame() until the next
  // frame's end_frame() (its reprojection reads last frame's): the renderer then writes each
  // frame into the other of two G-buffers, leaving last frame's untouched.
  virtual bool reads_gbuffers_in_place() const { return false; }
  // What the path tracer will ask besides sample(): pdf() (under FirstBounceMis::mixture) and
  // pixel_guide() (guided later vertices). The renderer announces it when the sampler is set;
  // a sampler may then skip making what nobody reads (the guided one: the mixture's stores and
  // copies, docs/design.md, "What crosses the bus"). Until told, a sampler answers both.
  struct HostQueries {
    bool pdf = true, pixel_guide = true;
  };
  virtual void expect_queries(const HostQueries& queries) {}
  // Figures of the last frame: times (ms) by kernel name, and other figures by name.
  virtual void report(std::map<std::string, double>& time_ms,
                      std::map<std::string, double>& extra) {}
  // One direction for every surface pixel of the G-buffer (others get density 0).
  virtual FirstBounceSamples sample(const GBuffer& gbuffer, const SampleCoordinates& at) = 0;
  // True when the samples come from a device that works beside the host and the sampler splits
  // sample() in two: start_sample() enqueues it and returns at once, finish_sample() waits and
  // returns what sample() would have. In between the path tracer makes the primary hit's light
  // samples and traces their shadow rays, which do not depend on the first bounce
  // (docs/guiding.md, "Sampling overlapped with the primary hit's light samples"). The host
  // must not read anything of the sampler in between; begin_frame() may likewise return before
  // the device is done with it. Samplers that do not split never have these two called.
  virtual bool samples_beside_the_host() const { return false; }
  virtual void start_sample(const GBuffer& gbuffer, const SampleCoordinates& at) {}
  virtual FirstBounceSamples finish_sample() { return {}; }
  // True when sample() draws bsdf_first_bounce_sample() for every pixel (BsdfFirstBounce):
  // the renderer then leaves sample() out and the path tracer draws the same directions at
  // the primary hit, in the pass that already has each pixel's frame and lobes, instead of a
  // pass of its own over every pixel (docs/host-path-tracer.md, "The BSDF's first bounce at
  // the primary hit").
  virtual bool samples_the_bsdf() const { return false; }
  // The density sample() uses at pixel i for direction wi: next-event estimation at the
  // primary hit needs it for its MIS weight under FirstBounceMis::mixture (under bsdf, the
  // default, the path tracer weighs with the BSDF's density). The caller passes what it already has
  // of the pixel: its lobes, and wo and wi in its shading frame (gbuffer_frame).
  virtual float pdf(const GBuffer& gbuffer, std::size_t i, const shared::pg_lobes& lobes,
                    const glm::vec3& wo, const glm::vec3& wi) const = 0;
  // The mixture pixel i sampled this frame, for a secondary vertex on pixel i's surface;
  // false when the sampler has none (BSDF sampling).
  virtual bool pixel_guide(const GBuffer& gbuffer, std::size_t i, PixelGuide& out) const {
    return false;
  }
};

// BSDF importance sampling of pixel i's first bounce (frame, wo and lobes of the pixel, as
// gbuffer_frame and gbuffer_material give them): its own random stream, so any pass may draw it.
FirstBounceSample bsdf_first_bounce_sample(const shared::pg_frame& frame, const glm::vec3& wo,
                                           const shared::pg_lobes& lobes,
                                           const SampleCoordinates& at, std::size_t i);
// The same from the start state of that stream, pg_rng_make(at.seed, i, at.frame, at.sample,
// PG_RNG_STREAM_FIRST_BOUNCE).state, made by the caller (render/stream_starts.h).
FirstBounceSample bsdf_first_bounce_sample(const shared::pg_frame& frame, const glm::vec3& wo,
                                           const shared::pg_lobes& lobes,
                                           std::uint32_t stream_start);

// BSDF importance sampling, on the host.
class BsdfFirstBounce final : public FirstBounceSampler {
 public:
  bool samples_the_bsdf() const override { return true; }
  FirstBounceSamples sample(const GBuffer& gbuffer, const SampleCoordinates& at) override;
  float pdf(const GBuffer& gbuffer, std::size_t i, const shared::pg_lobes& lobes,
            const glm::vec3& wo, const glm::vec3& wi) const override;

 private:
  std::vector<glm::vec4> direction_pdf_;
  std::vector<std::uint32_t> strategy_;
};
}  // namespace rtpg
