#include "rtpg/guider.h"

#include <algorithm>

#include "cl/work_groups.h"
#include "guiding/kernel_args.h"
#include "rtpg/image_size.h"
#include "shared/pmm.h"

namespace rtpg {
namespace {

static_assert(sizeof(pg_kernel_settings) == 25 * 4,
              "pg_kernel_settings: 25 plain 4-byte fields, no padding");
static_assert(sizeof(pg_gbuffer_cameras) == 34 * 4,
              "pg_gbuffer_cameras must hold only 4-byte fields (include/rtpg/guiding_layout.h)");
static_assert(sizeof(shared::pg_pmm_state) == 4 * PG_STATE_FLOATS_PER_PIXEL,
              "the state's floats per pixel");

std::size_t pixels(int width, int height) {
  const std::string problem = image_size_problem(width, height);
  if (!problem.empty()) throw GuiderError("guiding: resolution " + problem);
  return static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
}

// read_write, else what the kernels do with such buffers otherwise (read or write only).
cl_mem_flags kernel_access(KernelAccess access, cl_mem_flags otherwise) {
  return access == KernelAccess::read_write ? CL_MEM_READ_WRITE : otherwise;
}
}  // namespace

// What every make_guider_* does, as an expression: each channel of the channel list `list`
// (include/rtpg/guiding_layout.h) allocated for width x height pixels, with the kernels' access
// `kernel_flags` and the caller's host_flags.
#define RTPG_ALLOCATE(name, type, bytes) b.name = cl::Buffer(context, flags, n * (bytes));
#define RTPG_ALLOCATE_CHANNELS(Buffers, list, kernel_flags) \
  [&] {                                                     \
    const std::size_t n = pixels(width, height);            \
    const cl_mem_flags flags = (kernel_flags) | host_flags; \
    Buffers b;                                              \
    translate_cl_errors([&] { list(RTPG_ALLOCATE) });       \
    return b;                                               \
  }()

GuiderGBuffer make_guider_gbuffer(cl::Context& context, int width, int height,
                                  cl_mem_flags host_flags, KernelAccess access) {
  return RTPG_ALLOCATE_CHANNELS(GuiderGBuffer, PG_GBUFFER_CHANNELS,
                                kernel_access(access, CL_MEM_READ_ONLY));
}

GuiderPackedGBuffer make_guider_packed_gbuffer(cl::Context& context, int width, int height,
                                               cl_mem_flags host_flags) {
  return RTPG_ALLOCATE_CHANNELS(GuiderPackedGBuffer, PG_PACKED_GBUFFER_CHANNELS, CL_MEM_READ_ONLY);
}

GuiderPackedSamples make_guider_packed_samples(cl::Context& context, int width, int height,
                                               cl_mem_flags host_flags) {
  return RTPG_ALLOCATE_CHANNELS(GuiderPackedSamples, PG_PACKED_SAMPLE_CHANNELS, CL_MEM_WRITE_ONLY);
}

GuiderVpls make_guider_vpls(cl::Context& context, int width, int height, cl_mem_flags host_flags,
                            KernelAccess access) {
  return RTPG_ALLOCATE_CHANNELS(GuiderVpls, PG_VPL_CHANNELS,
                                kernel_access(access, CL_MEM_READ_ONLY));
}

GuiderPackedVpls make_guider_packed_vpls(cl::Context& context, int width, int height,
                                         cl_mem_flags host_flags) {
  return RTPG_ALLOCATE_CHANNELS(GuiderPackedVpls, PG_PACKED_VPL_CHANNELS, CL_MEM_READ_ONLY);
}

GuiderSamples make_guider_samples(cl::Context& context, int width, int height,
                                  cl_mem_flags host_flags, KernelAccess access) {
  return RTPG_ALLOCATE_CHANNELS(GuiderSamples, PG_SAMPLE_CHANNELS,
                                kernel_access(access, CL_MEM_WRITE_ONLY));
}
#undef RTPG_ALLOCATE_CHANNELS
#undef RTPG_ALLOCATE

Guider::Guider(ClRuntime& runtime, int width, int height, const GuidingSettings& settings)
    : runtime_(runtime),
      width_(width),
      height_(height),
      settings_(settings),
      kernel_settings_(to_kernel_settings(settings, height)) {  // validates the settings
  // settings() reports what the kernels run with: rows_per_model 0 resolved for this image.
  settings_.rows_per_model = kernel_settings_.rows_per_model;
  const std::size_t n = pixels(width, height);
  const DeviceInfo& info = runtime.info();
  const bool cpu = info.type == "cpu";
  switch (settings.train_memory) {
    case GuidingSettings::TrainMemory::Local:
      local_tile_ = true;
      break;
    case GuidingSettings::TrainMemory::Global:
      local_tile_ = false;
      break;
    case GuidingSettings::TrainMemory::Auto:
      // The VPL tile on GPUs, unless the settings ask for several pixels per work-item, which
      // read VPLs from global memory (train_wide.cl).
      local_tile_ = !cpu && settings.train_lanes <= 1;
      break;
  }
  // A GPU keeps the VPL tile and a pixel per work-item (DeviceInfo::simd_lanes).
  const int simd_lanes = info.simd_lanes();
  train_lanes_ = settings.train_lanes != 0 ? settings.train_lanes : local_tile_ ? 1 : simd_lanes;
  sample_lanes_ = settings.sample_lanes != 0 ? settings.sample_lanes : simd_lanes;
  if (train_lanes_ > 1 && local_tile_)
    throw GuiderError("guiding settings: train_lanes = " + std::to_string(train_lanes_) +
                      " reads VPLs from global memory; it cannot be combined with "
                      "train_memory = local");
  reproject_ = runtime.kernel("reproject.cl", "reproject");
  sample_ = sample_lanes_ > 1 ? runtime.kernel("sample_wide.cl", "sample_wide",
                                               "-DPG_LANES=" + std::to_string(sample_lanes_))
                              : runtime.kernel("sample.cl", "sample");
  train_ = train_lanes_ > 1
               ? runtime.kernel("train_wide.cl", "train_wide",
                                "-DPG_LANES=" + std::to_string(train_lanes_))
               : runtime.kernel("train.cl", "train",
                                std::string("-DPG_TRAIN_LOCAL_TILE=") + (local_tile_ ? "1" : "0"));

  translate_cl_errors([&] {
    const std::vector<std::size_t> max_items =
        runtime.device().getInfo<CL_DEVICE_MAX_WORK_ITEM_SIZES>();
    const std::size_t max_group =
        largest_row_group(runtime.device(), {&reproject_, &sample_, &train_});
    // Reproject and sample read their own pixel (or one gathered through the motion vector);
    // train reads a window of VPLs.
    const WorkGroupShape pixel = resolve_work_groups(info, settings.local_x, settings.local_y,
                                                     KernelReach::Pixel, max_group);
    const WorkGroupShape window = resolve_work_groups(info, settings.local_x, settings.local_y,
                                                      KernelReach::Neighbourhood, max_group);
    pixel_rows_ = pixel.rows;
    row_items_ = pixel.rows ? pixel.x : 0;
    group_x_ = window.x;
    group_y_ = window.y;
    const std::size_t group = static_cast<std::size_t>(group_x_) * group_y_;
    sample_launch_ = launch_of(sample_lanes_, /*pixel_kernel=*/true);
    train_launch_ = launch_of(train_lanes_, /*pixel_kernel=*/false);
    for (cl::Kernel* k : {&reproject_, &sample_, &train_}) {
      const std::size_t limit = k->getWorkGroupInfo<CL_KERNEL_WORK_GROUP_SIZE>(runtime.device());
      if (group > limit || static_cast<std::size_t>(group_x_) > max_items.at(0) ||
          static_cast<std::size_t>(group_y_) > max_items.at(1))
        throw GuiderError("local size " + std::to_string(group_x_) + "x" +
                          std::to_string(group_y_) + " is refused by " + info.device_name +
                          " (at most " + std::to_string(limit) + " work-items for kernel " +
                          k->getInfo<CL_KERNEL_FUNCTION_NAME>() + ")");
    }
    if (local_tile_) {
      const std::size_t tile = static_cast<std::size_t>(group_x_ + 2 * settings.apron) *
                               (group_y_ + 2 * settings.apron) * 2 * 16;
      // Plus the work-group's count records (kernels/shared/work_group_sum.h).
      const std::size_t used = train_.getWorkGroupInfo<CL_KERNEL_LOCAL_MEM_SIZE>(runtime.device()) +
                               group * PG_COUNT_RECORD_BYTES;
      if (tile + used > info.local_mem_size)
        throw GuiderError("the VPL tile (" + std::to_string(tile) + " bytes for " +
                          std::to_string(group_x_) + "x" + std::to_string(group_y_) +
                          " pixels, apron " + std::to_string(settings.apron) +
                          ") does not fit in the " + std::to_string(info.local_mem_size) +
                          " bytes of local memory of " + info.device_name);
    }
    for (State& s : state_) {
      s.state0 = cl::Buffer(runtime.context(), CL_MEM_READ_WRITE, n * 16);
      s.state1 = cl::Buffer(runtime.context(), CL_MEM_READ_WRITE, n * 16);
    }
    shares_model_ = cl::Buffer(runtime.context(), CL_MEM_READ_WRITE, n * PG_SHARES_MODEL_BYTES);
    sample_counts_ = cl::Buffer(runtime.context(), CL_MEM_READ_WRITE,
                                sample_launch_.groups * PG_COUNT_RECORD_BYTES);
    train_counts_ = cl::Buffer(runtime.context(), CL_MEM_READ_WRITE,
                               train_launch_.groups * PG_COUNT_RECORD_BYTES);
  });
  reset();
}

Guider::~Guider() = default;

void Guider::reset() {
  // Zeros written from the host, not clEnqueueFillBuffer: Oclgrind 21.10 keeps treating filled
  // memory as uninitialised even after a kernel has overwritten it, so every later kernel that
  // reads the state is flagged under --uninitialized (a false positive hiding real findings).
  const std::size_t n = static_cast<std::size_t>(width_) * height_;
  const std::vector<float> zeros(
      std::max(n, std::max(sample_launch_.groups, train_launch_.groups)) * 4, 0.0f);
  translate_cl_errors([&] {
    // Blocking writes: the host vector must outlive them, also when one of them fails and the
    // exception unwinds past it (a non-blocking write would go on reading freed memory).
    for (State& s : state_) {
      runtime_.queue().enqueueWriteBuffer(s.state0, CL_TRUE, 0, n * 16, zeros.data());
      runtime_.queue().enqueueWriteBuffer(s.state1, CL_TRUE, 0, n * 16, zeros.data());
    }
    // No counts before the first sample() and train().
    runtime_.queue().enqueueWriteBuffer(sample_counts_, CL_TRUE, 0, sample_count_record_bytes(),
                                        zeros.data());
    runtime_.queue().enqueueWriteBuffer(train_counts_, CL_TRUE, 0, train_count_record_bytes(),
                                        zeros.data());
    // No pixel shares before a kernel decides (and a kernel that read the flags undecided would
    // read zeros, not uninitialised memory, under Oclgrind).
    runtime_.queue().enqueueWriteBuffer(shares_model_, CL_TRUE, 0, n * PG_SHARES_MODEL_BYTES,
                                        zeros.data());
  });
  sharing_ = Sharing::undecided;
}

void Guider::check_buffer(const cl::Buffer& b, std::size_t element_size,
                          const std::string& name) const {
  const std::size_t need = element_size * static_cast<std::size_t>(width_) * height_;
  if (b() == nullptr) throw GuiderError(name + ": buffer is not set");
  // Another context's buffer is undefined in OpenCL (under an ICD loader, another driver's).
  if (translate_cl_errors([&] { return b.getInfo<CL_MEM_CONTEXT>()(); }) != runtime_.context()())
    throw GuiderError(name + ": buffer belongs to another OpenCL context");
  const std::size_t have = translate_cl_errors([&] { return b.getInfo<CL_MEM_SIZE>(); });
  // Exactly: a larger buffer is another resolution's, whose rows this guider would misread.
  if (have != need)
    throw GuiderError(name + ": buffer holds " + std::to_string(have) + " bytes, " +
                      std::to_string(width_) + "x" + std::to_string(height_) + " pixels need " +
                      std::to_string(need));
}

void Guider::check_gbuffer(const GuiderGBuffer& g, const char* which) const {
  const std::string w(which);
#define RTPG_CHECK(name, type, bytes) check_buffer(g.name, bytes, w + "." #name);
  PG_GBUFFER_CHANNELS(RTPG_CHECK)
#undef RTPG_CHECK
}

Guider::Launch Guider::launch_of(int lanes, bool pixel_kernel) const {
  const WorkGroupShape shape = pixel_kernel && pixel_rows_
                                   ? WorkGroupShape{true, row_items_, 1}
                                   : WorkGroupShape{false, group_x_, group_y_};
  const ImageLaunch launch = image_launch(width_, height_, lanes, shape);
  Launch l{launch.global, launch.local, 1, 1};
  for (int d = 0; d < 2; ++d) {
    l.groups *= launch.global[d] / launch.local[d];
    l.group_items *= launch.local[d];
  }
  return l;
}

void Guider::run(cl::Kernel& kernel, const cl::NDRange& global, const cl::NDRange& local, Wait wait,
                 double* ms) {
  cl::Event done;
  runtime_.queue().enqueueNDRangeKernel(kernel, cl::NullRange, global, local, nullptr, &done);
  if (wait == Wait::later) {
    runtime_.queue().flush();  // so that it starts now, not at the next blocking call
    pending_.emplace_back(done, ms);
    return;
  }
  done.wait();
  *ms = ClRuntime::event_ms(done);
}

std::array<double, 4> Guider::sum_count_records(const cl::Buffer& records, std::size_t groups) {
  std::vector<float> r(groups * 4);
  translate_cl_errors([&] {
    runtime_.queue().enqueueReadBuffer(records, CL_TRUE, 0, groups * PG_COUNT_RECORD_BYTES,
                                       r.data());
  });
  std::array<double, 4> sum{};
  for (std::size_t g = 0; g < groups; ++g)
    for (int c = 0; c < 4; ++c) sum[c] += r[g * 4 + c];
  return sum;
}

void Guider::run_per_pixel(cl::Kernel& kernel, const char* file, const char* name,
                           const std::function<void(KernelArgs&)>& arguments, Wait wait,
                           double* ms) {
  if (kernel() == nullptr) kernel = runtime_.kernel(file, name);
  KernelArgs args(kernel);
  arguments(args);
  const std::size_t n = static_cast<std::size_t>(width_) * height_;
  const std::size_t group = std::min<std::size_t>(
      64, kernel.getWorkGroupInfo<CL_KERNEL_WORK_GROUP_SIZE>(runtime_.device()));
  run(kernel, cl::NDRange((n + group - 1) / group * group), cl::NDRange(group), wait, ms);
}

void Guider::require_kernel_access(const cl::Buffer& buffer, cl_mem_flags flag,
                                   const std::string& what) {
  translate_cl_errors([&] {
    if (buffer.getInfo<CL_MEM_FLAGS>() & flag)
      throw GuiderError(what + " (made without KernelAccess::read_write)");
  });
}

void Guider::unpack_gbuffer(const GuiderPackedGBuffer& packed, const GuiderGBuffer& out,
                            const pg_gbuffer_cameras& cameras, Wait wait) {
#define RTPG_CHECK(name, type, bytes) check_buffer(packed.name, bytes, "packed." #name);
  PG_PACKED_GBUFFER_CHANNELS(RTPG_CHECK)
#undef RTPG_CHECK
  check_gbuffer(out, "unpacked");
  if (cameras.width != width_ || cameras.height != height_)
    throw GuiderError("unpack_gbuffer: the cameras' image is " + std::to_string(cameras.width) +
                      "x" + std::to_string(cameras.height) + ", the guider's " +
                      std::to_string(width_) + "x" + std::to_string(height_));
  require_kernel_access(out.position_depth, CL_MEM_READ_ONLY,
                        "unpack_gbuffer: the G-buffer to write is read-only for kernels");
  sharing_ = Sharing::undecided;  // a new G-buffer: a new frame's decision
  translate_cl_errors([&] {
    run_per_pixel(
        unpack_, "unpack_gbuffer.cl", "unpack_gbuffer",
        [&](KernelArgs& args) {
#define RTPG_ARG(name, type, bytes) args << packed.name;
          PG_PACKED_GBUFFER_CHANNELS(RTPG_ARG)
#undef RTPG_ARG
          args << out << static_cast<cl_uint>(static_cast<std::size_t>(width_) * height_)
               << cameras;
        },
        wait, &times_.unpack_ms);
  });
}

void Guider::pack_samples(const GuiderSamples& samples, const GuiderPackedSamples& out, Wait wait) {
#define RTPG_CHECK(name, type, bytes) check_buffer(samples.name, bytes, "samples." #name);
  PG_SAMPLE_CHANNELS(RTPG_CHECK)
#undef RTPG_CHECK
#define RTPG_CHECK(name, type, bytes) check_buffer(out.name, bytes, "packed." #name);
  PG_PACKED_SAMPLE_CHANNELS(RTPG_CHECK)
#undef RTPG_CHECK
  require_kernel_access(samples.direction_pdf, CL_MEM_WRITE_ONLY,
                        "pack_samples: the samples are write-only for kernels");
  translate_cl_errors([&] {
    run_per_pixel(
        pack_samples_, "pack_samples.cl", "pack_samples",
        [&](KernelArgs& args) {
          args << samples;
#define RTPG_ARG(name, type, bytes) args << out.name;
          PG_PACKED_SAMPLE_CHANNELS(RTPG_ARG)
#undef RTPG_ARG
          args << static_cast<cl_uint>(static_cast<std::size_t>(width_) * height_);
        },
        wait, &times_.pack_samples_ms);
  });
}

void Guider::unpack_vpls(const GuiderPackedVpls& packed, const GuiderGBuffer& gbuffer,
                         const GuiderSamples& first_samples, const GuiderVpls& out, Wait wait) {
  check_gbuffer(gbuffer, "gbuffer");
#define RTPG_CHECK(name, type, bytes) check_buffer(packed.name, bytes, "packed." #name);
  PG_PACKED_VPL_CHANNELS(RTPG_CHECK)
#undef RTPG_CHECK
#define RTPG_CHECK(name, type, bytes) \
  check_buffer(first_samples.name, bytes, "first_samples." #name);
  PG_SAMPLE_CHANNELS(RTPG_CHECK)
#undef RTPG_CHECK
#define RTPG_CHECK(name, type, bytes) check_buffer(out.name, bytes, "unpacked." #name);
  PG_VPL_CHANNELS(RTPG_CHECK)
#undef RTPG_CHECK
  require_kernel_access(out.position, CL_MEM_READ_ONLY,
                        "unpack_vpls: the VPLs to write are read-only for kernels");
  require_kernel_access(first_samples.direction_pdf, CL_MEM_WRITE_ONLY,
                        "unpack_vpls: the first samples are write-only for kernels");
  translate_cl_errors([&] {
    run_per_pixel(
        unpack_vpls_, "unpack_vpls.cl", "unpack_vpls",
        [&](KernelArgs& args) {
          args << gbuffer;
#define RTPG_ARG(name, type, bytes) args << packed.name;
          PG_PACKED_VPL_CHANNELS(RTPG_ARG)
#undef RTPG_ARG
          args << first_samples << out
               << static_cast<cl_uint>(static_cast<std::size_t>(width_) * height_);
        },
        wait, &times_.unpack_vpls_ms);
  });
}

void Guider::reproject(const GuiderGBuffer& current, const GuiderGBuffer& previous, Wait wait) {
  check_gbuffer(current, "current");
  check_gbuffer(previous, "previous");
  const State &from = state_[current_], &to = state_[1 - current_];
  translate_cl_errors([&] {
    KernelArgs(reproject_) << current << previous << from.state0 << from.state1 << to.state0
                           << to.state1 << shares_model_ << static_cast<cl_uint>(width_)
                           << static_cast<cl_uint>(height_) << kernel_settings_;
    const Launch launch = launch_of(1, /*pixel_kernel=*/true);
    run(reproject_, launch.global, launch.local, wait, &times_.reproject_ms);
  });
  current_ = 1 - current_;
  sharing_ = Sharing::by_reproject;
}

void Guider::sample(const GuiderGBuffer& current, std::uint32_t seed, std::uint32_t frame,
                    std::uint32_t sample_index, const GuiderSamples& out, SampleOutputs outputs,
                    Wait wait) {
  check_gbuffer(current, "current");
#define RTPG_CHECK(name, type, bytes) check_buffer(out.name, bytes, "samples." #name);
  PG_SAMPLE_CHANNELS(RTPG_CHECK)
#undef RTPG_CHECK
  const State& state = state_[current_];
  // The frame's decision of which pixels share a model (guider.h, above reproject()).
  const bool decided =
      sharing_ == Sharing::by_reproject ||
      (sharing_ == Sharing::by_sample && sharing_frame_ == frame && sample_index != 0);
  translate_cl_errors([&] {
    const cl_uint write_mixture = outputs == SampleOutputs::directions_and_mixture ? 1 : 0;
    KernelArgs(sample_) << current << state.state0 << state.state1 << out << shares_model_
                        << sample_counts_ << static_cast<cl_uint>(width_)
                        << static_cast<cl_uint>(height_) << static_cast<cl_uint>(seed)
                        << static_cast<cl_uint>(frame) << static_cast<cl_uint>(sample_index)
                        << write_mixture << static_cast<cl_uint>(decided ? 1 : 0)
                        << kernel_settings_
                        << cl::Local(sample_launch_.group_items * PG_COUNT_RECORD_BYTES);
    run(sample_, sample_launch_.global, sample_launch_.local, wait, &times_.sample_ms);
  });
  sharing_ = Sharing::by_sample;
  sharing_frame_ = frame;
}

void Guider::train(const GuiderGBuffer& current, const GuiderVpls& vpls, std::uint32_t seed,
                   std::uint32_t frame, Wait wait) {
  wait_for_training();  // its time is recorded before this one's
  check_gbuffer(current, "current");
#define RTPG_CHECK(name, type, bytes) check_buffer(vpls.name, bytes, "vpls." #name);
  PG_VPL_CHANNELS(RTPG_CHECK)
#undef RTPG_CHECK
  // In place (kernels/train.cl): a pixel that does not train this frame costs no state traffic.
  const State& state = state_[current_];
  const std::size_t tile = local_tile_ ? static_cast<std::size_t>(group_x_ + 2 * settings_.apron) *
                                             (group_y_ + 2 * settings_.apron) * 16
                                       : 16;
  const bool decided = sharing_ == Sharing::by_reproject ||
                       (sharing_ == Sharing::by_sample && sharing_frame_ == frame);
  sharing_ = Sharing::undecided;  // the frame ends here
  translate_cl_errors([&] {
    KernelArgs args(train_);
    args << current << vpls << state.state0 << state.state1 << shares_model_ << train_counts_
         << static_cast<cl_uint>(width_) << static_cast<cl_uint>(height_)
         << static_cast<cl_uint>(seed) << static_cast<cl_uint>(frame)
         << static_cast<cl_uint>(decided ? 1 : 0) << kernel_settings_;
    if (train_lanes_ == 1) args << cl::Local(tile) << cl::Local(tile);
    args << cl::Local(train_launch_.group_items * PG_COUNT_RECORD_BYTES);
    if (wait == Wait::finish) {
      run(train_, train_launch_.global, train_launch_.local, wait, &times_.train_ms);
      return;
    }
    runtime_.queue().enqueueNDRangeKernel(train_, cl::NullRange, train_launch_.global,
                                          train_launch_.local, nullptr, &train_done_);
    runtime_.queue().flush();  // so that it starts now, not at the next blocking call
    train_pending_ = true;
    pending_before_train_ = pending_.size();
  });
}

void Guider::wait_for_training() {
  if (!train_pending_) return;
  train_pending_ = false;
  translate_cl_errors([&] {
    train_done_.wait();
    times_.train_ms = ClRuntime::event_ms(train_done_);
    // What was enqueued before the training (unpack_vpls, its input) is done too: the queue is
    // in order. Its times are recorded and its events released here, so that a caller who only
    // ever waits for the training does not collect them frame after frame.
    for (std::size_t k = 0; k < pending_before_train_; ++k)
      *pending_[k].second = ClRuntime::event_ms(pending_[k].first);
    pending_.erase(pending_.begin(),
                   pending_.begin() + static_cast<std::ptrdiff_t>(pending_before_train_));
    pending_before_train_ = 0;
  });
}

void Guider::wait_for_kernels() {
  wait_for_training();
  // The list is emptied whatever happens: a kernel that failed is reported once, not again by
  // every later wait.
  auto pending = std::move(pending_);
  pending_.clear();
  translate_cl_errors([&] {
    for (auto& [done, ms] : pending) {
      done.wait();
      *ms = ClRuntime::event_ms(done);
    }
  });
}

void Guider::read_state(std::vector<float>& state) {
  const std::size_t n = static_cast<std::size_t>(width_) * height_;
  std::vector<float> s0(n * 4), s1(n * 4);
  translate_cl_errors([&] {
    // Both blocking: were the first left running, a failure of the second would free s0 under
    // it.
    runtime_.queue().enqueueReadBuffer(state_[current_].state0, CL_TRUE, 0, n * 16, s0.data());
    runtime_.queue().enqueueReadBuffer(state_[current_].state1, CL_TRUE, 0, n * 16, s1.data());
  });
  state.resize(n * PG_STATE_FLOATS_PER_PIXEL);
  for (std::size_t i = 0; i < n; ++i)
    for (int c = 0; c < 4; ++c) {
      state[i * 8 + c] = s0[i * 4 + c];
      state[i * 8 + 4 + c] = s1[i * 4 + c];
    }
}

void Guider::write_state(const std::vector<float>& state) {
  const std::size_t n = static_cast<std::size_t>(width_) * height_;
  if (state.size() != n * PG_STATE_FLOATS_PER_PIXEL)
    throw GuiderError("write_state: " + std::to_string(state.size()) + " floats given, " +
                      std::to_string(n * PG_STATE_FLOATS_PER_PIXEL) + " needed (" +
                      std::to_string(PG_STATE_FLOATS_PER_PIXEL) + " per pixel)");
  std::vector<float> s0(n * 4), s1(n * 4);
  for (std::size_t i = 0; i < n; ++i)
    for (int c = 0; c < 4; ++c) {
      s0[i * 4 + c] = state[i * 8 + c];
      s1[i * 4 + c] = state[i * 8 + 4 + c];
    }
  translate_cl_errors([&] {
    // Both blocking, as in read_state.
    runtime_.queue().enqueueWriteBuffer(state_[current_].state0, CL_TRUE, 0, n * 16, s0.data());
    runtime_.queue().enqueueWriteBuffer(state_[current_].state1, CL_TRUE, 0, n * 16, s1.data());
  });
}

std::size_t Guider::count_trained() {
  return static_cast<std::size_t>(sum_count_records(train_counts_, train_launch_.groups)[0]);
}

GuiderSampleCounts Guider::sample_counts() {
  const std::array<double, 4> sum = sum_count_records(sample_counts_, sample_launch_.groups);
  return GuiderSampleCounts{static_cast<std::size_t>(sum[0]), static_cast<std::size_t>(sum[1]),
                            sum[2]};
}

}  // namespace rtpg
