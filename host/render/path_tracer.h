// The host path tracer, wavefront style: every stage handles all live paths of a frame in one
// batch (Embree queries and shading spread over all cores with TBB). Next-event estimation
// for area lights, the sun and the environment is combined with BSDF sampling by MIS (power
// heuristic); Russian roulette ends paths. The first bounce comes from a FirstBounceSampler.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include <glm/glm.hpp>

#include "render/first_bounce.h"
#include "render/gbuffer.h"
#include "render/lights.h"
#include "render/surface.h"
#include "render/vpl_buffer.h"
#include "render/world_guide.h"
#include "scene/scene.h"
#include "shared/rng.h"
#include "trace/embree_scene.h"
#include "trace/ray_order.h"
#include "util/timed_choice.h"
#include "util/huge_pages.h"

namespace rtpg {

struct SurfacePoint;

// Which random numbers every sample of a frame takes from sample 0 instead of its own stream: a
// diagnostic that splits a pixel's variance by where it arises (bench/variance_split.py,
// docs/guiding.md, "Where the variance is"). Each sample stays an unbiased estimate; the frame's
// samples are then correlated, so --spp averages only what comes after the shared part.
enum class SharedRandoms {
  none,            // every sample its own (the renderer)
  first_bounce,    // the first bounce's direction (BSDF or guided) is sample 0's
  primary_vertex,  // and so is the next-event estimate at the primary hit
  second_vertex,   // and so are the first bounce's hit y's light sample and bounce (with its
                   // Russian roulette draw)
};

// The density the primary hit's two strategies for direct light weigh each other with (the light
// sample of next-event estimation, and the first bounce's hit on an emitter). Both sides use the
// same function of the direction, so the weights sum to one and either choice is unbiased (Veach's
// MIS needs a partition of unity, not the sampling densities); they differ in variance and cost
// (docs/guiding.md, "The primary hit's MIS with the BSDF's density").
enum class FirstBounceMis {
  mixture,  // the first-bounce sampler's own density (the guided mixture D of paper eq. 2)
  bsdf,     // the BSDF's density (D where that is 0): no mixture evaluated for the light sample
};

// grouped: before each bounce's trace the paths that go on are put in RayOrder's groups (by the
// direction's octant and the origin's cell: trace/ray_order.h), so that Embree's streams walk
// the BVH coherently; listed: as the blocks list them; automatic: listed where the scene's BVH
// fits in a core's cache, else whichever of the two the first passes time faster
// (TimedChoice), as the gain depends on how much of the BVH the paths walk
// (docs/host-path-tracer.md, "Bounce rays traced in groups").
enum class BounceRayOrder { automatic, grouped, listed };
// Whether `setting` may group the scene's bounce rays (automatic: its BVH outgrows a core's
// cache).
bool may_group_bounce_rays(BounceRayOrder setting, const Scene& scene);

struct PathTracerSettings {
  int max_bounces = 8;     // path vertices after the primary hit
  int roulette_start = 3;  // first bounce at which Russian roulette may end a path
  bool next_event = true;  // false: BSDF sampling only (emitters found by chance)
  // Guiding beyond the first bounce (docs/guiding.md): a later vertex that the camera sees
  // in some pixel (the same surface by the tests of reprojection, these thresholds) samples
  // that pixel's guiding mixture instead of its BSDF alone.
  bool guide_secondary = false;
  // What the first-bounce VPLs learn of the light that y emits towards x0 when next-event
  // estimation is on (docs/guiding.md, "Direct light in the training target"): false leaves it
  // out (NEE samples the lights at x0); true adds it with the MIS weight the BSDF-side sample
  // received, so that directions where light sampling does worse than the mixture are learnt
  // (Sponza's sun and sky: relMSE -2% to -3% on every seed, no scene worse).
  bool direct_light_in_vpls = true;
  FirstBounceMis first_bounce_mis = FirstBounceMis::bsdf;
  float guide_position = 0.05f;  // relative distance to the pixel's depth
  float guide_normal = 0.9f;     // normal cosine
  SharedRandoms shared_randoms = SharedRandoms::none;
  // Whether the shading loop and the G-buffer load each hit's triangle, vertices and texels a
  // few hits ahead (render/surface.h, loads_surfaces_ahead). Images are the same either way.
  SurfacePrefetch surface_prefetch = SurfacePrefetch::automatic;
  // The order each bounce's rays go to Embree in (BounceRayOrder). Images are the same
  // either way.
  BounceRayOrder bounce_ray_order = BounceRayOrder::automatic;
};

// The coordinates a sample's first bounce draws with: sample 0's where the first bounce is
// shared by the frame's samples (SharedRandoms).
inline SampleCoordinates first_bounce_coordinates(const SampleCoordinates& at, SharedRandoms s) {
  SampleCoordinates first = at;
  if (s != SharedRandoms::none) first.sample = 0;
  return first;
}

// How a frame's rays go to Embree (host/trace/ray.h): camera rays in packets of 4x4 or 4x2
// pixels (EmbreeScene::intersect_image; docs/host-path-tracer.md, "Camera rays in vector
// lanes"); bounce and shadow rays in streams, 1.1-1.2x and 1.7-1.8x as fast as one by one
// (2026-11-26, AVX-512) (docs/host-path-tracer.md, "Embree's stream API"). bench_frame times
// Embree alone the same way.
inline constexpr RayMode kBounceRayMode = RayMode::Stream;
inline constexpr RayMode kShadowRayMode = RayMode::Stream;

struct RayCounts {
  std::uint64_t secondary = 0, shadow = 0;
  std::uint64_t guided_vertices = 0;  // later vertices that sampled a borrowed guide
};

struct PassTimes {
  double trace_ms = 0.0, shade_ms = 0.0;
  double group_ms = 0.0;  // the bounce rays put in groups (BounceRayOrder)
  // Between the passes: shadow rays' results added to their paths, and the pixel estimates and
  // VPL radiance gathered at the end (the name stays from when it also compacted the live
  // paths, which the shading now lists in place).
  double compact_ms = 0.0;
};

class PathTracer {
 public:
  PathTracer(const Scene& scene, const EmbreeScene& tracer, const TriangleTable& triangles,
             const Lights& lights, PathTracerSettings settings);

  // Where a pass's first-bounce directions come from: `ready` (from the sampler's sample()), or
  // `await`, called once after the primary hit's next-event estimation and its shadow rays,
  // which returns them (a sampler that samples_beside_the_host(): its finish_sample()); neither:
  // bsdf_first_bounce_sample() drawn at the primary hit (a sampler that samples_the_bsdf()).
  struct FirstBounceSource {
    const FirstBounceSamples* ready = nullptr;
    std::function<FirstBounceSamples()> await;
  };
  // One path per surface pixel of the G-buffer, starting with the directions of `first` (from
  // `sampler`).
  // radiance[i] receives the estimate of pixel i (primary emission included); a non-finite
  // estimate is replaced by zero and counted. vpls (optional) receives the first-bounce hits.
  void trace(const GBuffer& gbuffer, const FirstBounceSource& first,
             const FirstBounceSampler& sampler, const SampleCoordinates& at,
             std::vector<glm::vec3>& radiance, VplBuffer* vpls, std::uint64_t& nonfinite,
             RayCounts& rays, PassTimes& times);

  const PathTracerSettings& settings() const { return settings_; }
  // settings().surface_prefetch resolved for the scene (render/surface.h, loads_surfaces_ahead):
  // the G-buffer pass follows the same decision.
  bool loads_surfaces_ahead() const { return prefetch_surfaces_; }
  // Whether the last trace() grouped its bounce rays (settings().bounce_ray_order).
  bool grouped_rays() const { return group_this_pass_; }
  // Later vertices sample the world-space guide's cells and record their bounces for it
  // (render/world_guide.h); null: neither. The caller trains the guide between frames.
  void set_world_guide(const WorldGuide* guide) { world_guide_ = guide; }
  // The world guide's training samples of the traces since clear_world_samples(), in blocks
  // of a fixed order (WorldGuide::train).
  const std::vector<std::vector<WorldTrainingSample>>& world_samples() const {
    return world_blocks_;
  }
  void clear_world_samples() {
    for (auto& block : world_blocks_) block.clear();
    world_blocks_used_ = 0;
  }

 private:
  // What every path carries from vertex to vertex (44 bytes: a path touches one cache line).
  struct PathState {
    glm::vec3 throughput;     // from the camera (from y where VPLs are kept: VplPath)
    glm::vec3 radiance;       // accumulated pixel estimate (the VPL's radiance: VplPath)
    float prev_pdf;           // density of the direction that led here (for MIS)
    glm::vec3 prev_position;  // origin of the current ray
    std::uint32_t rng;        // pg_rng state
  };
  // Where a pass keeps VPLs (trace() with vpls), a path's PathState measures from the
  // first-bounce hit y instead of from the camera: its throughput is y's onwards (1 at y) and
  // its radiance is what leaves y towards x0, the VPL's radiance, so no second set of sums
  // follows the path. What the pixel needs besides is kept per pixel, written at x0 and read
  // at the end (docs/host-path-tracer.md, "The VPL's radiance as the path's own"): the pixel's
  // estimate is before_y + first_throughput * radiance.
  struct VplPath {
    glm::vec3 first_throughput;  // from the camera through x0's bounce: f cos / D at x0
    glm::vec3 before_y;  // the pixel's own before y: x0's emission and light sample (and y's
                         // emission where the VPLs leave it out)
    float sampler_pdf;   // the first-bounce sampler's density D of the direction x0 -> y
  };

  // The steps of trace(), in order.
  void prepare(std::size_t n, VplBuffer* vpls);
  // At the primary hit x0 of every pixel: emission, next-event estimation, the first bounce
  // (null `first`: the BSDF's, drawn here), in one pass over the pixels or in two (`part`): the
  // second pass reads what the first left in each path (its stream past the light sample).
  enum class StartPart { whole, next_event, first_bounce };
  void start_paths(const GBuffer& g, const FirstBounceSamples* first,
                   const FirstBounceSampler& sampler, const SampleCoordinates& at, VplBuffer* vpls,
                   StartPart part = StartPart::whole);
  // The hits of the live paths at path vertex `depth` (the blocks' lists): emission found by
  // the bounce (MIS), the VPL at depth 1, next-event estimation, BSDF sampling and Russian
  // roulette; the paths that go on are listed again, with their next rays.
  void shade_bounce(int depth, VplBuffer* vpls, RayCounts& rays);
  // The sampler's pdf() at pixel i for world direction `direction` (first_bounce_mis_deferred_).
  float first_bounce_mis_density(std::size_t i, const glm::vec3& direction) const;
  // The random numbers of path i's vertex y (the first bounce's hit) where the frame's samples
  // share it (SharedRandoms::second_vertex): sample 0's stream there; `own` then continues
  // past y as if it had drawn them.
  shared::pg_rng second_vertex_stream(std::uint32_t i, shared::pg_rng& own) const;
  // Next-event estimation at a surface point, once for every vertex: samples a light and,
  // where the BSDF sees it, returns true with the contribution an unoccluded shadow ray adds
  // (BSDF x cosine x radiance x MIS weight / pdf; competing_pdf(world_dir, local_dir) is the
  // density of the strategy that could have found the same light) and the shadow ray, written
  // into `shadow` in place (set_ray) and only where it returns true.
  template <class CompetingPdf>
  bool next_event(const glm::vec3& position, const glm::vec3& geometric_normal,
                  const shared::pg_frame& frame, const glm::vec3& wo, const shared::pg_lobes& lobes,
                  const glm::vec3& origin, float u_select, float u1, float u2,
                  const CompetingPdf& competing_pdf, glm::vec3& contribution, Ray& shadow) const;
  // The shadow rays of the pass just made (the blocks' lists).
  void run_shadow_rays(RayCounts& rays, PassTimes& times);
  // Adds each unoccluded shadow ray's contribution to its path (to the pixel's before_y at
  // x0, where VPLs are kept).
  void apply_shadow_rays(bool at_x0);
  // Light a bounce found at path vertex `depth` (emission with its MIS weight, times the
  // path's throughput), added to the path's radiance, or to the pixel's own where the VPL
  // leaves it out.
  void add_found_light(PathState& p, std::uint32_t i, int depth, const glm::vec3& found);
  // What borrow_guide() reads of the pixel a later vertex projects to, in one cache line:
  // the vertices land all over the image, and the G-buffer's channels and the sampler's
  // mixture, read apart, cost a cache miss each (docs/guiding.md, "Later vertices, revisited").
  struct alignas(64) BorrowablePixel {
    shared::float4 position_depth;  // w <= 0: the pixel has no guide to lend
    glm::vec3 normal;               // shading normal
    std::uint32_t material = 0;
    shared::pg_pmm_model model;
  };
  static_assert(sizeof(BorrowablePixel) == 64, "one cache line per borrowable pixel");
  // Fills borrowable_ from the G-buffer and the sampler's mixtures (guide_secondary).
  void collect_borrowable(const GBuffer& g, const FirstBounceSampler& sampler);
  // The pixel a world position projects to in this frame's camera, or kNotOnScreen.
  static constexpr std::size_t kNotOnScreen = ~std::size_t{0};
  std::size_t borrowable_index(const glm::vec3& position) const;
  // The pixel the hit of slot j projects to (kNotOnScreen for none), whose borrowable entry
  // it starts loading: the shading loop asks a few vertices before borrow_guide() reads it,
  // since later vertices land all over the image and a table entry read cold stalls the loop
  // for a whole cache miss (docs/guiding.md, "Later vertices, revisited").
  std::size_t prefetch_borrowable(std::size_t j) const;
  // Starts loading path i's PathState (and VplPath where VPLs are kept) a few vertices before
  // the shading loop reads it.
  void prefetch_path(std::uint32_t i) const;
  // Starts loading the VPL records of pixel i that the first bounce's hit writes.
  static void prefetch_vpl(const VplBuffer& vpls, std::uint32_t i);
  // The guide of pixel i (from prefetch_borrowable) if it shows surface point sp
  // (guide_secondary).
  bool borrow_guide(std::size_t i, const SurfacePoint& sp, PixelGuide& guide) const;
  // The world guide's training samples of this pass: each recorded vertex's bounce with the
  // radiance its path gathered after it (WorldVertex), into the next blocks of world_blocks_.
  void collect_world_samples();
  // Puts the listed bounce rays and their paths in RayOrder's groups: rays_ and active_ then
  // hold them from slot 0 on, every block full but the last (group_this_pass_).
  void group_rays();
  // Pixel estimates (non-finite ones dropped and counted) and the VPLs' radiance.
  void gather(std::vector<glm::vec3>& radiance, VplBuffer* vpls, std::uint64_t& nonfinite) const;

  const Scene& scene_;
  const EmbreeScene& tracer_;
  const TriangleTable& triangles_;
  const Lights& lights_;
  PathTracerSettings settings_;
  bool prefetch_surfaces_ = false;  // settings_.surface_prefetch, resolved for the scene
  bool may_group_ = false;          // may_group_bounce_rays(settings_.bounce_ray_order)
  bool group_this_pass_ = false;    // this trace() groups its bounce rays
  TimedChoice order_choice_;        // listed or grouped, under BounceRayOrder::automatic
  RayOrder ray_order_;              // the groups: the scene's bounds in cells

  // This frame's G-buffer and first-bounce sampler (set by trace()).
  const GBuffer* gbuffer_ = nullptr;
  const FirstBounceSampler* sampler_ = nullptr;
  SampleCoordinates at_;  // this sample's (trace)
  // Under FirstBounceMis::mixture with a sampler that is not the BSDF's, the first bounce's
  // hit on a light weighs itself with the sampler's pdf(), as the primary hit's light sample
  // does, evaluated only where a light is found (first_bounce_mis_density) instead of for
  // every path at x0 (docs/guiding.md, "One density for both weights at the primary hit").
  bool first_bounce_mis_deferred_ = false;

  // Scratch, reused across frames.
  LargeVector<PathState> paths_;
  LargeVector<VplPath> vpl_paths_;  // per pixel, where keep_vpls_
  bool keep_vpls_ = false;          // this pass writes VPLs (trace()'s vpls)
  bool next_event_on_ = true;       // next-event estimation this frame (settings and lights)
  // The paths are shaded in blocks of kPathBlock slots, fixed whatever the thread count: block
  // b's slots are b * kPathBlock onwards. At the primary hits slot i is pixel i's; after each
  // vertex a block lists, from its first slot and in slot order, the paths that go on (their
  // pixels in active_, their next rays in rays_, ray_counts_[b] of them, written in place), and
  // the shadow rays its vertices made (shadow_counts_[b] of them). Blocks merge only where a
  // pass groups its bounce rays (group_rays: every block full but the last); otherwise a block
  // of the last bounce holds what is left of its pixels' paths (docs/host-path-tracer.md,
  // "Shadow rays listed where they are made", "Bounce rays listed in place", "Bounce rays traced
  // in groups").
  static constexpr std::size_t kPathBlock = 2048;
  LargeVector<std::uint32_t> active_;
  LargeVector<Ray> rays_;
  LargeVector<Hit> hits_;
  // Where group_this_pass_: each listed ray's group (written with the ray), and the rays and
  // their paths in group order (group_rays), swapped with rays_ and active_ before each trace.
  LargeVector<std::uint16_t> ray_groups_;
  LargeVector<Ray> grouped_rays_;
  LargeVector<std::uint32_t> grouped_active_;
  std::vector<std::uint32_t> ray_counts_;  // per block
  // Per shadow-ray entry: the ray, what it adds to its path's radiance if unoccluded, the path,
  // and Embree's answer.
  LargeVector<Ray> shadow_rays_;
  LargeVector<glm::vec3> shadow_contribution_;
  LargeVector<std::uint32_t> shadow_path_;
  LargeVector<std::uint8_t> occluded_;
  std::vector<std::uint32_t> shadow_counts_;  // per block
  LargeVector<BorrowablePixel> borrowable_;   // per pixel, with guide_secondary

  // The world guide (set_world_guide) and what a path records for it at each later vertex that
  // sampled a bounce: the bounce's training sample without its weight, the path's throughput
  // on arrival and its radiance once the vertex's own light sample is in (written when the path
  // reaches the next vertex). The radiance the path gathers after that, divided by the
  // throughput, is the sample's weight a = L_i f cos / r (with Russian roulette's 1/q).
  struct WorldVertex {
    std::uint64_t cell;  // kNoCell: no sample (a glossy vertex, or a direction below the cell)
    float ux, uy, bsdf_pdf, density;
    glm::vec3 throughput, radiance_before;
  };
  const WorldGuide* world_guide_ = nullptr;
  LargeVector<WorldVertex> world_vertices_;  // [path * world_stride_ + depth - 1]
  int world_depths_ = 0;                     // the depths the guide covers (prepare)
  std::size_t world_stride_ = 1;             // records per path: max(1, world_depths_)
  LargeVector<std::uint8_t> world_depth_;    // per path: vertices recorded (or kNotRecording)
  static constexpr std::uint8_t kNotRecording = 0xff;
  static_assert(kMaxPathBounces < kNotRecording, "a path's recorded depth fits below the mark");
  // Blocks of kWorldBlock paths of each pass, in order; world_blocks_used_ of them hold this
  // frame's samples (the vectors keep their memory).
  std::vector<std::vector<WorldTrainingSample>> world_blocks_;
  std::size_t world_blocks_used_ = 0;
};

}  // namespace rtpg
