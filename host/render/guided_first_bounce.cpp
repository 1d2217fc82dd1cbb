#include "render/guided_first_bounce.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "render/gbuffer_packer.h"
#include "render/pinned_staging.h"
#include "rtpg/cl_runtime.h"
#include "shared/gbuffer_packing.h"

namespace rtpg {
namespace {

// A frame's G-buffer and VPLs must be of the sampler's size, every channel whole, before
// anything is copied, wrapped or swapped: a G-buffer of the same pixel count in another shape
// (32x64 for 64x32) would pass every byte-size check and be read at the wrong width, and a short
// channel copied through staging would leave the rest of the device buffer as it was.
void check_frame_size(const GBuffer& g, const Guider& guider) {
  if (g.width != guider.width() || g.height != guider.height())
    throw GuiderError(fmt::format("guided first bounce: a {}x{} G-buffer for a {}x{} sampler",
                                  g.width, g.height, guider.width(), guider.height()));
  const std::size_t n = g.pixel_count();
#define RTPG_CHECK_CHANNEL(name, type, bytes)                                                 \
  if (g.name.size() != n)                                                                     \
    throw GuiderError(fmt::format("guided first bounce: G-buffer channel " #name " holds {} " \
                                  "pixels, not {}",                                           \
                                  g.name.size(), n));
  PG_GBUFFER_CHANNELS(RTPG_CHECK_CHANNEL)
#undef RTPG_CHECK_CHANNEL
}

void check_vpl_size(const VplBuffer& vpls, std::size_t n) {
#define RTPG_CHECK_CHANNEL(name, type, bytes)                                                    \
  if (vpls.name.size() != n)                                                                     \
    throw GuiderError(fmt::format("guided first bounce: VPL channel " #name " holds {}, not {}", \
                                  vpls.name.size(), n));
  PG_VPL_CHANNELS(RTPG_CHECK_CHANNEL)
#undef RTPG_CHECK_CHANNEL
}

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

// Bytes of one pixel's entries in a channel list (include/rtpg/guiding_layout.h).
#define RTPG_ADD_BYTES(name, type, bytes) +(bytes)
constexpr std::size_t kGBufferBytes = 0 PG_GBUFFER_CHANNELS(RTPG_ADD_BYTES);
constexpr std::size_t kVplBytes = 0 PG_VPL_CHANNELS(RTPG_ADD_BYTES);
constexpr std::size_t kPackedGBufferBytes = 0 PG_PACKED_GBUFFER_CHANNELS(RTPG_ADD_BYTES);
constexpr std::size_t kPackedSampleBytes = 0 PG_PACKED_SAMPLE_CHANNELS(RTPG_ADD_BYTES);
constexpr std::size_t kPackedVplBytes = 0 PG_PACKED_VPL_CHANNELS(RTPG_ADD_BYTES);
#undef RTPG_ADD_BYTES
#define RTPG_COUNT(name, type, bytes) +1
constexpr std::size_t kGBufferChannels = 0 PG_GBUFFER_CHANNELS(RTPG_COUNT);
constexpr std::size_t kVplChannels = 0 PG_VPL_CHANNELS(RTPG_COUNT);
#undef RTPG_COUNT

// Each channel of a host G-buffer or VPL buffer through the staging into the device buffer of
// the same name (include/rtpg/guiding_layout.h).
void stage_channels(PinnedStaging& staging, const GBuffer& host, const GuiderGBuffer& device) {
#define RTPG_STAGE(name, type, bytes) staging.stage(host.name, device.name, #name);
  PG_GBUFFER_CHANNELS(RTPG_STAGE)
#undef RTPG_STAGE
}
void stage_channels(PinnedStaging& staging, const VplBuffer& host, const GuiderVpls& device) {
#define RTPG_STAGE(name, type, bytes) staging.stage(host.name, device.name, #name);
  PG_VPL_CHANNELS(RTPG_STAGE)
#undef RTPG_STAGE
}

// The host G-buffer packed straight into the staging (render/gbuffer_packer.h), in parallel, and
// its channels' copies to the device enqueued. Throws GuiderError where a material id or the
// flags do not fit in the packed word (nothing is enqueued then).
void stage_packed_gbuffer(PinnedStaging& staging, const GBuffer& g,
                          const GuiderPackedGBuffer& device) {
  const std::size_t n = g.pixel_count();
  auto* surface =
      static_cast<shared::uint4*>(staging.reserve(n * 16, device.surface, "packed surface"));
  auto* shading =
      static_cast<shared::uint2*>(staging.reserve(n * 8, device.shading, "packed shading"));
  const PackedGBufferView view{surface, shading};
  std::atomic<bool> unpackable{false};
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, std::size_t{1} << 13),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      if (!pack_gbuffer(g, r.begin(), r.end(), view)) unpackable = true;
                    });
  if (unpackable)
    throw GuiderError(
        "packed G-buffer: a material id above " + std::to_string(PG_PACKED_MATERIAL_MAX) +
        " or flags above 255 do not fit in the packed shading word (use --host-transfer pinned)");
  staging.commit(surface, n * 16, device.surface);
  staging.commit(shading, n * 8, device.shading);
}

void stage_channels(PinnedStaging& staging, const VplBuffer::Packed& host,
                    const GuiderPackedVpls& device) {
#define RTPG_STAGE(name, type, bytes) staging.stage(host.name, device.name, "packed " #name);
  PG_PACKED_VPL_CHANNELS(RTPG_STAGE)
#undef RTPG_STAGE
}

}  // namespace

template <class Host, class Device>
void GuidedFirstBounce::copy_to_device(const Host& host, const Device& device, std::size_t bytes,
                                       bool wait) {
  if (transfer_ == HostTransfer::pinned || transfer_ == HostTransfer::packed) {
    upload_staging_->begin();
    stage_channels(*upload_staging_, host, device);
  } else {
    enqueue_upload(runtime_.queue(), host, device);
  }
  if (wait) translate_cl_errors([&] { runtime_.queue().finish(); });
  bytes_ += bytes;
}

Overlap parse_overlap(const std::string& name) {
  if (name == "auto") return Overlap::automatic;
  if (name == "on") return Overlap::on;
  if (name == "off") return Overlap::off;
  throw GuiderError("overlap '" + name + "' is none of auto, on, off");
}

GuidedFirstBounce::GuidedFirstBounce(ClRuntime& runtime, int width, int height,
                                     const GuidingSettings& settings, HostTransfer transfer,
                                     Overlap train_overlap, Overlap sample_overlap)
    : runtime_(runtime),
      guider_(std::make_unique<Guider>(runtime, width, height, settings)),
      pixels_(static_cast<std::size_t>(width) * static_cast<std::size_t>(height)) {
  transfer_ = resolve_host_transfer(transfer, runtime.info().host_unified_memory);
  zero_copy_ = transfer_ == HostTransfer::in_place;
  shares_host_memory_ = runtime.info().host_unified_memory;
  // The training's automatic overlap: only where the device has cores of its own to work on
  // while the host works; on PoCL's CPU device the kernels and the host share the cores
  // (docs/guiding.md, "Training overlapped with the next frame's host work"). The sampling's:
  // nowhere, since its split pass over the pixels cost the host more than the overlap hid, on
  // PoCL and on an H200 ("The bus and the sampling's overlap on an H200").
  overlap_ = train_overlap == Overlap::on ||
             (train_overlap == Overlap::automatic && !runtime.info().host_unified_memory);
  sample_overlap_ = sample_overlap == Overlap::on;
  packed_ = transfer_ == HostTransfer::packed;
  if (transfer_ == HostTransfer::pinned || packed_)
    upload_staging_ = std::make_unique<PinnedStaging>(
        runtime.context(), runtime.queue(),
        std::max(packed_ ? kPackedGBufferBytes : kGBufferBytes, kVplBytes) * pixels_,
        std::max(kGBufferChannels, kVplChannels));
  if (packed_) packed_gbuffer_ = make_guider_packed_gbuffer(runtime.context(), width, height);
  if (!zero_copy_) {
    for (GuiderGBuffer& g : owned_gbuffers_)
      g = make_guider_gbuffer(runtime.context(), width, height, 0,
                              packed_ ? KernelAccess::read_write : KernelAccess::read_only);
    owned_vpls_ = make_guider_vpls(runtime.context(), width, height, 0,
                                   packed_ ? KernelAccess::read_write : KernelAccess::read_only);
  }
  samples_ =
      make_guider_samples(runtime.context(), width, height, zero_copy_ ? CL_MEM_ALLOC_HOST_PTR : 0,
                          packed_ ? KernelAccess::read_write : KernelAccess::read_only);
  if (!zero_copy_) {
    staging_ = make_guider_samples(runtime.context(), width, height, CL_MEM_ALLOC_HOST_PTR);
    if (packed_) {
      first_samples_ =
          make_guider_samples(runtime.context(), width, height, 0, KernelAccess::read_write);
      packed_vpls_ = make_guider_packed_vpls(runtime.context(), width, height);
      packed_samples_ = make_guider_packed_samples(runtime.context(), width, height);
      packed_staging_ =
          make_guider_packed_samples(runtime.context(), width, height, CL_MEM_ALLOC_HOST_PTR);
    }
    translate_cl_errors([&] {
      cl::CommandQueue& q = runtime_.queue();
#define RTPG_MAP_STAGING(name, type, bytes)                                              \
  staged_.name.count = pixels_;                                                          \
  staged_.name.pointer = static_cast<decltype(staged_.name.pointer)>(q.enqueueMapBuffer( \
      staging_.name, CL_TRUE, CL_MAP_READ | CL_MAP_WRITE, 0, pixels_ * (bytes)));
      PG_SAMPLE_CHANNELS(RTPG_MAP_STAGING)
#undef RTPG_MAP_STAGING
      if (packed_) {
#define RTPG_MAP_STAGING(name, type, bytes)                                  \
  staged_packed_.name.count = pixels_;                                       \
  staged_packed_.name.pointer =                                              \
      static_cast<decltype(staged_packed_.name.pointer)>(q.enqueueMapBuffer( \
          packed_staging_.name, CL_TRUE, CL_MAP_READ | CL_MAP_WRITE, 0, pixels_ * (bytes)));
        PG_PACKED_SAMPLE_CHANNELS(RTPG_MAP_STAGING)
#undef RTPG_MAP_STAGING
      }
    });
  }
}

GuidedFirstBounce::~GuidedFirstBounce() {
  try {
    unmap_samples();
    if (!zero_copy_) {
      cl::CommandQueue& q = runtime_.queue();
#define RTPG_UNMAP_STAGING(name, type, bytes) \
  q.enqueueUnmapMemObject(staging_.name, staged_.name.pointer);
      PG_SAMPLE_CHANNELS(RTPG_UNMAP_STAGING)
#undef RTPG_UNMAP_STAGING
      if (packed_) {
#define RTPG_UNMAP_STAGING(name, type, bytes) \
  q.enqueueUnmapMemObject(packed_staging_.name, staged_packed_.name.pointer);
        PG_PACKED_SAMPLE_CHANNELS(RTPG_UNMAP_STAGING)
#undef RTPG_UNMAP_STAGING
      }
    }
  } catch (...) {  // a failing unmap at teardown leaves the finish below to do
  }
  // Apart from the unmaps: kernels still running (training overlapped with the host) read the
  // renderer's G-buffer and VPLs in place, which the renderer frees after this destructor.
  try {
    runtime_.queue().finish();
  } catch (...) {  // a failing queue at teardown has nothing left to corrupt
  }
}

void GuidedFirstBounce::unmap_samples() {
  if (!mapped_) return;
  // Each pointer is cleared once its unmap is enqueued, and mapped_ only after all of them: an
  // unmap that fails leaves the buffers still mapped to the next call, instead of mapped behind
  // a flag that says they are not (the sample kernel would then write a mapped buffer).
  translate_cl_errors([&] {
    cl::CommandQueue& q = runtime_.queue();
    const auto unmap = [&](const cl::Buffer& buffer, const auto*& pointer) {
      if (pointer == nullptr) return;
      q.enqueueUnmapMemObject(buffer, const_cast<void*>(static_cast<const void*>(pointer)));
      pointer = nullptr;
    };
    unmap(samples_.direction_pdf, view_.direction_pdf);
    unmap(samples_.strategy, view_.strategy);
    unmap(samples_.mixture_a, view_.mixture_a);
    unmap(samples_.mixture_b, view_.mixture_b);
  });
  mapped_ = false;
  view_ = SampleView{};
}

void GuidedFirstBounce::finish_training() {
  const auto t = Clock::now();
  guider_->wait_for_training();
  train_wait_ms_ = ms_since(t);
  pending_vpls_ = GuiderVpls{};
  bytes_ += guider_->train_count_record_bytes();  // what count_trained reads
  trained_fraction_ =
      surfaces_ ? static_cast<double>(guider_->count_trained()) / static_cast<double>(surfaces_)
                : 0.0;
}

void GuidedFirstBounce::begin_frame(const GBuffer& g, const SampleCoordinates& at) {
  check_frame_size(g, *guider_);
  bytes_ = 0;
  // Last frame's training, left running by end_frame: the staging the G-buffer goes up through,
  // and the host memory it read in place, are free once it is done. Its figures (train,
  // trained_fraction) are reported with this frame's. With the sampling overlapped it is
  // finish_sample that waits for it, and here only its VPLs' copy out of the staging.
  train_wait_ms_ = 0.0;
  if (!guider_->training_pending()) {
    trained_fraction_ = 0.0;
  } else if (!sample_overlap_) {
    finish_training();
  } else if (upload_staging_) {
    // The training goes on (finish_sample waits for it; the queue runs reproject after it), but
    // the staging is the G-buffer's next: the VPLs' copy must have left it.
    translate_cl_errors([&] { vpls_staged_.wait(); });
  }
  const Guider::Wait wait = sample_overlap_ ? Guider::Wait::later : Guider::Wait::finish;
  auto t = Clock::now();
  // Last frame's G-buffer becomes the previous one only once this frame's is in place: a frame
  // refused on the way (the checks below, a packed G-buffer that does not fit) leaves the
  // sampler as it was, so the next good frame reprojects from the last good one
  // (GBufferPacker.ARefusedFrameLeavesTheHistoryAsItWas).
  const GuiderGBuffer previous = current_gbuffer_;
  if (zero_copy_) {
    // The host wrote this G-buffer after last frame's buffers over it were released; had it
    // written last frame's, there would be no previous G-buffer left to reproject from.
    if (have_previous_ && g.position_depth.data() == current_host_)
      throw GuiderError(
          "guiding: the G-buffer is read in place, so each frame needs the other of two "
          "G-buffers (FirstBounceSampler::reads_gbuffers_in_place)");
    current_gbuffer_ = wrap_host_gbuffer(runtime_.context(), g);
    current_host_ = g.position_depth.data();
    if (!shares_host_memory_) bytes_ += kGBufferBytes * g.pixel_count();
  } else {
    const int next = 1 - owned_current_;
    if (packed_) {
      // Packed into the staging first: it refuses a G-buffer that does not fit before anything
      // is enqueued or swapped.
      upload_staging_->begin();
      stage_packed_gbuffer(*upload_staging_, g, packed_gbuffer_);
      owned_current_ = next;
      current_gbuffer_ = owned_gbuffers_[owned_current_];
      if (!sample_overlap_) translate_cl_errors([&] { runtime_.queue().finish(); });
      bytes_ += kPackedGBufferBytes * g.pixel_count();
    } else {
      owned_current_ = next;
      current_gbuffer_ = owned_gbuffers_[owned_current_];
      copy_to_device(g, current_gbuffer_, kGBufferBytes * g.pixel_count(), !sample_overlap_);
    }
    copied_from_ = &g;
  }
  previous_gbuffer_ = previous;
  upload_ms_ = ms_since(t);
  if (packed_) guider_->unpack_gbuffer(packed_gbuffer_, current_gbuffer_, gbuffer_cameras(g), wait);
  if (have_previous_) {
    guider_->reproject(current_gbuffer_, previous_gbuffer_, wait);
  } else {
    guider_->reset();
  }
  have_previous_ = true;
  readback_ms_ = 0.0;
  sample_ms_ = 0.0;
}

void GuidedFirstBounce::expect_queries(const HostQueries& queries) {
  host_reads_mixture_ = queries.pdf || queries.pixel_guide;
}

FirstBounceSamples GuidedFirstBounce::sample(const GBuffer& g, const SampleCoordinates& at) {
  if (sample_overlap_) {
    start_sample(g, at);
    return finish_sample();
  }
  unmap_samples();  // the kernel overwrites them
  const SampleOutputs outputs = sample_outputs();
  guider_->sample(current_gbuffer_, at.seed, at.frame, at.sample, samples_for(at), outputs);
  sample_ms_ += guider_->last_times().sample_ms;
  const auto t = Clock::now();
  enqueue_sample_transfer(outputs);
  translate_cl_errors([&] { runtime_.queue().finish(); });
  readback_ms_ += ms_since(t);
  // The path tracer reads the directions as the kernel wrote them (no copy); the statistics
  // of this frame's models wait for end_frame (count_models).
  return FirstBounceSamples{view_.direction_pdf, view_.strategy, view_.packed_direction,
                            view_.packed_pdf_strategy};
}

const GuiderSamples& GuidedFirstBounce::samples_for(const SampleCoordinates& at) {
  drawn_ = packed_ && at.sample == 0 ? &first_samples_ : &samples_;
  return *drawn_;
}

SampleOutputs GuidedFirstBounce::sample_outputs() const {
  return host_reads_mixture_ ? SampleOutputs::directions_and_mixture : SampleOutputs::directions;
}

void GuidedFirstBounce::start_sample(const GBuffer& g, const SampleCoordinates& at) {
  unmap_samples();  // the kernel overwrites them
  const SampleOutputs outputs = sample_outputs();
  guider_->sample(current_gbuffer_, at.seed, at.frame, at.sample, samples_for(at), outputs,
                  Guider::Wait::later);
  enqueue_sample_transfer(outputs);
  translate_cl_errors([&] { runtime_.queue().flush(); });
}

FirstBounceSamples GuidedFirstBounce::finish_sample() {
  const auto t = Clock::now();
  // Last frame's training first (it ran before everything this frame enqueued), then the
  // upload, reproject, sample and the samples' way back (readback: the whole wait).
  if (guider_->training_pending()) finish_training();
  translate_cl_errors([&] { runtime_.queue().finish(); });
  guider_->wait_for_kernels();
  readback_ms_ += ms_since(t);
  sample_ms_ += guider_->last_times().sample_ms;
  return FirstBounceSamples{view_.direction_pdf, view_.strategy, view_.packed_direction,
                            view_.packed_pdf_strategy};
}

void GuidedFirstBounce::enqueue_sample_transfer(SampleOutputs outputs) {
  const std::size_t n = pixels_;
  if (zero_copy_) {
    // Marked mapped before the first map: each pointer is set as its map returns, so a map that
    // fails leaves the ones before it for unmap_samples to release.
    mapped_ = true;
    translate_cl_errors([&] {
      cl::CommandQueue& q = runtime_.queue();
      auto map = [&](const cl::Buffer& b, std::size_t bytes) {
        return q.enqueueMapBuffer(b, CL_FALSE, CL_MAP_READ, 0, n * bytes);
      };
      view_.direction_pdf = static_cast<const glm::vec4*>(map(samples_.direction_pdf, 16));
      view_.strategy = static_cast<const std::uint32_t*>(map(samples_.strategy, 4));
      if (host_reads_mixture_) {
        view_.mixture_a = static_cast<const glm::vec4*>(map(samples_.mixture_a, 16));
        view_.mixture_b = static_cast<const glm::vec2*>(map(samples_.mixture_b, 8));
      }
    });
    if (!shares_host_memory_) bytes_ += sample_bytes_per_pixel(outputs) * n;
    return;
  }
  if (host_reads_mixture_) {
    view_.mixture_a = staged_.mixture_a.data();
    view_.mixture_b = staged_.mixture_b.data();
  }
  if (!packed_) {
    enqueue_download(runtime_.queue(), *drawn_, staged_, outputs);
    bytes_ += sample_bytes_per_pixel(outputs) * n;
    view_.direction_pdf = staged_.direction_pdf.data();
    view_.strategy = staged_.strategy.data();
    return;
  }
  // Packed: 12 bytes a pixel instead of direction_pdf's and strategy's 20, and the mixture
  // where the host reads it.
  guider_->pack_samples(*drawn_, packed_samples_,
                        sample_overlap_ ? Guider::Wait::later : Guider::Wait::finish);
  enqueue_download(runtime_.queue(), packed_samples_, staged_packed_);
  bytes_ += kPackedSampleBytes * n;
  if (host_reads_mixture_) {
    translate_cl_errors([&] {
      cl::CommandQueue& q = runtime_.queue();
      q.enqueueReadBuffer(drawn_->mixture_a, CL_FALSE, 0, n * 16, staged_.mixture_a.data());
      q.enqueueReadBuffer(drawn_->mixture_b, CL_FALSE, 0, n * 8, staged_.mixture_b.data());
    });
    bytes_ += (sample_bytes_per_pixel(SampleOutputs::directions_and_mixture) -
               sample_bytes_per_pixel(SampleOutputs::directions)) *
              n;
  }
  view_.packed_direction = staged_packed_.direction.data();
  view_.packed_pdf_strategy = staged_packed_.pdf_strategy.data();
}

void GuidedFirstBounce::count_models() {
  // The share of surface pixels that sampled a trained Gaussian and their mean pi, from the
  // sample kernel's counts of the frame's last sample() (statistics only).
  const GuiderSampleCounts counts = guider_->sample_counts();
  bytes_ += guider_->sample_count_record_bytes();
  surfaces_ = counts.surfaces;
  guided_fraction_ = counts.surfaces
                         ? static_cast<double>(counts.guided) / static_cast<double>(counts.surfaces)
                         : 0.0;
  mean_pi_ = counts.guided ? counts.pi_sum / static_cast<double>(counts.guided) : 0.0;
}

shared::pg_pmm_model GuidedFirstBounce::model_at(std::size_t i) const {
  if (!host_reads_mixture_)
    throw GuiderError(
        "guided first bounce: the mixture was not written (the renderer announced neither "
        "pdf() nor pixel_guide(), FirstBounceSampler::expect_queries)");
  const glm::vec4 a = view_.mixture_a[i];
  const glm::vec2 b = view_.mixture_b[i];
  return shared::pg_pmm_model_from_mixture(shared::float4(a.x, a.y, a.z, a.w),
                                           shared::float2(b.x, b.y));
}

float GuidedFirstBounce::pdf(const GBuffer&, std::size_t i, const shared::pg_lobes& lobes,
                             const glm::vec3& wo, const glm::vec3& wi) const {
  return shared::pg_pmm_pdf(model_at(i), lobes, wo, wi);
}

bool GuidedFirstBounce::pixel_guide(const GBuffer& g, std::size_t i, PixelGuide& out) const {
  if (host_reads_mixture_ && (view_.mixture_a == nullptr || i >= pixels_)) return false;
  out.model = model_at(i);
  if (!out.model.valid) return false;
  out.frame = gbuffer_frame(g, i);
  return true;
}

void GuidedFirstBounce::end_frame(const GBuffer& g, const VplBuffer& vpls,
                                  const SampleCoordinates& at) {
  // Last frame's G-buffer is done with (reproject read it): in place, the host writes that
  // memory next frame, so its buffers are released first.
  previous_gbuffer_ = GuiderGBuffer{};
  count_models();
  if (!training_) return;
  check_frame_size(g, *guider_);
  if (!packed_) check_vpl_size(vpls, g.pixel_count());
  const auto t = Clock::now();
  GuiderVpls device_vpls = owned_vpls_;
  if (zero_copy_) {
    device_vpls = wrap_host_vpls(runtime_.context(), vpls);  // released when train is done
    if (!shares_host_memory_) bytes_ += kVplBytes * g.pixel_count();
  } else if (packed_) {
    // The path tracer wrote them packed (VplBuffer::for_bus, which the renderer sets from
    // sends_packed_vpls()).
    if (!vpls.for_bus || vpls.packed.distance.size() != g.pixel_count())
      throw GuiderError(
          "guided first bounce: the VPLs were not packed for the bus (VplBuffer::for_bus)");
    upload_staging_->begin();
    stage_channels(*upload_staging_, vpls.packed, packed_vpls_);
    if (!overlap_) translate_cl_errors([&] { runtime_.queue().finish(); });
    bytes_ += kPackedVplBytes * g.pixel_count();
  } else {
    copy_to_device(vpls, device_vpls, kVplBytes * g.pixel_count(), /*wait=*/!overlap_);
  }
  if (!zero_copy_ && overlap_ && upload_staging_)
    translate_cl_errors(
        [&] { runtime_.queue().enqueueMarkerWithWaitList(nullptr, &vpls_staged_); });
  upload_ms_ += ms_since(t);
  if (packed_)
    guider_->unpack_vpls(packed_vpls_, current_gbuffer_, first_samples_, device_vpls,
                         overlap_ ? Guider::Wait::later : Guider::Wait::finish);
  if (overlap_) {
    // Nothing touches the VPLs, their staging or this G-buffer before the next frame waits for
    // the training: the renderer writes the other G-buffer next frame (in place) and rewrites
    // the VPLs only after the next sample() or finish_sample(); begin_frame waits for the
    // training (or, with the sampling overlapped, for the VPLs' copy, vpls_staged_) before it
    // stages the G-buffer.
    pending_vpls_ = device_vpls;
    guider_->train(current_gbuffer_, device_vpls, at.seed, at.frame, Guider::Wait::later);
    return;
  }
  guider_->train(current_gbuffer_, device_vpls, at.seed, at.frame);
  finish_training();
}

void GuidedFirstBounce::report(std::map<std::string, double>& time_ms,
                               std::map<std::string, double>& extra) {
  const GuiderTimes& k = guider_->last_times();
  time_ms["reproject"] = have_previous_ ? k.reproject_ms : 0.0;
  time_ms["sample"] = sample_ms_;
  time_ms["train"] = k.train_ms;
  time_ms["upload"] = upload_ms_;
  if (overlap_) time_ms["train_wait"] = train_wait_ms_;
  if (packed_) {
    time_ms["unpack"] = k.unpack_ms;
    time_ms["pack_samples"] = k.pack_samples_ms;
    time_ms["unpack_vpls"] = k.unpack_vpls_ms;
  }
  time_ms["readback"] = readback_ms_;
  extra["guided_fraction"] = guided_fraction_;
  extra["trained_fraction"] = trained_fraction_;
  extra["mean_pi"] = mean_pi_;
  // What the device ran (the settings' 0 = auto resolved) and whether samples were read in place.
  extra["train_lanes"] = guider_->train_lanes();
  extra["sample_lanes"] = guider_->sample_lanes();
  extra["row_work_groups"] = guider_->row_work_groups() ? 1.0 : 0.0;
  // 1 where nothing but the count records crosses: read in place, and the device shares host
  // memory.
  extra["zero_copy"] = zero_copy_ && shares_host_memory_ ? 1.0 : 0.0;
  extra["train_overlap"] = overlap_ ? 1.0 : 0.0;
  extra["sample_overlap"] = sample_overlap_ ? 1.0 : 0.0;
  // HostTransfer as a number: 1 in place, 2 pinned, 3 pageable, 4 packed.
  extra["host_transfer"] = static_cast<double>(static_cast<int>(transfer_));
  extra["host_device_bytes_per_pixel"] =
      static_cast<double>(bytes_) / static_cast<double>(std::max<std::size_t>(pixels_, 1));
}

}  // namespace rtpg
