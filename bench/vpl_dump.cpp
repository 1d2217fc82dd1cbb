// vpl_dump: the first-bounce VPLs of path-traced frames with the G-buffer they came from, for
// fitting directional models offline (bench/lobe_fit.py; docs/guiding.md, "How many lobes").
//
//   vpl_dump SCENE WxH FRAMES OUT.bin [SEED]
//
// Static camera, 1 spp, BSDF sampling at the first bounce (plain path tracing, at the scene's full
// depth). OUT.bin: a 16-byte header (magic "RTPGVPL1", width, height as uint32), then per frame
// and pixel 28 float32: position_depth, shading_normal, base_color_roughness and the G-buffer
// flags (as a float, then three zeros), the VPL's position (include/rtpg/guiding_layout.h: w the
// BSDF sample's density in area measure at y), its normal and mixture density, its radiance and
// info bits (as a float), unpacked from normal_radiance.
#include <cstdio>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "render/first_bounce.h"
#include "render/renderer.h"
#include "render/vpl_buffer.h"
#include "scene/scene_loader.h"
#include "shared/vpl_packing.h"

namespace {

using namespace rtpg;

// Plain BSDF sampling that asks for the frame's VPLs and writes them out with the G-buffer.
class DumpingSampler final : public FirstBounceSampler {
 public:
  explicit DumpingSampler(std::FILE* out) : out_(out) {}
  bool samples_the_bsdf() const override { return true; }
  bool wants_vpls() const override { return true; }
  FirstBounceSamples sample(const GBuffer& g, const SampleCoordinates& at) override {
    return bsdf_.sample(g, at);
  }
  float pdf(const GBuffer& g, std::size_t i, const shared::pg_lobes& lobes, const glm::vec3& wo,
            const glm::vec3& wi) const override {
    return bsdf_.pdf(g, i, lobes, wo, wi);
  }
  void end_frame(const GBuffer& g, const VplBuffer& vpls, const SampleCoordinates&) override {
    std::vector<float> row(28 * g.pixel_count());
    for (std::size_t i = 0; i < g.pixel_count(); ++i) {
      float* r = &row[28 * i];
      auto put = [&](int at, const glm::vec4& v) { std::memcpy(r + at, &v, sizeof v); };
      put(0, g.position_depth[i]);
      put(4, g.shading_normal[i]);
      put(8, g.base_color_roughness[i]);
      put(12, glm::vec4(static_cast<float>(g.flags[i]), 0.0f, 0.0f, 0.0f));
      put(16, vpls.position[i]);
      const glm::uvec4 packed = vpls.normal_radiance[i];
      put(20, glm::vec4(shared::pg_vpl_normal(packed), shared::pg_vpl_mixture_density(packed)));
      put(24, glm::vec4(shared::pg_vpl_radiance(packed),
                        static_cast<float>(shared::pg_vpl_info(packed))));
    }
    if (std::fwrite(row.data(), sizeof(float), row.size(), out_) != row.size())
      throw std::runtime_error("vpl_dump: write failed");
  }

 private:
  std::FILE* out_;
  BsdfFirstBounce bsdf_;
};

}  // namespace

int main(int argc, char** argv) {
  if (argc < 5) {
    std::fprintf(stderr, "usage: vpl_dump SCENE WxH FRAMES OUT.bin [SEED]\n");
    return 2;
  }
  try {
    const Scene scene = load_scene(argv[1]);
    RenderSettings settings;
    if (std::sscanf(argv[2], "%dx%d", &settings.width, &settings.height) != 2)
      throw std::runtime_error(std::string("vpl_dump: bad size ") + argv[2]);
    const int frames = std::stoi(argv[3]);
    settings.seed = argc > 5 ? static_cast<std::uint32_t>(std::stoul(argv[5])) : 1u;
    settings.path_tracer.max_bounces = scene.max_bounces > 0 ? scene.max_bounces : 8;
    std::FILE* out = std::fopen(argv[4], "wb");
    if (!out) throw std::runtime_error(std::string("vpl_dump: cannot write ") + argv[4]);
    const std::uint32_t header[4] = {0x4c505452u, 0x314c5056u,  // "RTPGVPL1"
                                     static_cast<std::uint32_t>(settings.width),
                                     static_cast<std::uint32_t>(settings.height)};
    std::fwrite(header, sizeof header, 1, out);
    Renderer renderer(scene, settings);
    renderer.set_first_bounce_sampler(std::make_unique<DumpingSampler>(out));
    for (int f = 0; f < frames; ++f) renderer.render_frame(f);
    std::fclose(out);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 1;
  }
  return 0;
}
