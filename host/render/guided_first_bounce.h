// The guided first bounce: the renderer's side of the guiding library. Hands the host
// G-buffer and VPLs to the device, runs the guider's reproject / sample / train kernels and
// brings the sampled directions back for the host path tracer. Where the device shares host
// memory all three are read in place (no copies; docs/design.md, "One frame").
#pragma once

#include <memory>
#include <vector>

#include "render/first_bounce.h"
#include "render/host_transfer.h"
#include "render/vpl_buffer.h"
#include "rtpg/guider.h"

namespace rtpg {

class ClRuntime;
class PinnedStaging;

// What the device does beside the host (docs/guiding.md). Training: end_frame leaves it running
// while the host makes the next frame's camera rays and G-buffer, and the next frame waits for it
// ("Training overlapped with the next frame, on a GPU"); automatic is on where the device has
// memory of its own (not DeviceInfo::host_unified_memory), off where its kernels share the host's
// cores (PoCL, where it saved nothing). Sampling: begin_frame and start_sample leave the
// G-buffer's upload, reproject and sample running while the path tracer makes the primary hit's
// light samples, and finish_sample waits ("Sampling overlapped with the primary hit's light
// samples"); automatic is off on every device: its split pass cost more than it hid on PoCL and
// on an H200 ("The bus and the sampling's overlap on an H200").
enum class Overlap { automatic, on, off };
// "auto", "on", "off" (the CLI's --train-overlap and --sample-overlap); throws GuiderError else.
Overlap parse_overlap(const std::string& name);

class GuidedFirstBounce final : public FirstBounceSampler {
 public:
  // With HostTransfer::in_place (automatic on a device that shares host memory) the renderer
  // must alternate two G-buffers (reads_gbuffers_in_place()). automatic is resolved by
  // resolve_host_transfer (host/render/host_transfer.h).
  GuidedFirstBounce(ClRuntime& runtime, int width, int height, const GuidingSettings& settings,
                    HostTransfer transfer = HostTransfer::automatic,
                    Overlap train_overlap = Overlap::automatic,
                    Overlap sample_overlap = Overlap::automatic);
  ~GuidedFirstBounce() override;

  void begin_frame(const GBuffer& gbuffer, const SampleCoordinates& at) override;
  FirstBounceSamples sample(const GBuffer& gbuffer, const SampleCoordinates& at) override;
  bool samples_beside_the_host() const override { return sample_overlap_; }
  void start_sample(const GBuffer& gbuffer, const SampleCoordinates& at) override;
  FirstBounceSamples finish_sample() override;
  float pdf(const GBuffer& gbuffer, std::size_t i, const shared::pg_lobes& lobes,
            const glm::vec3& wo, const glm::vec3& wi) const override;
  bool pixel_guide(const GBuffer& gbuffer, std::size_t i, PixelGuide& out) const override;
  void end_frame(const GBuffer& gbuffer, const VplBuffer& vpls,
                 const SampleCoordinates& at) override;
  bool wants_vpls() const override { return true; }
  bool reads_gbuffers_in_place() const override { return zero_copy_; }
  // Without pdf() or pixel_guide() to answer, the sample kernel leaves the mixture unwritten
  // and nothing of it is copied or mapped; the statistics come from the kernels' counts.
  void expect_queries(const HostQueries& queries) override;
  // The VPLs the last end_frame() gave the training, where they were copied to the device
  // (not HostTransfer::in_place): the layout the train kernel read.
  const GuiderVpls& device_vpls() const { return owned_vpls_; }
  bool sends_packed_vpls() const override { return packed_; }
  HostTransfer host_transfer() const { return transfer_; }  // automatic resolved
  bool overlaps_training() const { return overlap_; }       // Overlap resolved
  bool overlaps_sampling() const { return sample_overlap_; }
  // This frame's G-buffer on the device where begin_frame copied g there (not in place): the
  // denoiser reads it instead of copying it again (SvgfDenoiser::denoise). Valid until the next
  // begin_frame; nullptr for any other G-buffer.
  const GuiderGBuffer* device_gbuffer_of(const GBuffer& g) const {
    return !zero_copy_ && copied_from_ == &g ? &current_gbuffer_ : nullptr;
  }
  void report(std::map<std::string, double>& time_ms,
              std::map<std::string, double>& extra) override;

  Guider& guider() { return *guider_; }
  // Freezes (false) or resumes (true) training: frozen, end_frame() leaves the state alone.
  void set_training(bool on) { training_ = on; }

 private:
  // The model pixel i sampled this frame (from the mixture the sample kernel wrote); throws
  // GuiderError where the mixture was not asked for (expect_queries).
  shared::pg_pmm_model model_at(std::size_t i) const;
  // surfaces_, guided_fraction_ and mean_pi_ from the counts of the last sample().
  void count_models();
  // Waits for the last training (at once where end_frame waited for it) and reads back what it
  // trained, for trained_fraction.
  void finish_training();
  // Copies a host G-buffer or VPL buffer into its device buffers (pinned or pageable), waits
  // unless told not to (then the staging, or the pageable host memory, stays in use until the
  // queue gets past the copy), and counts the bytes.
  template <class Host, class Device>
  void copy_to_device(const Host& host, const Device& device, std::size_t bytes, bool wait = true);

  ClRuntime& runtime_;
  ClRuntime::Use runtime_use_{runtime_};  // the runtime must outlive this
  std::unique_ptr<Guider> guider_;
  // This frame's and last frame's G-buffer on the device: in place, the host's own memory
  // (wrap_host_gbuffer; current_host_ is that memory), else copies in owned_gbuffers_.
  GuiderGBuffer current_gbuffer_, previous_gbuffer_;
  const void* current_host_ = nullptr;
  const GBuffer* copied_from_ = nullptr;  // the G-buffer current_gbuffer_ is a copy of
  GuiderGBuffer owned_gbuffers_[2];
  int owned_current_ = 0;
  bool have_previous_ = false;
  bool training_ = true;
  // The training's Overlap resolved. While training runs past end_frame, pending_vpls_ holds
  // the VPL buffers it reads (in place: the wrapper of the host's vector), and vpls_staged_
  // completes once their copy has left the upload staging (pinned or packed).
  bool overlap_ = false;
  cl::Event vpls_staged_;
  // The sampling's Overlap resolved: begin_frame and start_sample enqueue without waiting.
  bool sample_overlap_ = false;
  // What the sample kernel writes: the mixture too where the host reads it (expect_queries).
  SampleOutputs sample_outputs() const;
  // Enqueues the samples' way to the host: mapped in place, or copied into the staging.
  void enqueue_sample_transfer(SampleOutputs outputs);
  GuiderVpls owned_vpls_, pending_vpls_;
  double train_wait_ms_ = 0.0;  // how long begin_frame waited for the overlapped training
  GuiderSamples samples_;
  // Where the device shares host memory the samples are read in place (mapped from the time
  // sample() returns until the next sample() or the end). Elsewhere they are copied into
  // staging_, host memory the OpenCL runtime allocates (CL_MEM_ALLOC_HOST_PTR) and that stays
  // mapped: a discrete GPU's driver copies into such (pinned) memory about 5x faster than into
  // pageable memory (docs/guiding.md, "On a GPU"). Its mapped pointers are staged_.
  void unmap_samples();
  HostTransfer transfer_ = HostTransfer::automatic;
  bool zero_copy_ = false, mapped_ = false;
  // Whether the device shares host memory (DeviceInfo::host_unified_memory): where it does not,
  // what zero_copy_ reads in place still crosses the bus (the OpenCL implementation copies it),
  // and the traffic counted says so.
  bool shares_host_memory_ = false;
  // HostTransfer::packed: the G-buffer goes up packed into packed_gbuffer_ and the device
  // unpacks it into current_gbuffer_ (Guider::unpack_gbuffer).
  bool packed_ = false;
  GuiderPackedGBuffer packed_gbuffer_;
  bool host_reads_mixture_ = true;  // expect_queries: pdf() or pixel_guide() will be asked
  GuiderSamples staging_;
  // HostTransfer::pinned: where the G-buffer and then the VPLs are copied on their way up.
  std::unique_ptr<PinnedStaging> upload_staging_;
  struct HostSamples {  // PG_SAMPLE_CHANNELS in staging_
    HostChannelView<glm::vec4> direction_pdf;
    HostChannelView<std::uint32_t> strategy;
    HostChannelView<glm::vec4> mixture_a;  // what pdf() evaluates
    HostChannelView<glm::vec2> mixture_b;
  } staged_;
  // HostTransfer::packed: the sample kernel's directions, densities and strategies come back
  // packed (Guider::pack_samples into packed_samples_, copied into packed_staging_, mapped at
  // staged_packed_); the mixture, where the host reads it, through staging_ as before.
  GuiderPackedSamples packed_samples_, packed_staging_;
  // HostTransfer::packed: the VPLs go up packed into packed_vpls_ and the device unpacks them
  // (Guider::unpack_vpls) from the samples they followed, sample 0's, which the sample kernel
  // writes into first_samples_ (later samples into samples_) so that they survive the frame.
  GuiderPackedVpls packed_vpls_;
  GuiderSamples first_samples_;
  const GuiderSamples& samples_for(const SampleCoordinates& at);  // sets drawn_
  const GuiderSamples* drawn_ = &samples_;  // what the last sample() drew into
  struct HostPackedSamples {                // PG_PACKED_SAMPLE_CHANNELS in packed_staging_
    HostChannelView<glm::vec2> direction;
    HostChannelView<float> pdf_strategy;
  } staged_packed_;
  struct SampleView {  // this frame's samples, in staging_ or mapped
    const glm::vec4* direction_pdf = nullptr;
    const std::uint32_t* strategy = nullptr;
    const glm::vec2* packed_direction = nullptr;
    const float* packed_pdf_strategy = nullptr;
    const glm::vec4* mixture_a = nullptr;
    const glm::vec2* mixture_b = nullptr;
  } view_;
  std::size_t pixels_ = 0, surfaces_ = 0;
  std::size_t bytes_ = 0;  // copied between host and device this frame
  double upload_ms_ = 0.0, readback_ms_ = 0.0, sample_ms_ = 0.0;
  double guided_fraction_ = 0.0, trained_fraction_ = 0.0, mean_pi_ = 0.0;
};

}  // namespace rtpg
