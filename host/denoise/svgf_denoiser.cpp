#include "denoise/svgf_denoiser.h"

#include <chrono>
#include <cstring>
#include <initializer_list>

#include "render/host_transfer.h"
#include "render/pinned_staging.h"
#include "denoise/svgf_reference.h"
#include "rtpg/cl_error.h"
#include "rtpg/errors.h"
#include "rtpg/image_size.h"

namespace rtpg {
namespace {

static_assert(sizeof(shared::pg_svgf_settings) == 12 * 4, "pg_svgf_settings: 4-byte fields only");
static_assert(sizeof(shared::pg_svgf_view) == 10 * 4, "pg_svgf_view: 4-byte fields only");
static_assert(sizeof(glm::vec4) == sizeof(cl_float4), "glm::vec4 must match cl_float4");
static_assert(sizeof(glm::vec3) == 3 * sizeof(cl_float), "glm::vec3 must be three packed floats");

// Bytes per pixel the upload of one frame copies: colour (12: the renderer's image, three floats
// a pixel), emission, position_depth, shading_normal, base_color_roughness (16 each), flags,
// material (4 each), motion (8); only the first two where the G-buffer is on the device already.
constexpr std::size_t kColourBytesPerPixel = 12;
constexpr double kUploadBytesPerPixel = kColourBytesPerPixel + 4 * 16 + 4 + 4 + 8;
constexpr double kColourUploadBytesPerPixel = kColourBytesPerPixel + 16;
constexpr std::size_t kUploadChannels = 8;
constexpr double kDownloadBytesPerPixel = kColourBytesPerPixel;

using BufferList = std::initializer_list<const cl::Buffer*>;

}  // namespace

SvgfDenoiser::SvgfDenoiser(ClRuntime& runtime, int width, int height, const SvgfSettings& settings,
                           bool zero_copy)
    : runtime_(runtime),
      width_(width),
      height_(height),
      settings_(settings),
      zero_copy_(zero_copy && resolve_host_transfer(HostTransfer::automatic,
                                                    runtime.info().host_unified_memory) ==
                                  HostTransfer::in_place),
      upload_bytes_per_pixel_(zero_copy_ ? 0.0 : kUploadBytesPerPixel) {
  validate(settings);
  const std::string size_problem = image_size_problem(width, height);
  if (!size_problem.empty()) throw InputError("svgf", "image size " + size_problem);
  kernel_settings_ = to_kernel_settings(settings);
  // The filters' edge-stopping weights run through exp() down into float's denormal range (a
  // tap's weight ~1e-20 squared for the variance), where x86 cores take a slow path per
  // operation: denormals flushed to zero made the a-trous pass 3.9x faster on Sponza and change
  // no output above 1e-37 (docs/denoising.md, "Denormals"). An OpenCL 1.2 build option, a hint
  // any device may ignore; the guiding kernels keep denormals (their host references carry a
  // decaying sample count through that range).
  // sigma_n, the normal weight's exponent, is a build option of every SVGF kernel (the filters
  // square it out in straight-line code: kernels/shared/svgf.h, PG_SVGF_CONSTANT_POWER).
  const std::string options =
      "-cl-denorms-are-zero -DPG_SVGF_PHI_NORMAL=" + std::to_string(settings.phi_normal);
  temporal_ = runtime.kernel("svgf_temporal.cl", "svgf_temporal", options);
  lanes_ = settings.lanes != 0 ? settings.lanes : runtime.info().simd_lanes();
  const std::string wide_options = options + " -DPG_LANES=" + std::to_string(lanes_);
  variance_ = lanes_ > 1
                  ? runtime.kernel("svgf_variance_wide.cl", "svgf_variance_wide", wide_options)
                  : runtime.kernel("svgf_variance.cl", "svgf_variance", options);
  // One build per kernel radius (a build option, so that the tap loops stay unrolled): the
  // iterations up to the history iteration and those after it may differ.
  const auto atrous_kernel = [&](int radius) {
    const std::string r = " -DPG_SVGF_ATROUS_RADIUS=" + std::to_string(radius);
    return lanes_ > 1 ? runtime.kernel("svgf_atrous_wide.cl", "svgf_atrous_wide", wide_options + r)
                      : runtime.kernel("svgf_atrous.cl", "svgf_atrous", options + r);
  };
  atrous_ = atrous_kernel(settings.atrous_radius);
  history_atrous_ = settings.history_atrous_radius == settings.atrous_radius
                        ? atrous_
                        : atrous_kernel(settings.history_atrous_radius);
  remodulate_ = runtime.kernel("svgf_remodulate.cl", "svgf_remodulate", options);
  const std::size_t n = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  translate_cl_errors([&] {
    const std::vector<std::size_t> max_items =
        runtime.device().getInfo<CL_DEVICE_MAX_WORK_ITEM_SIZES>();
    const std::size_t max_group = largest_row_group(
        runtime.device(), {&temporal_, &variance_, &atrous_, &history_atrous_, &remodulate_});
    // Temporal and remodulate read their own pixel (temporal also the bilinear taps of one
    // back-projected position); variance and a-trous filter neighbourhoods, from global memory.
    pixel_groups_ = resolve_work_groups(runtime.info(), settings.local_x, settings.local_y,
                                        KernelReach::Pixel, max_group);
    filter_groups_ = resolve_work_groups(runtime.info(), settings.local_x, settings.local_y,
                                         KernelReach::GlobalNeighbourhood, max_group);
    const std::size_t group = static_cast<std::size_t>(filter_groups_.x) * filter_groups_.y;
    for (cl::Kernel* k : {&temporal_, &variance_, &atrous_, &history_atrous_, &remodulate_}) {
      const std::size_t limit = k->getWorkGroupInfo<CL_KERNEL_WORK_GROUP_SIZE>(runtime.device());
      if (group > limit || static_cast<std::size_t>(filter_groups_.x) > max_items.at(0) ||
          static_cast<std::size_t>(filter_groups_.y) > max_items.at(1))
        throw InputError("svgf settings", "local size " + std::to_string(filter_groups_.x) + "x" +
                                              std::to_string(filter_groups_.y) + " is refused by " +
                                              runtime.info().device_name + " (at most " +
                                              std::to_string(limit) + " work-items for kernel " +
                                              k->getInfo<CL_KERNEL_FUNCTION_NAME>() + ")");
    }
    const cl::Context& c = runtime.context();
    // The images only the device reads and writes; where it shares the host's memory, in host
    // memory it uses in place, whose large arrays are in huge pages (PoCL's own allocations are
    // in 4 KiB pages; docs/denoising.md, "The denoiser's images in huge pages"). host_images_ may
    // grow: moving a LargeVector keeps its storage where it is.
    auto buffer = [&](std::size_t bytes) {
      if (!zero_copy_) return cl::Buffer(c, CL_MEM_READ_WRITE, n * bytes);
      LargeVector<glm::vec4>& storage = host_images_.emplace_back((n * bytes + 15) / 16);
      return cl::Buffer(c, CL_MEM_READ_WRITE | CL_MEM_USE_HOST_PTR, n * bytes, storage.data());
    };
    for (Surfaces& s : surfaces_) {
      s.position_depth = buffer(16);
      s.shading_normal = buffer(16);
      s.material = buffer(4);
    }
    for (cl::Buffer& b : moments_) b = buffer(16);
    for (cl::Buffer& b : illumination_) b = buffer(16);
    if (!zero_copy_) {  // else denoise() reads these in place
      colour_ = buffer(kColourBytesPerPixel);
      emission_ = buffer(16);
      position_depth_ = buffer(16);
      shading_normal_ = buffer(16);
      base_color_roughness_ = buffer(16);
      flags_ = buffer(4);
      material_ = buffer(4);
      motion_ = buffer(8);
    }
    surface_ = buffer(16);
    depth_slope_ = buffer(4);
    integrated_ = buffer(16);
    history_ = buffer(16);
    // Where memory is shared, remodulate writes the host's output image in place (mapped after
    // the kernel: OpenCL 1.2 gives the mapped pointer from host_ptr); elsewhere it is read back.
    output_host_.resize(n);
    output_ = zero_copy_ ? cl::Buffer(c, CL_MEM_WRITE_ONLY | CL_MEM_USE_HOST_PTR,
                                      n * kColourBytesPerPixel, output_host_.data())
                         : buffer(kColourBytesPerPixel);
  });
  if (!zero_copy_)
    staging_ = std::make_unique<PinnedStaging>(
        runtime.context(), runtime.queue(),
        static_cast<std::size_t>(kUploadBytesPerPixel + 0.5) * n, kUploadChannels);
}

double SvgfDenoiser::run(cl::Kernel& kernel, int lanes, const WorkGroupShape& shape) {
  const ImageLaunch launch = image_launch(width_, height_, lanes, shape);
  cl::Event done;
  runtime_.queue().enqueueNDRangeKernel(kernel, cl::NullRange, launch.global, launch.local, nullptr,
                                        &done);
  done.wait();
  return ClRuntime::event_ms(done);
}

SvgfDenoiser::~SvgfDenoiser() {
  try {
    unmap_output();
  } catch (...) {  // a failing unmap at teardown leaves the finish below to do
  }
  try {
    runtime_.queue().finish();  // kernels still reading the caller's images finish first
  } catch (...) {               // a failing queue at teardown has nothing left to corrupt
  }
}

void SvgfDenoiser::unmap_output() {
  if (mapped_output_ == nullptr) return;
  void* mapped = mapped_output_;
  mapped_output_ = nullptr;
  translate_cl_errors([&] { runtime_.queue().enqueueUnmapMemObject(output_, mapped); });
}

const std::vector<glm::vec3>& SvgfDenoiser::denoise(const std::vector<glm::vec3>& colour,
                                                    const GBuffer& g,
                                                    const GuiderGBuffer* on_device) {
  check_svgf_input(width_, height_, colour, g);
  using Clock = std::chrono::steady_clock;
  const auto ms_since = [](Clock::time_point t) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
  };
  times_.clear();
  unmap_output();  // remodulate writes it again
  const cl_uint w = static_cast<cl_uint>(width_), h = static_cast<cl_uint>(height_);
  const Surfaces& cur = surfaces_[current_];
  const Surfaces& prev = surfaces_[1 - current_];
  // The inputs the kernels read: the owned buffers the host copies into, or the host's memory.
  // The temporal pass keeps position, normal and material in `cur` for next frame's history test.
  cl::Buffer colour_in = colour_, emission_in = emission_, position_depth_in = position_depth_,
             shading_normal_in = shading_normal_, base_color_roughness_in = base_color_roughness_,
             flags_in = flags_, material_in = material_, motion_in = motion_;
  translate_cl_errors([&] {
    const auto start = Clock::now();
    if (zero_copy_) {
      const cl::Context& c = runtime_.context();
      colour_in = read_in_place(c, colour);
      emission_in = read_in_place(c, g.emission);
      position_depth_in = read_in_place(c, g.position_depth);
      shading_normal_in = read_in_place(c, g.shading_normal);
      base_color_roughness_in = read_in_place(c, g.base_color_roughness);
      flags_in = read_in_place(c, g.flags);
      material_in = read_in_place(c, g.material);
      motion_in = read_in_place(c, g.motion);
    } else {
      // Through pinned staging: a discrete GPU copies from it several times faster than from
      // the host's vectors (host/render/pinned_staging.h).
      staging_->begin();
      staging_->stage(colour, colour_, "svgf colour");
      staging_->stage(g.emission, emission_, "svgf emission");
      if (on_device != nullptr) {
        const std::size_t n = static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_);
        const auto check = [&](const cl::Buffer& b, std::size_t bytes, const char* name) {
          // Exactly the image's size, as the Guider asks: a larger buffer is another image,
          // whose rows the kernels would read at this one's width.
          if (b.getInfo<CL_MEM_SIZE>() != n * bytes)
            throw InputError("svgf", std::string("the device G-buffer's ") + name + " holds " +
                                         std::to_string(b.getInfo<CL_MEM_SIZE>()) + " bytes, not " +
                                         std::to_string(n * bytes));
          if (b.getInfo<CL_MEM_CONTEXT>()() != runtime_.context()())
            throw InputError("svgf", std::string("the device G-buffer's ") + name +
                                         " belongs to another OpenCL context");
          return b;
        };
        position_depth_in = check(on_device->position_depth, 16, "position_depth");
        shading_normal_in = check(on_device->shading_normal, 16, "shading_normal");
        base_color_roughness_in =
            check(on_device->base_color_roughness, 16, "base_color_roughness");
        flags_in = check(on_device->flags, 4, "flags");
        material_in = check(on_device->material, 4, "material");
        motion_in = check(on_device->motion, 8, "motion");
        upload_bytes_per_pixel_ = kColourUploadBytesPerPixel;
      } else {
        staging_->stage(g.position_depth, position_depth_, "svgf position_depth");
        staging_->stage(g.shading_normal, shading_normal_, "svgf shading_normal");
        staging_->stage(g.base_color_roughness, base_color_roughness_, "svgf base_color_roughness");
        staging_->stage(g.flags, flags_, "svgf flags");
        staging_->stage(g.material, material_, "svgf material");
        staging_->stage(g.motion, motion_, "svgf motion");
        upload_bytes_per_pixel_ = kUploadBytesPerPixel;
      }
    }
    runtime_.queue().finish();  // the host vectors may change once denoise() returns
    times_["svgf_upload"] = ms_since(start);

    int a = 0;
    for (const cl::Buffer* b : BufferList{&colour_in,
                                          &emission_in,
                                          &position_depth_in,
                                          &shading_normal_in,
                                          &base_color_roughness_in,
                                          &flags_in,
                                          &material_in,
                                          &motion_in,
                                          &prev.position_depth,
                                          &prev.shading_normal,
                                          &prev.material,
                                          &history_,
                                          &moments_[1 - current_],
                                          &surface_,
                                          &depth_slope_,
                                          &integrated_,
                                          &moments_[current_],
                                          &cur.position_depth,
                                          &cur.shading_normal,
                                          &cur.material})
      temporal_.setArg(a++, *b);
    temporal_.setArg(a++, w);
    temporal_.setArg(a++, h);
    temporal_.setArg(a++, static_cast<cl_uint>(has_history_ ? 1 : 0));
    temporal_.setArg(a++, kernel_settings_);
    temporal_.setArg(a++, to_svgf_view(g.camera, height_));
    times_["svgf_temporal"] = run(temporal_, 1, pixel_groups_);

    a = 0;
    for (const cl::Buffer* b :
         BufferList{&integrated_, &moments_[current_], &surface_, &depth_slope_, &illumination_[2]})
      variance_.setArg(a++, *b);
    variance_.setArg(a++, w);
    variance_.setArg(a++, h);
    variance_.setArg(a++, kernel_settings_);
    times_["svgf_variance"] = run(variance_, lanes_, filter_groups_);

    double atrous_ms = 0.0;
    // Iteration k reads the variance pass's output (k = 0) or iteration k - 1's, and writes
    // illumination_[k % 2], or history_ for the iteration whose output the next frame keeps
    // (written in place: no copy).
    const cl::Buffer* in = &illumination_[2];
    for (int k = 0; k < settings_.iterations; ++k) {
      const cl::Buffer* out = k == settings_.history_iteration ? &history_ : &illumination_[k % 2];
      cl::Kernel& atrous = k <= settings_.history_iteration ? history_atrous_ : atrous_;
      atrous.setArg(0, *in);
      atrous.setArg(1, *out);
      atrous.setArg(2, surface_);
      atrous.setArg(3, depth_slope_);
      atrous.setArg(4, w);
      atrous.setArg(5, h);
      atrous.setArg(6, static_cast<cl_int>(1 << k));
      atrous.setArg(7, kernel_settings_);
      atrous_ms += run(atrous, lanes_, filter_groups_);
      in = out;
    }
    filtered_ = in;
    times_["svgf_atrous"] = atrous_ms;

    a = 0;
    for (const cl::Buffer* b : BufferList{filtered_, &colour_in, &emission_in,
                                          &base_color_roughness_in, &flags_in, &output_})
      remodulate_.setArg(a++, *b);
    remodulate_.setArg(a++, w);
    remodulate_.setArg(a++, h);
    remodulate_.setArg(a++, kernel_settings_);
    times_["svgf_remodulate"] = run(remodulate_, 1, pixel_groups_);

    const auto download = Clock::now();
    const std::size_t bytes = output_host_.size() * kColourBytesPerPixel;
    if (zero_copy_) {
      // Mapped for reading until the next denoise(), so that the host reads output_host_ only
      // between map and unmap, as OpenCL 1.2 asks of a CL_MEM_USE_HOST_PTR buffer. Nothing is
      // copied where the mapped pointer is output_host_ (OpenCL 1.2 promises one derived from
      // host_ptr; the memcpy keeps a device that hands back another one correct).
      mapped_output_ = runtime_.queue().enqueueMapBuffer(output_, CL_TRUE, CL_MAP_READ, 0, bytes);
      if (mapped_output_ != static_cast<void*>(output_host_.data()))
        std::memcpy(output_host_.data(), mapped_output_, bytes);
    } else {
      runtime_.queue().enqueueReadBuffer(output_, CL_TRUE, 0, bytes, output_host_.data());
    }
    times_["svgf_download"] = ms_since(download);
  });
  double total = 0.0;
  for (const auto& [name, ms] : times_) total += ms;
  times_["svgf_total"] = total;
  current_ = 1 - current_;
  has_history_ = true;
  return output_host_;
}

double SvgfDenoiser::host_device_bytes_per_pixel() const {
  // In place, remodulate writes the host's output: nothing comes back.
  return upload_bytes_per_pixel_ + (zero_copy_ ? 0.0 : kDownloadBytesPerPixel);
}

std::vector<glm::vec4> SvgfDenoiser::read(SvgfStage stage) {
  if (filtered_ == nullptr) throw InputError("svgf", "no frame has been denoised yet");
  const cl::Buffer* b = &output_;
  // After denoise() current_ points at the next frame: last frame's moments are the other one.
  switch (stage) {
    case SvgfStage::Surface:
      b = &surface_;
      break;
    case SvgfStage::Integrated:
      b = &integrated_;
      break;
    case SvgfStage::Moments:
      b = &moments_[1 - current_];
      break;
    case SvgfStage::Illumination:
      b = &illumination_[2];
      break;
    case SvgfStage::Filtered:
      b = filtered_;
      break;
    case SvgfStage::History:
      b = &history_;
      break;
    case SvgfStage::Output:
      break;
  }
  const std::size_t n = static_cast<std::size_t>(width_) * height_;
  const std::size_t channels = stage == SvgfStage::Output ? 3 : 4;
  std::vector<float> floats(channels * n);
  translate_cl_errors([&] {
    runtime_.queue().enqueueReadBuffer(*b, CL_TRUE, 0, n * channels * sizeof(float), floats.data());
  });
  std::vector<glm::vec4> out(n);
  if (stage == SvgfStage::Output) {  // three floats per pixel, returned with w = 1
    for (std::size_t i = 0; i < n; ++i)
      out[i] = glm::vec4(floats[3 * i], floats[3 * i + 1], floats[3 * i + 2], 1.0f);
    return out;
  }
  // The denoiser's own images are planar (kernels/shared/svgf.h).
  for (std::size_t i = 0; i < n; ++i)
    out[i] = glm::vec4(floats[i], floats[n + i], floats[2 * n + i], floats[3 * n + i]);
  return out;
}

std::vector<float> SvgfDenoiser::read_depth_slope() {
  std::vector<float> out(static_cast<std::size_t>(width_) * height_);
  translate_cl_errors([&] {
    runtime_.queue().enqueueReadBuffer(depth_slope_, CL_TRUE, 0, out.size() * 4, out.data());
  });
  return out;
}

}  // namespace rtpg
