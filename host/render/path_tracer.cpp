#include "render/path_tracer.h"

#include <algorithm>
#include <functional>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <type_traits>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>
#include <tbb/parallel_scan.h>

#include "render/cpu_code.h"
#include "render/mis.h"
#include "render/stream_starts.h"
#include "render/surface.h"
#include "shared/guiding_pixel.h"
#include "shared/rng.h"
#include "shared/vpl_packing.h"
#include "rtpg/guiding_layout.h"

namespace rtpg {
namespace {

using Clock = std::chrono::steady_clock;
constexpr std::size_t kGrain = 2048;
// Random numbers a path vertex draws from its stream, whatever it does with them: three for
// next-event estimation (light choice, point on the light), then four for the bounce (lobe,
// direction, Russian roulette). SharedRandoms counts on them to find where sample 0's stream
// stood at a vertex.
constexpr int kNextEventDraws = 3;
constexpr int kBounceDraws = 4;
// How many vertices ahead the shading loop starts loading the pixel a later vertex borrows
// from (prefetch_borrowable), and the ring of those pixels' indices (a power of two above it).
constexpr std::size_t kPrefetchAhead = 4;
constexpr std::size_t kBorrowRing = 8;
static_assert(kBorrowRing > kPrefetchAhead && (kBorrowRing & (kBorrowRing - 1)) == 0,
              "the ring holds the vertices between a prefetch and its use");
// How many vertices ahead the shading loop starts loading a path's state: after compaction
// the live paths' pixels are sparse, and a state read cold stalled the loop on its first field
// (prefetch_path).
constexpr std::size_t kPathPrefetchAhead = 8;

double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

// Veach's power heuristic (beta = 2) for the strategy with density a against b.
bool is_black(const glm::vec3& c) {
  return c.x <= 0.0f && c.y <= 0.0f && c.z <= 0.0f;
}
bool is_finite(const glm::vec3& c) {
  return std::isfinite(c.x) && std::isfinite(c.y) && std::isfinite(c.z);
}

// The density the primary hit's light sample and first bounce weigh each other with under
// FirstBounceMis::bsdf: the BSDF's, kept above 0 so that a guided bounce into a direction the
// BSDF never samples still counts in full where the light sample cannot reach (the power
// heuristic gives a density of 0 no weight even against 0), and both weights of a direction
// still sum to one.
float bsdf_mis_density(float bsdf_pdf) {
  return std::max(bsdf_pdf, std::numeric_limits<float>::min());
}

// Whether a VPL's density of its own strategy (position.w) can weight a training sample.
bool usable_vpl_density(float pdf) {
  return pdf > 0.0f && std::isfinite(pdf);
}

// Density of a borrowed guide's mixture at world direction w (bsdf_pdf: the vertex's own BSDF
// density there): the Gaussian of the lending pixel in that pixel's frame, mixed with the
// vertex's BSDF.
// The same, given the direction's point in the guide's square (in_square false: the direction
// lies below the guide's hemisphere, where the Gaussian has no density).
float guide_density_at(const PixelGuide& guide, bool in_square, const shared::float2& square,
                       float bsdf_pdf) {
  const float gaussian =
      in_square ? shared::pg_pmm_gaussian_pdf(guide.model, square) * PG_INV_TWO_PI : 0.0f;
  return guide.model.pi * gaussian + (1.0f - guide.model.pi) * bsdf_pdf;
}

float guide_density(const PixelGuide& guide, const glm::vec3& w, float bsdf_pdf) {
  const glm::vec3 l = shared::pg_to_local(guide.frame, w);
  const bool in_square = l.z > 0.0f;
  return guide_density_at(
      guide, in_square, in_square ? shared::pg_hemisphere_to_square(l) : shared::float2(0.0f, 0.0f),
      bsdf_pdf);
}

}  // namespace

PathTracer::PathTracer(const Scene& scene, const EmbreeScene& tracer,
                       const TriangleTable& triangles, const Lights& lights,
                       PathTracerSettings settings)
    : scene_(scene),
      tracer_(tracer),
      triangles_(triangles),
      lights_(lights),
      settings_(settings),
      may_group_(may_group_bounce_rays(settings.bounce_ray_order, scene)),
      ray_order_(scene.bounds_min(), scene.bounds_max()) {
  prefetch_surfaces_ = rtpg::loads_surfaces_ahead(settings_.surface_prefetch, scene);
}

bool may_group_bounce_rays(BounceRayOrder setting, const Scene& scene) {
  if (setting != BounceRayOrder::automatic) return setting == BounceRayOrder::grouped;
  // Embree 3's BVH takes 70-96 bytes a triangle (measured with its memory monitor at 36 to
  // 262,000 triangles); grouping costs about 7 ns a ray on two cores, which a BVH held in a
  // core's cache does not win back (docs/host-path-tracer.md, "Bounce rays traced in groups").
  constexpr std::size_t kBvhBytesPerTriangle = 80;
  return scene.triangle_count() * kBvhBytesPerTriangle > core_cache_bytes();
}

void PathTracer::trace(const GBuffer& g, const FirstBounceSource& first,
                       const FirstBounceSampler& sampler, const SampleCoordinates& at,
                       std::vector<glm::vec3>& radiance, VplBuffer* vpls, std::uint64_t& nonfinite,
                       RayCounts& rays, PassTimes& times) {
  const std::size_t n = g.pixel_count();
  gbuffer_ = &g;
  sampler_ = &sampler;
  at_ = at;
  first_bounce_mis_deferred_ =
      settings_.first_bounce_mis == FirstBounceMis::mixture && !sampler.samples_the_bsdf();
  prepare(n, vpls);
  const bool timing_choice = may_group_ && settings_.bounce_ray_order == BounceRayOrder::automatic;
  group_this_pass_ = may_group_ && (!timing_choice || order_choice_.next_takes_second());
  auto start = Clock::now();
  if (first.await) {
    // The primary hit's light samples and their shadow rays while the device makes the first
    // bounce's directions (FirstBounceSampler::start_sample), then the first bounce.
    start_paths(g, nullptr, sampler, at, vpls, StartPart::next_event);
    times.shade_ms += ms_since(start);
    run_shadow_rays(rays, times);
    const FirstBounceSamples samples = first.await();
    start = Clock::now();
    if (settings_.guide_secondary) collect_borrowable(g, sampler);
    start_paths(g, &samples, sampler, at, vpls, StartPart::first_bounce);
    times.shade_ms += ms_since(start);
  } else {
    if (settings_.guide_secondary) collect_borrowable(g, sampler);
    start_paths(g, first.ready, sampler, at, vpls);
    times.shade_ms += ms_since(start);
    run_shadow_rays(rays, times);
  }
  start = Clock::now();
  apply_shadow_rays(true);
  times.compact_ms += ms_since(start);

  // What grouping changes most, the bounce loop's tracing and grouping (its shading, when the
  // sky's lookups make it most of the frame, would drown the difference in its noise), and the
  // rays traced, for order_choice_ (docs/host-path-tracer.md, "Bounce rays traced in groups").
  const double loop_trace_ms = times.trace_ms + times.group_ms;
  const std::uint64_t loop_rays = rays.secondary + rays.shadow;
  for (int depth = 1; depth <= settings_.max_bounces; ++depth) {
    std::size_t m = 0;
    for (const std::uint32_t count : ray_counts_) m += count;
    if (m == 0) break;
    if (group_this_pass_) {
      start = Clock::now();
      group_rays();
      times.group_ms += ms_since(start);
    }
    start = Clock::now();
    tracer_.intersect_lists(rays_.data(), hits_.data(), kPathBlock, ray_counts_.data(),
                            ray_counts_.size(), kBounceRayMode);
    times.trace_ms += ms_since(start);
    rays.secondary += m;

    start = Clock::now();
    shade_bounce(depth, vpls, rays);
    times.shade_ms += ms_since(start);
    run_shadow_rays(rays, times);
    start = Clock::now();
    apply_shadow_rays(false);
    times.compact_ms += ms_since(start);
  }
  if (timing_choice)
    order_choice_.record(group_this_pass_, times.trace_ms + times.group_ms - loop_trace_ms,
                         static_cast<double>(rays.secondary + rays.shadow - loop_rays));
  start = Clock::now();
  if (world_guide_) collect_world_samples();
  gather(radiance, vpls, nonfinite);
  times.compact_ms += ms_since(start);
}

void PathTracer::prepare(std::size_t n, VplBuffer* vpls) {
  paths_.resize(n);
  keep_vpls_ = vpls != nullptr;
  if (vpls) {
    vpls->resize(n);
    vpl_paths_.resize(n);
  }
  shadow_rays_.resize(n);
  shadow_contribution_.resize(n);
  shadow_path_.resize(n);
  occluded_.resize(n);
  shadow_counts_.resize((n + kPathBlock - 1) / kPathBlock);
  rays_.resize(n);
  hits_.resize(n);
  active_.resize(n);
  if (may_group_) {
    ray_groups_.resize(n);
    grouped_rays_.resize(n);
    grouped_active_.resize(n);
  }
  ray_counts_.resize((n + kPathBlock - 1) / kPathBlock);
  if (world_guide_) {
    // One record per path for each depth the guide covers (at most 254: world_depth_ counts them
    // in a byte beside kNotRecording).
    world_depths_ = std::min({settings_.max_bounces, world_guide_->settings().max_depth, 254});
    world_stride_ = static_cast<std::size_t>(std::max(1, world_depths_));
    world_vertices_.resize(n * world_stride_);
    world_depth_.resize(n);
    // The paths that record for training: one in record_every, chosen afresh every sample by
    // a hash of the pixel (the others still sample the guide).
    const std::uint32_t every = static_cast<std::uint32_t>(world_guide_->settings().record_every);
    const std::uint32_t salt = at_.frame * 0x9e3779b9u + at_.sample * 0x85ebca6bu + at_.seed;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 16384), [&](const auto& range) {
      for (std::size_t i = range.begin(); i != range.end(); ++i) {
        std::uint32_t h = static_cast<std::uint32_t>(i) ^ salt;
        h ^= h >> 16;
        h *= 0x7feb352du;
        h ^= h >> 15;
        h *= 0x846ca68bu;
        h ^= h >> 16;
        world_depth_[i] = every <= 1 || h % every == 0 ? 0 : kNotRecording;
      }
    });
  }
  next_event_on_ = settings_.next_event && !lights_.empty();
}

template <class CompetingPdf>
bool PathTracer::next_event(const glm::vec3& position, const glm::vec3& ng,
                            const shared::pg_frame& frame, const glm::vec3& wo,
                            const shared::pg_lobes& lobes, const glm::vec3& origin, float u_select,
                            float u1, float u2, const CompetingPdf& competing_pdf,
                            glm::vec3& contribution, Ray& shadow) const {
  LightSample ls;
  if (!lights_.sample(position, u_select, u1, u2, ls) || glm::dot(ls.direction, ng) <= 0.0f)
    return false;
  const glm::vec3 wi = shared::pg_to_local(frame, ls.direction);
  const glm::vec3 f = shared::pg_bsdf_eval(lobes, wo, wi) * std::max(wi.z, 0.0f);
  if (is_black(f)) return false;
  const float w = ls.delta ? 1.0f : power_heuristic(ls.pdf, competing_pdf(ls.direction, wi));
  contribution = f * ls.radiance * (w / ls.pdf);
  set_shadow_ray(shadow, origin, ls);
  return true;
}

shared::pg_rng PathTracer::second_vertex_stream(std::uint32_t i, shared::pg_rng& own) const {
  shared::pg_rng zero = shared::pg_rng_make(at_.seed, i, at_.frame, 0u, PG_RNG_STREAM_PATH);
  for (int k = 0; k < kNextEventDraws; ++k) shared::pg_rng_next(&zero);  // x0's light sample
  for (int k = 0; k < kNextEventDraws + kBounceDraws; ++k) shared::pg_rng_next(&own);
  return zero;
}

void PathTracer::start_paths(const GBuffer& g, const FirstBounceSamples* first,
                             const FirstBounceSampler& sampler, const SampleCoordinates& at,
                             VplBuffer* vpls, StartPart part) {
  const bool starts = part != StartPart::first_bounce;  // emission and next-event estimation
  const bool bounces = part != StartPart::next_event;   // the first bounce
  // A sampler of the BSDF has the BSDF's density already (its samples' own).
  const bool mis_with_bsdf =
      settings_.first_bounce_mis == FirstBounceMis::bsdf && !sampler.samples_the_bsdf();
  const SampleCoordinates first_at = first_bounce_coordinates(at, settings_.shared_randoms);
  const std::size_t n = g.pixel_count();
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, (n + kPathBlock - 1) / kPathBlock),
      [&](const auto& blocks) {
        // The pixels' path streams (and first-bounce streams where the BSDF's first bounce is
        // drawn here) started in vector lanes, a block at a time (render/stream_starts.h).
        std::uint32_t path_starts[kPathBlock], first_starts[kPathBlock];
        for (std::size_t block = blocks.begin(); block != blocks.end(); ++block) {
          const std::size_t chunk = block * kPathBlock;
          const std::size_t chunk_end = std::min(n, chunk + kPathBlock);
          // The block's shadow rays and the rays of its paths that go on, each listed from its
          // first slot (kPathBlock).
          std::uint32_t shadows = 0, survivors = 0;
          if (starts)
            make_stream_starts({at.seed, at.frame, at.sample, PG_RNG_STREAM_PATH}, chunk,
                               chunk_end - chunk, path_starts);
          if (bounces && !first)
            make_stream_starts(
                {first_at.seed, first_at.frame, first_at.sample, PG_RNG_STREAM_FIRST_BOUNCE}, chunk,
                chunk_end - chunk, first_starts);
          for (std::size_t i = chunk; i != chunk_end; ++i) {
            PathState& p = paths_[i];
            if (starts) {
              p.throughput = glm::vec3(0.0f);
              if (vpls) {
                // Measured from y (VplPath): x0's emission is the pixel's own.
                p.radiance = glm::vec3(0.0f);
                vpl_paths_[i] = VplPath{glm::vec3(0.0f), glm::vec3(g.emission[i]), 0.0f};
              } else {
                p.radiance = glm::vec3(g.emission[i]);
              }
            }
            if (!g.has_surface(i)) continue;
            const glm::vec3 x0(g.position_depth[i]);
            const glm::vec3 ng(g.geometric_normal[i]);
            const shared::pg_frame frame = gbuffer_frame(g, i);
            const glm::vec3 wo = shared::pg_to_local(frame, glm::vec3(g.view_dir[i]));
            const shared::pg_lobes lobes = shared::pg_make_lobes(gbuffer_material(g, i), wo);
            const glm::vec3 origin = offset_ray_origin(x0, ng, g.geometric_normal[i].w);

            if (starts) {
              shared::pg_rng rng;
              rng.state = path_starts[i - chunk];
              // Next-event estimation draws three numbers: the sample's own, or sample 0's where
              // the frame's samples share the primary vertex (SharedRandoms); either way the
              // sample's own stream moves past them, so that sample 0 draws as the renderer does.
              const bool shared_nee = settings_.shared_randoms == SharedRandoms::primary_vertex ||
                                      settings_.shared_randoms == SharedRandoms::second_vertex;
              shared::pg_rng nee_rng =
                  shared_nee ? shared::pg_rng_make(at.seed, static_cast<shared::uint>(i), at.frame,
                                                   0u, PG_RNG_STREAM_PATH)
                             : rng;
              const float u_sel = shared::pg_rng_next(&nee_rng), u1 = shared::pg_rng_next(&nee_rng),
                          u2 = shared::pg_rng_next(&nee_rng);
              if (shared_nee) {
                for (int k = 0; k < kNextEventDraws; ++k) shared::pg_rng_next(&rng);
              } else {
                rng = nee_rng;
              }
              // The first bounce's own sampler competes with the light here: the MIS weights use
              // its density (the guided mixture), or the BSDF's where first_bounce_mis says so.
              const auto first_bounce_pdf = [&](const glm::vec3&, const glm::vec3& wi) {
                return mis_with_bsdf ? bsdf_mis_density(shared::pg_bsdf_pdf(lobes, wo, wi))
                                     : sampler.pdf(g, i, lobes, wo, wi);
              };
              // next_event writes the shadow ray in place only where it returns true.
              glm::vec3 c;
              const std::size_t entry = chunk + shadows;
              if (next_event_on_ && next_event(x0, ng, frame, wo, lobes, origin, u_sel, u1, u2,
                                               first_bounce_pdf, c, shadow_rays_[entry])) {
                shadow_contribution_[entry] = c;
                shadow_path_[entry] = static_cast<std::uint32_t>(i);
                ++shadows;
              }
              // The first bounce draws nothing from this stream: the path goes on from here.
              p.rng = rng.state;
            }
            if (!bounces) continue;

            FirstBounceSample fs;
            if (first) {
              fs = first->at(i);
            } else {
              fs = bsdf_first_bounce_sample(frame, wo, lobes, first_starts[i - chunk]);
            }
            if (fs.pdf > 0.0f && glm::dot(fs.direction, ng) > 0.0f) {
              const glm::vec3 wi = shared::pg_to_local(frame, fs.direction);
              const glm::vec3 f = shared::pg_bsdf_eval(lobes, wo, wi) * std::max(wi.z, 0.0f);
              const glm::vec3 throughput = f / fs.pdf;
              const bool bsdf_strategy = fs.strategy == kStrategyBsdf;
              const float bsdf_pdf = (vpls && bsdf_strategy) || mis_with_bsdf
                                         ? shared::pg_bsdf_pdf(lobes, wo, wi)
                                         : 0.0f;
              if (vpls) {
                // The VPL keeps the density of the strategy that made it (BSDF samples are
                // distributed by the BSDF alone: paper 3.2) and the whole sampler's density D
                // (include/rtpg/guiding_layout.h). Area measure comes at y.
                vpls->strategy_pdf[i] = bsdf_strategy ? bsdf_pdf : fs.pdf;
                vpls->info[i] = fs.strategy << PG_VPL_STRATEGY_SHIFT;
                vpl_paths_[i].sampler_pdf = fs.pdf;
              }
              if (!is_black(throughput) && is_finite(throughput)) {
                if (vpls) {
                  vpl_paths_[i].first_throughput = throughput;
                  p.throughput = glm::vec3(1.0f);  // measured from y on (VplPath)
                } else {
                  p.throughput = throughput;
                }
                const std::size_t slot = chunk + survivors++;
                set_ray(rays_[slot], origin, fs.direction, 0.0f, 1e30f);
                active_[slot] = static_cast<std::uint32_t>(i);
                if (group_this_pass_) ray_groups_[slot] = ray_order_.group(origin, fs.direction);
                // The density the hit's MIS weight uses: the same function of the direction
                // as next-event estimation's above. Under first_bounce_mis_deferred_ the hit
                // asks the sampler's pdf() instead of this sample's density, which a device
                // may have computed from a G-buffer rounded for the bus (docs/guiding.md, "One
                // density for both weights at the primary hit").
                p.prev_pdf = mis_with_bsdf ? bsdf_mis_density(bsdf_pdf) : fs.pdf;
                p.prev_position = x0;
              }
            }
          }
          if (starts) shadow_counts_[block] = shadows;
          if (bounces) ray_counts_[block] = survivors;
        }
      });
}

void PathTracer::add_found_light(PathState& p, std::uint32_t i, int depth, const glm::vec3& found) {
  // With next-event estimation at x0 the light's own direction is NEE's job: the guide
  // learns only what arrives indirectly (y's emission stays out of the VPL, and the pixel
  // keeps it: VplPath), or the light with the MIS weight this sample got
  // (direct_light_in_vpls). found is then the emission itself (the path's throughput from y is
  // 1 at y).
  if (depth == 1 && keep_vpls_ && next_event_on_ && !settings_.direct_light_in_vpls) {
    vpl_paths_[i].before_y += vpl_paths_[i].first_throughput * found;
  } else {
    p.radiance += found;
  }
}

float PathTracer::first_bounce_mis_density(std::size_t i, const glm::vec3& direction) const {
  const GBuffer& g = *gbuffer_;
  const shared::pg_frame frame = gbuffer_frame(g, i);
  const glm::vec3 wo = shared::pg_to_local(frame, glm::vec3(g.view_dir[i]));
  const shared::pg_lobes lobes = shared::pg_make_lobes(gbuffer_material(g, i), wo);
  return sampler_->pdf(g, i, lobes, wo, shared::pg_to_local(frame, direction));
}

void PathTracer::shade_bounce(int depth, VplBuffer* vpls, RayCounts& rays) {
  const bool nee = next_event_on_;
  // The options that add work at a vertex beyond the first bounce's hit: guiding it (borrowed
  // pixel mixtures or the world guide's cells), recording it for the world guide (at every
  // depth: the vertex after the last recorded one completes that record), the second vertex's
  // shared random numbers. All off by default; the loop is compiled twice, and without them it
  // holds none of their code (docs/host-path-tracer.md, "What a scene does not use, skipped").
  const bool extras_on = settings_.guide_secondary || world_guide_ != nullptr ||
                         (depth == 1 && settings_.shared_randoms == SharedRandoms::second_vertex);
  std::atomic<std::uint64_t> guided_vertices{0};
  // extras: std::true_type or std::false_type, whether extras_on.
  const auto shade_range = [&](auto extras, const auto& range) __attribute__((flatten)) {
    constexpr bool kExtras = decltype(extras)::value;
    const bool guide_secondary = kExtras && settings_.guide_secondary;
    // The world guide's vertices at this depth: sampled from it, and recorded to train it.
    const bool world_here = kExtras && world_guide_ && depth <= world_depths_;
    std::uint64_t guided_here = 0;
    // The block's shadow rays and the next rays of its paths that go on, each listed from its
    // first slot (kPathBlock): the latter in place, at or before the slot being shaded, whose
    // ray and path were read first.
    std::uint32_t shadows = 0, survivors = 0;
    // The pixel each of the next vertices projects to, found once where its entry is
    // prefetched.
    std::size_t borrow_from[kBorrowRing];
    if (guide_secondary) {
      for (std::size_t j = range.begin(); j < std::min(range.end(), range.begin() + kPrefetchAhead);
           ++j)
        borrow_from[j % kBorrowRing] = prefetch_borrowable(j);
    }
    for (std::size_t j = range.begin(); j != range.end(); ++j) {
      if (guide_secondary && j + kPrefetchAhead < range.end())
        borrow_from[(j + kPrefetchAhead) % kBorrowRing] = prefetch_borrowable(j + kPrefetchAhead);
      if (j + kPathPrefetchAhead < range.end()) {
        const std::uint32_t ahead = active_[j + kPathPrefetchAhead];
        prefetch_path(ahead);
        // In groups the first bounce's hits write their pixels' VPLs all over the buffer.
        if (depth == 1 && vpls && group_this_pass_) prefetch_vpl(*vpls, ahead);
      }
      if (world_here && j + kPrefetchAhead < range.end() && hits_[j + kPrefetchAhead].valid()) {
        const Ray& ahead = rays_[j + kPrefetchAhead];
        world_guide_->prefetch(ahead.origin + ahead.direction * hits_[j + kPrefetchAhead].t);
      }
      if (prefetch_surfaces_)
        prefetch_surfaces_ahead(scene_, triangles_, hits_.data(), j, range.end());
      const std::uint32_t i = active_[j];
      PathState& p = paths_[i];
      // The previous vertex's light sample is in the path's radiance now (the compaction added
      // it); what comes after is the light its bounce found.
      if (kExtras && world_guide_ && depth >= 2 && world_depth_[i] == depth - 1)
        world_vertices_[i * world_stride_ + (depth - 2)].radiance_before = p.radiance;
      const Ray ray = rays_[j];
      const Hit& hit = hits_[j];
      const glm::vec3 dir = glm::normalize(ray.direction);
      // The density the light found here weighs itself with against a light sample.
      const auto arriving_pdf = [&] {
        return depth == 1 && first_bounce_mis_deferred_ ? first_bounce_mis_density(i, dir)
                                                        : p.prev_pdf;
      };
      if (!hit.valid()) {
        const glm::vec3 le = lights_.escaped_radiance(dir);
        const float light_pdf = nee ? lights_.pdf_escaped(dir) : 0.0f;
        const float w = light_pdf > 0.0f ? power_heuristic(arriving_pdf(), light_pdf) : 1.0f;
        add_found_light(p, i, depth, p.throughput * le * w);
        if (depth == 1) {
          if (vpls) {
            const float strategy_pdf = vpls->strategy_pdf[i];
            vpls->position[i] = glm::vec4(dir, strategy_pdf);
            vpls->normal_radiance[i].x = shared::pg_pack_vpl_normal(glm::vec3(0.0f));
            vpls->normal_radiance[i].y = shared::pg_pack_vpl_density(vpl_paths_[i].sampler_pdf);
            if (usable_vpl_density(strategy_pdf)) vpls->info[i] |= PG_VPL_VALID | PG_VPL_DISTANT;
            if (vpls->for_bus) {
              vpls->packed.distance[i] = 0x7f800000u;  // +infinity: escaped
              vpls->packed.normal[i] = 0u;
            }
          }
        }
        continue;
      }
      const SurfacePoint sp = make_surface_point(scene_, triangles_, ray, hit);
      if (!is_black(sp.emission)) {
        const float light_pdf = nee ? lights_.pdf_triangle(hit.mesh, hit.triangle, p.prev_position,
                                                           sp.position, sp.geometric_normal)
                                    : 0.0f;
        const float w = light_pdf > 0.0f ? power_heuristic(arriving_pdf(), light_pdf) : 1.0f;
        add_found_light(p, i, depth, p.throughput * sp.emission * w);
      }
      if (depth == 1 && vpls) {
        // Density in area measure at y: solid angle at x0 times cos(theta_y) / d^2.
        const glm::vec3 to = sp.position - p.prev_position;
        const float d2 = glm::dot(to, to);
        const float cos_y = std::fabs(glm::dot(sp.geometric_normal, dir));
        const float strategy_pdf = vpls->strategy_pdf[i] * cos_y / d2;
        vpls->position[i] = glm::vec4(sp.position, strategy_pdf);
        vpls->normal_radiance[i].x = shared::pg_pack_vpl_normal(sp.geometric_normal);
        vpls->normal_radiance[i].y =
            shared::pg_pack_vpl_density(vpl_paths_[i].sampler_pdf * cos_y / d2);
        if (usable_vpl_density(strategy_pdf)) vpls->info[i] |= PG_VPL_VALID;
        if (vpls->for_bus) {
          vpls->packed.distance[i] = shared::as_uint(std::sqrt(d2));
          vpls->packed.normal[i] =
              static_cast<std::uint16_t>(shared::pg_pack_unit_vector8(sp.geometric_normal));
        }
      }
      if (depth == settings_.max_bounces) continue;

      // The vertex's stream: the path's own, or at y sample 0's where the frame's samples share
      // it (SharedRandoms; `own` then moves past the numbers y draws).
      shared::pg_rng own;
      own.state = p.rng;
      const bool shared_y =
          kExtras && depth == 1 && settings_.shared_randoms == SharedRandoms::second_vertex;
      shared::pg_rng rng = shared_y ? second_vertex_stream(i, own) : own;
      const shared::pg_frame frame = shared::pg_frame_from_normal(sp.shading_normal);
      const glm::vec3 wo = shared::pg_to_local(frame, -dir);
      const shared::pg_lobes lobes = shared::pg_make_lobes(sp.material, wo);
      const glm::vec3 origin =
          offset_ray_origin(sp.position, sp.geometric_normal, sp.offset_distance);

      const float u_sel = shared::pg_rng_next(&rng), u1 = shared::pg_rng_next(&rng),
                  u2 = shared::pg_rng_next(&rng);
      // Read only where `guided` (borrow_guide or the world guide filled it); zeroed, since the
      // link-time analysis cannot see that through the two calls.
      PixelGuide guide{};
      // A borrowed lobe is the lending pixel's product of incident light and its BSDF for its
      // own view direction: it carries over to a vertex whose reflection is mostly diffuse
      // (view-independent), not to a glossy one seen from elsewhere. The world guide's cells
      // learn from many view directions, so the same holds for them.
      const bool diffuse_enough = lobes.p_specular <= 0.5f;
      const std::uint64_t cell = world_here && diffuse_enough
                                     ? world_guide_->cell_of(sp.position, sp.shading_normal)
                                     : WorldGuide::kNoCell;
      const bool guided = (guide_secondary && diffuse_enough &&
                           borrow_guide(borrow_from[j % kBorrowRing], sp, guide)) ||
                          (cell != WorldGuide::kNoCell && world_guide_->guide(cell, guide));
      guided_here += guided;
      // Beyond the first bounce the vertex's sampler competes with the light. The density
      // they weigh each other with: the BSDF's, or at a guided vertex the borrowed guide's
      // mixture, unless first_bounce_mis says the BSDF's there too (as at the primary hit:
      // the same function of the direction on both sides, so the weights still sum to one;
      // docs/guiding.md, "Later vertices weighed by the BSDF's density").
      const bool mis_with_bsdf = guided && settings_.first_bounce_mis == FirstBounceMis::bsdf;
      const auto vertex_pdf = [&](const glm::vec3& w, const glm::vec3& wi) {
        const float bsdf = shared::pg_bsdf_pdf(lobes, wo, wi);
        if (!guided) return bsdf;
        return mis_with_bsdf ? bsdf_mis_density(bsdf) : guide_density(guide, w, bsdf);
      };
      glm::vec3 c;
      const std::size_t entry = range.begin() + shadows;
      if (nee && next_event(sp.position, sp.geometric_normal, frame, wo, lobes, origin, u_sel, u1,
                            u2, vertex_pdf, c, shadow_rays_[entry])) {
        shadow_contribution_[entry] = p.throughput * c;
        shadow_path_[entry] = i;
        ++shadows;
      }

      const float u_lobe = shared::pg_rng_next(&rng), v1 = shared::pg_rng_next(&rng),
                  v2 = shared::pg_rng_next(&rng), u_rr = shared::pg_rng_next(&rng);
      p.rng = shared_y ? own.state : rng.state;
      shared::pg_bsdf_sample_t bs;
      glm::vec3 wi_world;
      float mis_pdf = 0.0f;  // the density the hit's MIS weight uses (vertex_pdf's function)
      // The bounce in the guide's square (the world cell's, where a world cell guides), kept for
      // the cell's training sample; and the BSDF's density there.
      shared::float2 square(0.0f, 0.0f);
      bool in_square = false;
      float bsdf_pdf = 0.0f;
      if (!guided) {
        bs = shared::pg_bsdf_sample(lobes, wo, u_lobe, v1, v2);
        if (bs.pdf <= 0.0f) continue;
        wi_world = shared::pg_to_world(frame, bs.wi);
        bsdf_pdf = bs.pdf;
      } else {
        // One-sample MIS over the borrowed mixture, as the sample kernel does (pmm.h): the
        // Gaussian with probability pi (in the lending pixel's square and frame), else the
        // BSDF; the weight uses the whole mixture's density.
        const float pi = guide.model.pi;
        if (u_lobe < pi) {
          int inside = 0;
          square = shared::pg_pmm_sample_square(guide.model, v1, v2, &inside);
          if (!inside) continue;
          in_square = true;
          wi_world = shared::pg_to_world(guide.frame, shared::pg_square_to_hemisphere(square));
          bs.wi = shared::pg_to_local(frame, wi_world);
        } else {
          const float u = std::min((u_lobe - pi) / (1.0f - pi), 0.99999994f);
          bs = shared::pg_bsdf_sample(lobes, wo, u, v1, v2);
          if (bs.pdf <= 0.0f) continue;
          wi_world = shared::pg_to_world(frame, bs.wi);
        }
        if (bs.wi.z <= 0.0f) continue;
        bsdf_pdf = shared::pg_bsdf_pdf(lobes, wo, bs.wi);
        // guide_density, with the square point the Gaussian drew where it drew one.
        if (!in_square) {
          const glm::vec3 l = shared::pg_to_local(guide.frame, wi_world);
          in_square = l.z > 0.0f;
          if (in_square) square = shared::pg_hemisphere_to_square(l);
        }
        bs.pdf = guide_density_at(guide, in_square, square, bsdf_pdf);
        if (!(bs.pdf > 0.0f)) continue;
        if (mis_with_bsdf) mis_pdf = bsdf_mis_density(bsdf_pdf);
      }
      if (glm::dot(wi_world, sp.geometric_normal) <= 0.0f) continue;
      const glm::vec3 weight = shared::pg_bsdf_eval(lobes, wo, bs.wi) * (bs.wi.z / bs.pdf);
      const glm::vec3 throughput_before = p.throughput;
      p.throughput *= weight;
      // Russian roulette and the end of a black path look at the throughput from the camera
      // (measured from y where VPLs are kept: VplPath; times 1, exact, where not).
      const glm::vec3 to_y = vpls ? vpl_paths_[i].first_throughput : glm::vec3(1.0f);
      if (depth >= settings_.roulette_start) {
        const glm::vec3 t = to_y * p.throughput;
        const float q = std::min(0.95f, std::max(t.x, std::max(t.y, t.z)));
        if (!(u_rr < q)) continue;
        p.throughput /= q;
      }
      const glm::vec3 from_camera = to_y * p.throughput;
      if (is_black(from_camera) || !is_finite(from_camera)) continue;
      p.prev_pdf = mis_with_bsdf ? mis_pdf : bs.pdf;
      p.prev_position = sp.position;
      const std::size_t slot = range.begin() + survivors++;
      set_ray(rays_[slot], origin, wi_world, 0.0f, 1e30f);
      active_[slot] = i;
      if (group_this_pass_) ray_groups_[slot] = ray_order_.group(origin, wi_world);
      if (world_here && world_depth_[i] != kNotRecording) {
        WorldVertex& v = world_vertices_[i * world_stride_ + (depth - 1)];
        v.cell = WorldGuide::kNoCell;
        if (cell != WorldGuide::kNoCell) {
          // A guided vertex has its bounce in the cell's square already (the cell guided it).
          if (!guided) {
            const glm::vec3 l = shared::pg_to_local(WorldGuide::cell_frame(cell), wi_world);
            in_square = l.z > 0.0f;
            if (in_square) square = shared::pg_hemisphere_to_square(l);
          }
          if (in_square) {
            v.cell = cell;
            v.ux = square.x;
            v.uy = square.y;
            v.bsdf_pdf = bsdf_pdf;
            v.density = bs.pdf;
            v.throughput = throughput_before;
          }
        }
        world_depth_[i] = static_cast<std::uint8_t>(depth);
      }
    }
    guided_vertices += guided_here;
    shadow_counts_[range.begin() / kPathBlock] = shadows;
    ray_counts_[range.begin() / kPathBlock] = survivors;
  };
  // Block by block: each block's live paths, listed from its first slot.
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, ray_counts_.size()),
                    [&](const auto& blocks) {
                      for (std::size_t b = blocks.begin(); b != blocks.end(); ++b) {
                        const tbb::blocked_range<std::size_t> range(
                            b * kPathBlock, b * kPathBlock + ray_counts_[b]);
                        if (extras_on)
                          shade_range(std::true_type{}, range);
                        else
                          shade_range(std::false_type{}, range);
                      }
                    });
  rays.guided_vertices += guided_vertices.load();
}

void PathTracer::collect_borrowable(const GBuffer& g, const FirstBounceSampler& sampler) {
  borrowable_.resize(g.pixel_count());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, g.pixel_count(), kGrain),
                    [&](const auto& range) {
                      for (std::size_t i = range.begin(); i != range.end(); ++i) {
                        BorrowablePixel& b = borrowable_[i];
                        PixelGuide guide;
                        if (!g.has_surface(i) || !sampler.pixel_guide(g, i, guide)) {
                          b.position_depth = shared::float4(0.0f, 0.0f, 0.0f, 0.0f);
                          continue;
                        }
                        b.position_depth = g.position_depth[i];
                        b.normal = shared::pg_float4_xyz(g.shading_normal[i]);
                        b.material = g.material[i];
                        b.model = guide.model;
                      }
                    });
}

std::size_t PathTracer::borrowable_index(const glm::vec3& position) const {
  const GBuffer& g = *gbuffer_;
  float sx = 0.0f, sy = 0.0f;
  if (!g.camera.project(position, sx, sy)) return kNotOnScreen;
  const float fx = std::floor(sx * static_cast<float>(g.width));
  const float fy = std::floor(sy * static_cast<float>(g.height));
  if (!(fx >= 0.0f && fy >= 0.0f && fx < static_cast<float>(g.width) &&
        fy < static_cast<float>(g.height)))
    return kNotOnScreen;
  return static_cast<std::size_t>(fy) * static_cast<std::size_t>(g.width) +
         static_cast<std::size_t>(fx);
}

void PathTracer::group_rays() {
  // Each ray and its pixel moved where the order puts it (RayOrder::arrange): the lists are read
  // in slot order, and each group's places are written in turn.
  const std::size_t count =
      ray_order_.arrange(ray_groups_.data(), kPathBlock, ray_counts_.data(), ray_counts_.size(),
                         [&](std::size_t slot, std::size_t place) {
                           grouped_rays_[place] = rays_[slot];
                           grouped_active_[place] = active_[slot];
                         });
  rays_.swap(grouped_rays_);
  active_.swap(grouped_active_);
  for (std::size_t b = 0; b != ray_counts_.size(); ++b) {
    const std::size_t first = b * kPathBlock;
    ray_counts_[b] =
        static_cast<std::uint32_t>(first < count ? std::min(kPathBlock, count - first) : 0);
  }
}

void PathTracer::prefetch_vpl(const VplBuffer& vpls, std::uint32_t i) {
  __builtin_prefetch(&vpls.position[i], 1);
  __builtin_prefetch(&vpls.normal_radiance[i], 1);
  __builtin_prefetch(&vpls.info[i], 1);
  __builtin_prefetch(&vpls.strategy_pdf[i]);
}

void PathTracer::prefetch_path(std::uint32_t i) const {
  // A PathState may straddle two cache lines (44 bytes at any offset).
  const char* p = reinterpret_cast<const char*>(&paths_[i]);
  __builtin_prefetch(p);
  __builtin_prefetch(p + sizeof(PathState) - 1);
  if (keep_vpls_) __builtin_prefetch(&vpl_paths_[i]);
}

std::size_t PathTracer::prefetch_borrowable(std::size_t j) const {
  const Hit& hit = hits_[j];
  if (!hit.valid()) return kNotOnScreen;
  const Ray& ray = rays_[j];
  const std::size_t i = borrowable_index(ray.origin + ray.direction * hit.t);
  if (i != kNotOnScreen) __builtin_prefetch(&borrowable_[i]);
  return i;
}

bool PathTracer::borrow_guide(std::size_t i, const SurfacePoint& sp, PixelGuide& guide) const {
  if (i == kNotOnScreen) return false;
  const BorrowablePixel& b = borrowable_[i];
  const GBuffer& g = *gbuffer_;
  const float depth = glm::dot(sp.position - g.camera.position, g.camera.forward);
  const shared::float4 here(sp.position.x, sp.position.y, sp.position.z, depth);
  // The pixel must show this very surface (an occluder in front fails the position test)
  // and lend a guide (position_depth.w > 0).
  if (!shared::pg_same_surface(b.position_depth, b.normal, b.material, here, sp.shading_normal,
                               sp.material_id, settings_.guide_position, settings_.guide_normal))
    return false;
  guide.model = b.model;
  guide.frame = shared::pg_frame_from_normal(b.normal);
  return true;
}

void PathTracer::run_shadow_rays(RayCounts& rays, PassTimes& times) {
  const auto start = Clock::now();
  rays.shadow +=
      tracer_.occluded_lists(shadow_rays_.data(), occluded_.data(), kPathBlock,
                             shadow_counts_.data(), shadow_counts_.size(), kShadowRayMode);
  times.trace_ms += ms_since(start);
}

void PathTracer::apply_shadow_rays(bool at_x0) {
  // Each unoccluded shadow ray of a block's list adds its contribution to its path (a path has
  // one slot and so at most one entry: no two iterations touch one PathState). At x0 a path kept
  // from y (VplPath) adds it to what the pixel found before y (docs/host-path-tracer.md, "One
  // pass after each vertex", "Shadow rays listed where they are made").
  const bool to_before_y = keep_vpls_ && at_x0;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, shadow_counts_.size()),
                    [&](const auto& range) {
                      for (std::size_t b = range.begin(); b != range.end(); ++b) {
                        const std::size_t first = b * kPathBlock, end = first + shadow_counts_[b];
                        for (std::size_t e = first; e != end; ++e) {
                          if (occluded_[e]) continue;
                          if (to_before_y) {
                            vpl_paths_[shadow_path_[e]].before_y += shadow_contribution_[e];
                          } else {
                            paths_[shadow_path_[e]].radiance += shadow_contribution_[e];
                          }
                        }
                      }
                    });
}

void PathTracer::collect_world_samples() {
  const std::size_t n = paths_.size();
  const std::size_t stride = world_stride_;
  // Fixed blocks of paths, each into its own vector: the samples' order is the paths' whatever
  // the thread count (WorldGuide::train sums each cell's samples in that order).
  constexpr std::size_t kWorldBlock = 8192;
  const std::size_t blocks = (n + kWorldBlock - 1) / kWorldBlock;
  const std::size_t first = world_blocks_used_;
  world_blocks_used_ += blocks;
  if (world_blocks_.size() < world_blocks_used_) world_blocks_.resize(world_blocks_used_);
  tbb::parallel_for(std::size_t{0}, blocks, [&](std::size_t b) {
    std::vector<WorldTrainingSample>& out = world_blocks_[first + b];
    out.clear();
    const std::size_t end = std::min(n, (b + 1) * kWorldBlock);
    for (std::size_t i = b * kWorldBlock; i != end; ++i) {
      // The records were written over the whole frame and left the cache: load them ahead.
      constexpr std::size_t kAhead = 16;
      if (i + kAhead < end) {
        const int ahead = world_depth_[i + kAhead] == kNotRecording ? 0 : world_depth_[i + kAhead];
        const char* r = reinterpret_cast<const char*>(&world_vertices_[(i + kAhead) * stride]);
        for (int line = 0; line < (ahead * static_cast<int>(sizeof(WorldVertex)) + 63) / 64; ++line)
          __builtin_prefetch(r + 64 * line);
        __builtin_prefetch(&paths_[i + kAhead]);
      }
      const int count = world_depth_[i];
      if (count == 0 || count == kNotRecording) continue;
      const glm::vec3 total = paths_[i].radiance;
      for (int d = 0; d < count; ++d) {
        const WorldVertex& v = world_vertices_[i * stride + static_cast<std::size_t>(d)];
        if (v.cell == WorldGuide::kNoCell) continue;
        // A path recorded at its last vertex before max_bounces reached the next one (the
        // compaction keeps every path that sampled a bounce), so radiance_before is set.
        const glm::vec3 after = total - v.radiance_before;
        glm::vec3 l(0.0f);
        for (int c = 0; c < 3; ++c)
          if (v.throughput[c] > 0.0f) l[c] = after[c] / v.throughput[c];
        const float a = 0.2126f * l.x + 0.7152f * l.y + 0.0722f * l.z;
        if (!(a >= 0.0f) || !std::isfinite(a)) continue;
        out.push_back({v.cell, a, v.ux, v.uy, v.bsdf_pdf, v.density});
      }
    }
  });
}

void PathTracer::gather(std::vector<glm::vec3>& radiance, VplBuffer* vpls,
                        std::uint64_t& nonfinite) const {
  const std::size_t n = paths_.size();
  radiance.resize(n);
  nonfinite += tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, n, kGrain), std::uint64_t{0},
      [&](const auto& range, std::uint64_t bad) {
        for (std::size_t i = range.begin(); i != range.end(); ++i) {
          const PathState& p = paths_[i];
          // Where VPLs are kept the path measured from y (VplPath): its radiance is the VPL's,
          // and the pixel's estimate adds what x0 found.
          const glm::vec3 estimate =
              vpls ? vpl_paths_[i].before_y + vpl_paths_[i].first_throughput * p.radiance
                   : p.radiance;
          if (is_finite(estimate)) {
            radiance[i] = estimate;
          } else {
            radiance[i] = glm::vec3(0.0f);
            ++bad;
          }
          if (vpls) {
            const glm::vec3 vpl_l = p.radiance;
            if (!is_finite(vpl_l)) vpls->info[i] &= ~PG_VPL_VALID;
            // The kernels read the info bits from the packed channel's w.
            const glm::vec3 l = is_finite(vpl_l) ? vpl_l : glm::vec3(0.0f);
            vpls->normal_radiance[i].z = shared::pg_pack_vpl_radiance_rg(l);
            vpls->normal_radiance[i].w = shared::pg_pack_vpl_radiance_b_info(l, vpls->info[i]);
            if (vpls->for_bus) {
              // The VPL as it crosses the bus (include/rtpg/guiding_layout.h, "Packed VPLs"):
              // the distance and normal written at the hit, where there was one.
              vpls->packed.radiance[i] = shared::pg_pack_rgbe(l);
              if ((vpls->info[i] & PG_VPL_VALID) == 0u) vpls->packed.distance[i] = 0u;
            }
          }
        }
        return bad;
      },
      std::plus<std::uint64_t>());
}

}  // namespace rtpg
