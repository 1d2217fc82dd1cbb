// A first-bounce sampler that hands every call to another one, for tests that change or record
// one of them (tests/render/test_guiding_image.cpp, tests/render/test_vpls.cpp). It does not
// forward samples_the_bsdf(): the renderer must call its sample().
#pragma once

#include <map>
#include <memory>
#include <string>
#include <utility>

#include "render/first_bounce.h"

namespace rtpg {

class ForwardingSampler : public FirstBounceSampler {
 public:
  explicit ForwardingSampler(std::unique_ptr<FirstBounceSampler> inner)
      : inner_(std::move(inner)) {}
  void begin_frame(const GBuffer& g, const SampleCoordinates& at) override {
    inner_->begin_frame(g, at);
  }
  void end_frame(const GBuffer& g, const VplBuffer& v, const SampleCoordinates& at) override {
    inner_->end_frame(g, v, at);
  }
  bool wants_vpls() const override { return inner_->wants_vpls(); }
  bool sends_packed_vpls() const override { return inner_->sends_packed_vpls(); }
  bool reads_gbuffers_in_place() const override { return inner_->reads_gbuffers_in_place(); }
  void report(std::map<std::string, double>& time_ms,
              std::map<std::string, double>& extra) override {
    inner_->report(time_ms, extra);
  }
  FirstBounceSamples sample(const GBuffer& g, const SampleCoordinates& at) override {
    return inner_->sample(g, at);
  }
  float pdf(const GBuffer& g, std::size_t i, const shared::pg_lobes& lobes, const glm::vec3& wo,
            const glm::vec3& wi) const override {
    return inner_->pdf(g, i, lobes, wo, wi);
  }
  bool pixel_guide(const GBuffer& g, std::size_t i, PixelGuide& out) const override {
    return inner_->pixel_guide(g, i, out);
  }

 private:
  std::unique_ptr<FirstBounceSampler> inner_;
};

}  // namespace rtpg
