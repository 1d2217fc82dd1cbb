// rtpg's guiding library: screen-space path guiding with a per-pixel parametric mixture
// (one 2D Gaussian in Shirley-Chiu square space plus the BSDF lobe), trained online by EM
// from the VPLs of neighbouring pixels and carried across frames by reprojection (paper
// "Real-Time Path-Guiding Based on Parametric Mixture Models"; docs/design.md).
//
// In Open PGL's terms: the Guider is the field (the per-pixel mixtures, on the device), the
// GuiderVpls are its sample storage (one VPL per pixel, filled by the renderer), and
// GuidingDistribution (include/rtpg/guiding_distribution.h) is the surface sampling
// distribution a CPU renderer evaluates for its MIS weights.
//
// A renderer keeps its own G-buffer and VPL buffers on the device, in the layouts of
// include/rtpg/guiding_layout.h, and per frame calls
//   guider.reproject(current, previous)   state of last frame -> this frame
//   guider.sample(current, ..., out)        first-bounce directions + pdf
//   ... the renderer traces its paths and writes one VPL per pixel ...
//   guider.train(current, vpls, ...)        one EM step per pixel
// Only the guider knows its state; it knows nothing of scenes, files or ray tracing. Every
// method throws GuiderError for misuse (among it a buffer that does not hold exactly
// width * height elements of its channel: another resolution's rows would be misread) and
// ClError (include/rtpg/cl_error.h) when OpenCL fails.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "rtpg/cl_error.h"
#include "rtpg/cl_runtime.h"
#include "rtpg/errors.h"
#include "rtpg/guiding_layout.h"
#include "rtpg/guiding_settings.h"
#include "rtpg/opencl.h"

namespace rtpg {

// Device buffers, one cl::Buffer per channel of include/rtpg/guiding_layout.h.
#define RTPG_DEVICE_CHANNEL(name, type, bytes) cl::Buffer name;
struct GuiderGBuffer {  // one frame's G-buffer (PG_GBUFFER_CHANNELS)
  PG_GBUFFER_CHANNELS(RTPG_DEVICE_CHANNEL)
};
struct GuiderVpls {  // one VPL per pixel (PG_VPL_CHANNELS)
  PG_VPL_CHANNELS(RTPG_DEVICE_CHANNEL)
};
struct GuiderSamples {  // what sample() writes (PG_SAMPLE_CHANNELS)
  PG_SAMPLE_CHANNELS(RTPG_DEVICE_CHANNEL)
};
// A G-buffer as it crossed the bus (PG_PACKED_GBUFFER_CHANNELS): what unpack_gbuffer() reads.
struct GuiderPackedGBuffer {
  PG_PACKED_GBUFFER_CHANNELS(RTPG_DEVICE_CHANNEL)
};
// VPLs as they cross the bus (PG_PACKED_VPL_CHANNELS): what unpack_vpls() reads.
struct GuiderPackedVpls {
  PG_PACKED_VPL_CHANNELS(RTPG_DEVICE_CHANNEL)
};
// Samples as they cross the bus back (PG_PACKED_SAMPLE_CHANNELS): what pack_samples() writes.
struct GuiderPackedSamples {
  PG_PACKED_SAMPLE_CHANNELS(RTPG_DEVICE_CHANNEL)
};
#undef RTPG_DEVICE_CHANNEL

// What sample() writes besides the directions, their densities and strategies: the mixture each
// pixel sampled (GuiderSamples' mixture_a and mixture_b), for a host that evaluates it in its
// MIS weights (include/rtpg/guiding_distribution.h); or nothing, which leaves those channels as
// they were and saves the kernel 24 bytes a pixel of stores (and a discrete GPU's host their
// copy).
enum class SampleOutputs { directions_and_mixture, directions };
// Whether a channel of PG_SAMPLE_CHANNELS is part of the mixture (mixture_a, mixture_b).
constexpr bool is_mixture_channel(std::string_view name) {
  return name.substr(0, 8) == "mixture_";
}
// Bytes per pixel of what sample() writes with these outputs (include/rtpg/guiding_layout.h).
constexpr std::size_t sample_bytes_per_pixel(SampleOutputs outputs) {
#define RTPG_SAMPLE_BYTES(name, type, bytes) \
  +(outputs == SampleOutputs::directions && is_mixture_channel(#name) ? 0 : (bytes))
  return 0 PG_SAMPLE_CHANNELS(RTPG_SAMPLE_BYTES);
#undef RTPG_SAMPLE_BYTES
}

// Buffers for width x height pixels (inputs read-only, samples write-only for the kernels).
// host_flags are added to the flags: with CL_MEM_ALLOC_HOST_PTR, on a device that shares host
// memory (DeviceInfo::host_unified_memory), the host can map the samples and read them in place
// instead of copying them; elsewhere such buffers, mapped, are pinned staging that a discrete
// GPU copies from and into several times faster (host/render/guided_first_bounce.cpp does both).
// A G-buffer that Guider::unpack_gbuffer() writes, VPLs that Guider::unpack_vpls() writes and
// samples that Guider::pack_samples() or unpack_vpls() read must be made with
// KernelAccess::read_write (otherwise the kernels only read a G-buffer and VPLs and only write
// samples).
enum class KernelAccess { read_only, read_write };
GuiderGBuffer make_guider_gbuffer(cl::Context& context, int width, int height,
                                  cl_mem_flags host_flags = 0,
                                  KernelAccess access = KernelAccess::read_only);
GuiderPackedGBuffer make_guider_packed_gbuffer(cl::Context& context, int width, int height,
                                               cl_mem_flags host_flags = 0);
GuiderVpls make_guider_vpls(cl::Context& context, int width, int height,
                            cl_mem_flags host_flags = 0,
                            KernelAccess access = KernelAccess::read_only);
GuiderPackedVpls make_guider_packed_vpls(cl::Context& context, int width, int height,
                                         cl_mem_flags host_flags = 0);
GuiderSamples make_guider_samples(cl::Context& context, int width, int height,
                                  cl_mem_flags host_flags = 0,
                                  KernelAccess access = KernelAccess::read_only);
GuiderPackedSamples make_guider_packed_samples(cl::Context& context, int width, int height,
                                               cl_mem_flags host_flags = 0);

namespace detail {
// A copy between a host channel and its device buffer moves exactly the buffer's bytes: a shorter
// channel would leave the rest of the image as whatever the buffer held (another image size, or
// a channel never filled). Throws GuiderError naming the copy and the channel.
inline void check_transfer_size(const cl::Buffer& buffer, std::size_t bytes, const char* what,
                                const char* name) {
  const std::size_t have = buffer.getInfo<CL_MEM_SIZE>();
  if (bytes != have)
    throw GuiderError(std::string(what) + " of " + name + ": a host channel of " +
                      std::to_string(bytes) + " bytes for a device buffer of " +
                      std::to_string(have));
}
template <std::size_t Bytes, class Channel>
void enqueue_write(cl::CommandQueue& queue, const cl::Buffer& buffer, const Channel& host,
                   const char* name) {
  static_assert(sizeof(typename Channel::value_type) == Bytes,
                "a host channel's element size differs from include/rtpg/guiding_layout.h");
  const std::size_t bytes = host.size() * Bytes;
  translate_cl_errors([&] {
    check_transfer_size(buffer, bytes, "upload", name);
    queue.enqueueWriteBuffer(buffer, CL_FALSE, 0, bytes, host.data());
  });
}
template <std::size_t Bytes, class Channel>
cl::Buffer wrap_channel(cl::Context& context, const Channel& host, const char* name) {
  static_assert(sizeof(typename Channel::value_type) == Bytes,
                "a host channel's element size differs from include/rtpg/guiding_layout.h");
  if (host.empty()) throw GuiderError(std::string("in-place buffer ") + name + " is empty");
  cl::Buffer b;
  translate_cl_errors([&] { b = read_in_place(context, host); });
  return b;
}
template <std::size_t Bytes, class Channel>
void enqueue_read(cl::CommandQueue& queue, const cl::Buffer& buffer, Channel& host,
                  const char* name) {
  static_assert(sizeof(typename Channel::value_type) == Bytes,
                "a host channel's element size differs from include/rtpg/guiding_layout.h");
  const std::size_t bytes = host.size() * Bytes;
  translate_cl_errors([&] {
    check_transfer_size(buffer, bytes, "download", name);
    queue.enqueueReadBuffer(buffer, CL_FALSE, 0, bytes, host.data());
  });
}
}  // namespace detail

// A channel in host memory the caller owns (mapped staging, say): what enqueue_upload and
// enqueue_download take besides std::vector.
template <class T>
struct HostChannelView {
  using value_type = T;
  T* pointer = nullptr;
  std::size_t count = 0;
  std::size_t size() const { return count; }
  T* data() const { return pointer; }
};

// Host <-> device copies of every channel, for any host struct whose members are named as the
// channels and hold them contiguously (std::vector<glm::vec4>, std::vector<uint32_t>,
// HostChannelView, ...).
// Non-blocking: the host data must live until the queue has finished them.
template <class HostGBuffer>
void enqueue_upload(cl::CommandQueue& queue, const HostGBuffer& host, const GuiderGBuffer& dev) {
#define RTPG_UPLOAD(name, type, bytes) \
  detail::enqueue_write<bytes>(queue, dev.name, host.name, #name);
  PG_GBUFFER_CHANNELS(RTPG_UPLOAD)
#undef RTPG_UPLOAD
}
template <class HostVpls>
void enqueue_upload(cl::CommandQueue& queue, const HostVpls& host, const GuiderVpls& dev) {
#define RTPG_UPLOAD(name, type, bytes) \
  detail::enqueue_write<bytes>(queue, dev.name, host.name, #name);
  PG_VPL_CHANNELS(RTPG_UPLOAD)
#undef RTPG_UPLOAD
}
// host's channels must already have their size (width * height).
// With SampleOutputs::directions the mixture's channels are left out (host's may then be empty).
template <class HostSamples>
void enqueue_download(cl::CommandQueue& queue, const GuiderSamples& dev, HostSamples& host,
                      SampleOutputs outputs = SampleOutputs::directions_and_mixture) {
#define RTPG_DOWNLOAD(name, type, bytes)                                              \
  if (outputs == SampleOutputs::directions_and_mixture || !is_mixture_channel(#name)) \
    detail::enqueue_read<bytes>(queue, dev.name, host.name, #name);
  PG_SAMPLE_CHANNELS(RTPG_DOWNLOAD)
#undef RTPG_DOWNLOAD
}

template <class HostPackedSamples>
void enqueue_download(cl::CommandQueue& queue, const GuiderPackedSamples& dev,
                      HostPackedSamples& host) {
#define RTPG_DOWNLOAD(name, type, bytes) \
  detail::enqueue_read<bytes>(queue, dev.name, host.name, #name);
  PG_PACKED_SAMPLE_CHANNELS(RTPG_DOWNLOAD)
#undef RTPG_DOWNLOAD
}

// Device buffers that read a host struct's channels in place (CL_MEM_USE_HOST_PTR) instead of
// a copy: for devices that share host memory (DeviceInfo::host_unified_memory), where nothing
// is copied; elsewhere the OpenCL implementation may copy at creation, which is correct but
// saves nothing. The device may cache the host data when the buffers are created (OpenCL 1.2,
// clCreateBuffer), so wrap the channels after the host has written them and release the
// buffers before it writes them again (host/render/guided_first_bounce.cpp does, with two
// G-buffers alternating so that last frame's stays for reproject()).
template <class HostGBuffer>
GuiderGBuffer wrap_host_gbuffer(cl::Context& context, const HostGBuffer& host) {
  GuiderGBuffer dev;
#define RTPG_WRAP(name, type, bytes) \
  dev.name = detail::wrap_channel<bytes>(context, host.name, #name);
  PG_GBUFFER_CHANNELS(RTPG_WRAP)
#undef RTPG_WRAP
  return dev;
}
template <class HostVpls>
GuiderVpls wrap_host_vpls(cl::Context& context, const HostVpls& host) {
  GuiderVpls dev;
#define RTPG_WRAP(name, type, bytes) \
  dev.name = detail::wrap_channel<bytes>(context, host.name, #name);
  PG_VPL_CHANNELS(RTPG_WRAP)
#undef RTPG_WRAP
  return dev;
}

// The statistics of the last sample() (include/rtpg/guiding_layout.h, "Counts"): surface pixels,
// those whose mixture has a Gaussian, and the sum of their pi.
struct GuiderSampleCounts {
  std::size_t surfaces = 0, guided = 0;
  double pi_sum = 0.0;
};

struct GuiderTimes {
  double reproject_ms = 0.0, sample_ms = 0.0, train_ms = 0.0;  // from profiling events
  double unpack_ms = 0.0;                                      // the last unpack_gbuffer()
  double pack_samples_ms = 0.0;                                // the last pack_samples()
  double unpack_vpls_ms = 0.0;                                 // the last unpack_vpls()
};

class KernelArgs;  // host/guiding/kernel_args.h

class Guider {
 public:
  // Throws GuiderError when the settings are out of range (validate()) or cannot run on the
  // runtime's device.
  Guider(ClRuntime& runtime, int width, int height, const GuidingSettings& settings = {});
  ~Guider();
  Guider(const Guider&) = delete;
  Guider& operator=(const Guider&) = delete;

  int width() const { return width_; }
  int height() const { return height_; }
  const GuidingSettings& settings() const { return settings_; }
  // What the kernels receive (to_kernel_settings(settings()), built once).
  const pg_kernel_settings& kernel_settings() const { return kernel_settings_; }
  bool train_uses_local_memory() const { return local_tile_; }
  // Pixels per work-item of the train kernel (settings().train_lanes, 0 resolved per device).
  int train_lanes() const { return train_lanes_; }
  // Pixels per work-item of the sample kernel (settings().sample_lanes, resolved likewise).
  int sample_lanes() const { return sample_lanes_; }
  // Whether reproject and sample run in work-groups along rows (settings().local_x and local_y
  // both 0 on a CPU device; host/cl/work_groups.h), not in tiles. Train runs in tiles.
  bool row_work_groups() const { return pixel_rows_; }

  void reset();  // every pixel back to the initial state (k = 0: BSDF sampling)

  // How a kernel call returns. Wait::finish (the default): when the kernel is done, its time in
  // last_times(). Wait::later: once it is enqueued and the queue flushed, so that a device with
  // cores of its own runs it while the host goes on; wait_for_training() (train) and
  // wait_for_kernels() (every kernel) wait for it and record its time. The guider's calls share
  // one in-order queue, so whatever it enqueues later sees what an earlier kernel wrote (the
  // trained state for reproject, sample, read_state and count_trained; the reprojected state for
  // sample), and the caller must leave every buffer a pending kernel reads or writes (and host
  // memory they wrap) untouched until it has waited.
  enum class Wait { finish, later };
  // Writes out's channels from a G-buffer the host packed (PG_PACKED_GBUFFER_CHANNELS;
  // kernels/shared/gbuffer_packing.h packs) and the frame's cameras, from which, with the depth
  // it sends, the position, the view direction and the motion vector follow (pg_gbuffer_cameras,
  // whose width and height must be the guider's): for a device with memory of its own, where
  // the packed form sends a quarter of the layout's bytes (24 of 96). out must be made with
  // KernelAccess::read_write.
  void unpack_gbuffer(const GuiderPackedGBuffer& packed, const GuiderGBuffer& out,
                      const pg_gbuffer_cameras& cameras, Wait wait = Wait::finish);
  // Writes out from samples' directions, densities and strategies (PG_PACKED_SAMPLE_CHANNELS;
  // kernels/shared/sample_packing.h unpacks): for a device with memory of its own, where the
  // host then copies 12 bytes a pixel instead of 20.
  void pack_samples(const GuiderSamples& samples, const GuiderPackedSamples& out,
                    Wait wait = Wait::finish);
  // Writes out's channels from VPLs the host packed (PG_PACKED_VPL_CHANNELS; kernels/shared/
  // vpl_packing.h packs), the G-buffer they were found from and the frame's first samples
  // (sample 0's, which the VPLs followed: their directions, densities and strategies): for a
  // device with memory of its own, where the packed form sends 10 bytes a pixel instead of 32.
  // out, and first_samples, must be made with KernelAccess::read_write.
  void unpack_vpls(const GuiderPackedVpls& packed, const GuiderGBuffer& gbuffer,
                   const GuiderSamples& first_samples, const GuiderVpls& out,
                   Wait wait = Wait::finish);
  // With rows_per_model > 1, which pixels share their group's model is decided once a frame
  // (include/rtpg/guiding_layout.h, "Shared models"): by reproject(), else by the frame's first
  // sample(); the frame's later sample() calls (the same frame, a sample_index other than 0) and
  // its train() read that decision, and train() ends the frame. So a frame's calls must all take
  // the same G-buffer, and a frame's sample() calls and train() the same frame number (they do
  // in the order above); a sample() with sample_index 0, or with another frame number, decides
  // again, and so does a train() with a frame number no sample() of the frame had.
  //
  // Carries last frame's state into this frame (previous: last frame's G-buffer). With
  // rows_per_model > 1 a pixel that shares its model is skipped: its state is the sample kernel's
  // to write, so between reproject() and sample() it holds stale contents.
  void reproject(const GuiderGBuffer& current, const GuiderGBuffer& previous,
                 Wait wait = Wait::finish);
  // Draws each pixel's first-bounce direction into out. With rows_per_model > 1 it also writes
  // the state of a pixel that shares its model: the model's, as its own.
  void sample(const GuiderGBuffer& current, std::uint32_t seed, std::uint32_t frame,
              std::uint32_t sample_index, const GuiderSamples& out,
              SampleOutputs outputs = SampleOutputs::directions_and_mixture,
              Wait wait = Wait::finish);
  void train(const GuiderGBuffer& current, const GuiderVpls& vpls, std::uint32_t seed,
             std::uint32_t frame, Wait wait = Wait::finish);
  // Waits for a train() enqueued with Wait::later (none pending: returns at once).
  void wait_for_training();
  // Waits for every kernel enqueued with Wait::later, train() included, and records their times.
  void wait_for_kernels();
  bool training_pending() const { return train_pending_; }

  // The state, PG_STATE_FLOATS_PER_PIXEL floats per pixel (state0 then state1;
  // include/rtpg/guiding_layout.h).
  void read_state(std::vector<float>& state);
  void write_state(const std::vector<float>& state);
  // Pixels whose state the last train() changed, and the counts of the last sample(): each
  // reads the kernel's records back, PG_COUNT_RECORD_BYTES per work-group (count_record_bytes).
  std::size_t count_trained();
  GuiderSampleCounts sample_counts();
  std::size_t sample_count_record_bytes() const {
    return sample_launch_.groups * PG_COUNT_RECORD_BYTES;
  }
  std::size_t train_count_record_bytes() const {
    return train_launch_.groups * PG_COUNT_RECORD_BYTES;
  }

  const GuiderTimes& last_times() const { return times_; }

 private:
  void check_gbuffer(const GuiderGBuffer& g, const char* which) const;
  void check_buffer(const cl::Buffer& b, std::size_t element_size, const std::string& name) const;
  // A kernel's launch over the image (host/cl/work_groups.h): `lanes` pixels of a row per
  // work-item; pixel_kernel: it reads its own pixels only (KernelReach::Pixel), so it may run in
  // rows.
  struct Launch {
    cl::NDRange global, local;
    std::size_t groups = 0, group_items = 0;
  };
  Launch launch_of(int lanes, bool pixel_kernel) const;
  // Launches; with Wait::finish waits and writes the profiled ms into *ms, with Wait::later
  // leaves that to wait_for_kernels().
  void run(cl::Kernel& kernel, const cl::NDRange& global, const cl::NDRange& local, Wait wait,
           double* ms);
  // The transfer kernels (unpack_gbuffer, pack_samples, unpack_vpls): one work-item a pixel over
  // the image in groups of up to 64 (any size works: each kernel checks its bound), the kernel
  // built from `file` at its first call, its arguments set by `arguments`.
  void run_per_pixel(cl::Kernel& kernel, const char* file, const char* name,
                     const std::function<void(KernelArgs&)>& arguments, Wait wait, double* ms);
  // Throws GuiderError naming `what` where `buffer` was made with `flag` (CL_MEM_READ_ONLY for a
  // buffer a kernel writes, CL_MEM_WRITE_ONLY for one it reads).
  static void require_kernel_access(const cl::Buffer& buffer, cl_mem_flags flag,
                                    const std::string& what);
  // Reads a kernel's count records (one float4 per work-group) and sums each component.
  std::array<double, 4> sum_count_records(const cl::Buffer& records, std::size_t groups);

  ClRuntime& runtime_;
  ClRuntime::Use runtime_use_{runtime_};  // the runtime must outlive this
  int width_, height_;
  GuidingSettings settings_;
  pg_kernel_settings kernel_settings_;
  bool local_tile_ = false;
  // The kernels' work-groups (host/cl/work_groups.h): reproject and sample in rows of up to
  // row_items_ work-items where pixel_rows_, else in the group_x_ x group_y_ tile that train
  // (and its VPL tile in local memory) always uses.
  bool pixel_rows_ = false;
  int row_items_ = 0;
  int group_x_ = 16, group_y_ = 16;
  int train_lanes_ = 1;
  int sample_lanes_ = 1;
  struct State {  // the mixtures of every pixel (PG_STATE_CHANNELS)
    cl::Buffer state0, state1;
  };
  State state_[2];  // reproject's source and destination (train updates the current in place)
  // The sample and train kernels' count records, one float4 per work-group of their launches.
  Launch sample_launch_, train_launch_;
  cl::Buffer sample_counts_, train_counts_;
  int current_ = 0;  // index of the buffers holding this frame's state
  // One byte per pixel (include/rtpg/guiding_layout.h, "Shared models") and who decided it for
  // the frame now running: nobody (the next kernel decides), reproject() (the next sample() or
  // train() reads it, whatever its frame number), or a sample() of frame sharing_frame_.
  cl::Buffer shares_model_;
  enum class Sharing { undecided, by_reproject, by_sample };
  Sharing sharing_ = Sharing::undecided;
  std::uint32_t sharing_frame_ = 0;
  cl::Kernel reproject_, sample_, train_;
  cl::Kernel unpack_;        // built at the first unpack_gbuffer()
  cl::Kernel pack_samples_;  // built at the first pack_samples()
  cl::Kernel unpack_vpls_;   // built at the first unpack_vpls()
  cl::Event train_done_;     // the last train() enqueued with Wait::later
  bool train_pending_ = false;
  // The other kernels enqueued with Wait::later, and where each one's time goes (in times_).
  std::vector<std::pair<cl::Event, double*>> pending_;
  std::size_t pending_before_train_ = 0;  // of pending_, those enqueued before the training
  GuiderTimes times_;
};

}  // namespace rtpg
