#include "rtpg/guider.h"

#include <numeric>

#include "cl/cl_runtime.h"
#include "guiding/guiding_params.h"
#include "shared/pmm.h"

namespace rtpg {
namespace {

using shared::pg_guiding_params;
static_assert(sizeof(pg_guiding_params) == 19 * 4,
              "pg_guiding_params: 19 plain 4-byte fields, no padding");
static_assert(sizeof(shared::pg_pmm_state) == 32, "8 floats of state per pixel");

// A step through the neighbourhood window that visits every cell once: coprime with its size.
int window_stride(int apron) {
  const int size = (2 * apron + 1) * (2 * apron + 1);
  for (int s = std::max(1, size / 3); s < size; ++s)
    if (std::gcd(s, size) == 1) return s;
  return 1;
}

void validate(const GuidingConfig& c, int width, int height) {
  auto fail = [](const std::string& what) { throw GuiderError("guiding configuration: " + what); };
  if (width <= 0 || height <= 0) fail("resolution must be positive");
  if (!(c.pi_min >= 0.0f && c.pi_min <= c.pi_max && c.pi_max < 1.0f))
    fail("need 0 <= pi_min <= pi_max < 1");
  if (!(c.pi_init > 0.0f && c.pi_init < 1.0f)) fail("pi_init must be in (0, 1)");
  if (c.k_max < 1) fail("k_max must be at least 1");
  if (!(c.step_alpha > 0.0f && c.step_alpha <= 1.0f)) fail("step_alpha must be in (0, 1]");
  if (!(c.sigma_eps > 0.0f)) fail("sigma_eps must be positive");
  if (!(c.sigma_prior >= 0.0f)) fail("sigma_prior must be non-negative");
  if (!(c.reseed_ratio > 0.0f)) fail("reseed_ratio must be positive");
  if (!(c.max_correlation > 0.0f && c.max_correlation < 1.0f))
    fail("max_correlation must be in (0, 1)");
  if (c.n_min < 1 || c.n_max < c.n_min) fail("need 1 <= n_min <= n_max");
  if (c.n_max > 32) fail("n_max must be at most 32 (PG_MAX_TRAIN_SAMPLES)");
  if (c.em_passes < 1 || c.em_passes > 8) fail("em_passes must be in [1, 8]");
  if (c.apron < 0 || c.apron > 8) fail("apron must be in [0, 8]");
  if (c.local_x < 1 || c.local_y < 1) fail("local size must be positive");
}

}  // namespace

shared::pg_guiding_params make_guiding_params(const GuidingConfig& c) {
  using shared::pg_guiding_params;
  pg_guiding_params p{};
  p.pi_min = c.pi_min;
  p.pi_max = c.pi_max;
  p.pi_init = c.pi_init;
  p.k_max = static_cast<float>(c.k_max);
  p.step_alpha = c.step_alpha;
  p.sigma_eps = c.sigma_eps;
  p.max_correlation = c.max_correlation;
  p.roughness_skip = c.roughness_skip;
  p.n_min = static_cast<float>(c.n_min);
  p.n_max = static_cast<float>(c.n_max);
  p.max_weight = c.max_weight;
  p.reproject_depth = c.reproject_position;
  p.reproject_normal = c.reproject_normal;
  p.sigma_prior = c.sigma_prior;
  p.reseed_ratio = c.reseed_ratio;
  p.weight_clamp = c.weight_clamp;
  p.em_passes = c.em_passes;
  p.apron = c.apron;
  p.stride = window_stride(c.apron);
  return p;
}

Guider::Guider(ClRuntime& runtime, int width, int height, const GuidingConfig& config)
    : runtime_(runtime), width_(width), height_(height), config_(config) {
  validate(config, width, height);
  const DeviceInfo& info = runtime.info();
  switch (config.train_memory) {
    case GuidingConfig::TrainMemory::Local:
      local_tile_ = true;
      break;
    case GuidingConfig::TrainMemory::Global:
      local_tile_ = false;
      break;
    case GuidingConfig::TrainMemory::Auto:
      local_tile_ = info.type != "cpu";
      break;
  }
  const std::string train_options =
      std::string("-DPG_TRAIN_LOCAL_TILE=") + (local_tile_ ? "1" : "0");
  reproject_ = runtime.kernel("reproject.cl", "reproject");
  sample_ = runtime.kernel("sample.cl", "sample");
  train_ = runtime.kernel("train.cl", "train", train_options);

  const std::size_t group = static_cast<std::size_t>(config.local_x) * config.local_y;
  std::vector<std::size_t> max_items = runtime.device().getInfo<CL_DEVICE_MAX_WORK_ITEM_SIZES>();
  for (cl::Kernel* k : {&reproject_, &sample_, &train_}) {
    const std::size_t limit = k->getWorkGroupInfo<CL_KERNEL_WORK_GROUP_SIZE>(runtime.device());
    if (group > limit || static_cast<std::size_t>(config.local_x) > max_items.at(0) ||
        static_cast<std::size_t>(config.local_y) > max_items.at(1))
      throw GuiderError("local size " + std::to_string(config.local_x) + "x" +
                        std::to_string(config.local_y) + " is refused by " + info.device_name +
                        " (at most " + std::to_string(limit) + " work-items for kernel " +
                        k->getInfo<CL_KERNEL_FUNCTION_NAME>() + ")");
  }
  if (local_tile_) {
    const std::size_t tile = static_cast<std::size_t>(config.local_x + 2 * config.apron) *
                             (config.local_y + 2 * config.apron) * 3 * 16;
    const std::size_t used = train_.getWorkGroupInfo<CL_KERNEL_LOCAL_MEM_SIZE>(runtime.device());
    if (tile + used > info.local_mem_size)
      throw GuiderError("the VPL tile (" + std::to_string(tile) + " bytes for " +
                        std::to_string(config.local_x) + "x" + std::to_string(config.local_y) +
                        " pixels, apron " + std::to_string(config.apron) +
                        ") does not fit in the " + std::to_string(info.local_mem_size) +
                        " bytes of local memory of " + info.device_name);
  }
  const std::size_t n = static_cast<std::size_t>(width) * height;
  for (int b = 0; b < 2; ++b) {
    state0_[b] = cl::Buffer(runtime.context(), CL_MEM_READ_WRITE, n * 16);
    state1_[b] = cl::Buffer(runtime.context(), CL_MEM_READ_WRITE, n * 16);
  }
  trained_ = cl::Buffer(runtime.context(), CL_MEM_READ_WRITE, n);
  reset();
}

Guider::~Guider() = default;

void Guider::reset() {
  // Zeros written from the host, not clEnqueueFillBuffer: Oclgrind 21.10 keeps treating filled
  // memory as uninitialised even after a kernel has overwritten it, so every later kernel that
  // reads the state is flagged under --uninitialized (a false positive hiding real findings).
  const std::size_t n = static_cast<std::size_t>(width_) * height_;
  const std::vector<float> zeros(n * 4, 0.0f);
  for (int b = 0; b < 2; ++b) {
    runtime_.queue().enqueueWriteBuffer(state0_[b], CL_FALSE, 0, n * 16, zeros.data());
    runtime_.queue().enqueueWriteBuffer(state1_[b], CL_FALSE, 0, n * 16, zeros.data());
  }
  const std::vector<cl_uchar> none(n, 0);
  runtime_.queue().enqueueWriteBuffer(trained_, CL_FALSE, 0, n, none.data());
  runtime_.queue().finish();  // the host vectors must outlive the writes
}

void Guider::check_buffer(const cl::Buffer& b, std::size_t element_size,
                          const std::string& name) const {
  const std::size_t need = element_size * static_cast<std::size_t>(width_) * height_;
  if (b() == nullptr) throw GuiderError(name + ": buffer is not set");
  const std::size_t have = b.getInfo<CL_MEM_SIZE>();
  if (have < need)
    throw GuiderError(name + ": buffer holds " + std::to_string(have) + " bytes, " +
                      std::to_string(width_) + "x" + std::to_string(height_) + " pixels need " +
                      std::to_string(need));
}

void Guider::check_gbuffer(const GuiderGBuffer& g, const char* which) const {
  const std::string w(which);
  check_buffer(g.position_depth, 16, w + ".position_depth");
  check_buffer(g.shading_normal, 16, w + ".shading_normal");
  check_buffer(g.view_dir, 16, w + ".view_dir");
  check_buffer(g.base_color_roughness, 16, w + ".base_color_roughness");
  check_buffer(g.metallic_specular, 16, w + ".metallic_specular");
  check_buffer(g.flags, 4, w + ".flags");
  check_buffer(g.material, 4, w + ".material");
  check_buffer(g.motion, 8, w + ".motion");
}

double Guider::run(cl::Kernel& kernel) {
  cl::Event done;
  runtime_.queue().enqueueNDRangeKernel(kernel, cl::NullRange, global_range(),
                                        cl::NDRange(config_.local_x, config_.local_y), nullptr,
                                        &done);
  done.wait();
  return ClRuntime::event_ms(done);
}

cl::NDRange Guider::global_range() const {
  auto round_up = [](int v, int m) { return static_cast<std::size_t>((v + m - 1) / m * m); };
  return cl::NDRange(round_up(width_, config_.local_x), round_up(height_, config_.local_y));
}

void Guider::reproject(const GuiderGBuffer& current, const GuiderGBuffer& previous) {
  check_gbuffer(current, "current");
  check_gbuffer(previous, "previous");
  const int from = current_, to = 1 - current_;
  const pg_guiding_params params = make_guiding_params(config_);
  int a = 0;
  cl::Kernel& k = reproject_;
  k.setArg(a++, state0_[from]);
  k.setArg(a++, state1_[from]);
  k.setArg(a++, previous.position_depth);
  k.setArg(a++, previous.shading_normal);
  k.setArg(a++, previous.material);
  k.setArg(a++, state0_[to]);
  k.setArg(a++, state1_[to]);
  k.setArg(a++, current.position_depth);
  k.setArg(a++, current.shading_normal);
  k.setArg(a++, current.base_color_roughness);
  k.setArg(a++, current.flags);
  k.setArg(a++, current.material);
  k.setArg(a++, current.motion);
  k.setArg(a++, static_cast<cl_uint>(width_));
  k.setArg(a++, static_cast<cl_uint>(height_));
  k.setArg(a++, params);
  times_.reproject_ms = run(k);
  current_ = to;
}

void Guider::sample(const GuiderGBuffer& current, std::uint32_t seed, std::uint32_t frame,
                    std::uint32_t sample_index, const GuiderSamples& out) {
  check_gbuffer(current, "current");
  check_buffer(out.direction_pdf, 16, "samples.direction_pdf");
  check_buffer(out.strategy, 4, "samples.strategy");
  const pg_guiding_params params = make_guiding_params(config_);
  int a = 0;
  cl::Kernel& k = sample_;
  k.setArg(a++, state0_[current_]);
  k.setArg(a++, state1_[current_]);
  k.setArg(a++, current.shading_normal);
  k.setArg(a++, current.view_dir);
  k.setArg(a++, current.base_color_roughness);
  k.setArg(a++, current.metallic_specular);
  k.setArg(a++, current.flags);
  k.setArg(a++, out.direction_pdf);
  k.setArg(a++, out.strategy);
  k.setArg(a++, static_cast<cl_uint>(width_));
  k.setArg(a++, static_cast<cl_uint>(height_));
  k.setArg(a++, static_cast<cl_uint>(seed));
  k.setArg(a++, static_cast<cl_uint>(frame));
  k.setArg(a++, static_cast<cl_uint>(sample_index));
  k.setArg(a++, params);
  times_.sample_ms = run(k);
}

void Guider::train(const GuiderGBuffer& current, const GuiderVpls& vpls, std::uint32_t seed,
                   std::uint32_t frame) {
  check_gbuffer(current, "current");
  check_buffer(vpls.position, 16, "vpls.position");
  check_buffer(vpls.normal, 16, "vpls.normal");
  check_buffer(vpls.radiance_info, 16, "vpls.radiance_info");
  const pg_guiding_params params = make_guiding_params(config_);
  const int from = current_, to = 1 - current_;
  const std::size_t tile = local_tile_
                               ? static_cast<std::size_t>(config_.local_x + 2 * config_.apron) *
                                     (config_.local_y + 2 * config_.apron) * 16
                               : 16;
  int a = 0;
  cl::Kernel& k = train_;
  k.setArg(a++, state0_[from]);
  k.setArg(a++, state1_[from]);
  k.setArg(a++, state0_[to]);
  k.setArg(a++, state1_[to]);
  k.setArg(a++, current.position_depth);
  k.setArg(a++, current.shading_normal);
  k.setArg(a++, current.view_dir);
  k.setArg(a++, current.base_color_roughness);
  k.setArg(a++, current.metallic_specular);
  k.setArg(a++, current.flags);
  k.setArg(a++, vpls.position);
  k.setArg(a++, vpls.normal);
  k.setArg(a++, vpls.radiance_info);
  k.setArg(a++, trained_);
  k.setArg(a++, static_cast<cl_uint>(width_));
  k.setArg(a++, static_cast<cl_uint>(height_));
  k.setArg(a++, static_cast<cl_uint>(seed));
  k.setArg(a++, static_cast<cl_uint>(frame));
  k.setArg(a++, params);
  k.setArg(a++, cl::Local(tile));
  k.setArg(a++, cl::Local(tile));
  k.setArg(a++, cl::Local(tile));
  times_.train_ms = run(k);
  current_ = to;
}

void Guider::read_state(std::vector<float>& state) {
  const std::size_t n = static_cast<std::size_t>(width_) * height_;
  std::vector<float> s0(n * 4), s1(n * 4);
  runtime_.queue().enqueueReadBuffer(state0_[current_], CL_FALSE, 0, n * 16, s0.data());
  runtime_.queue().enqueueReadBuffer(state1_[current_], CL_TRUE, 0, n * 16, s1.data());
  state.resize(n * 8);
  for (std::size_t i = 0; i < n; ++i)
    for (int c = 0; c < 4; ++c) {
      state[i * 8 + c] = s0[i * 4 + c];
      state[i * 8 + 4 + c] = s1[i * 4 + c];
    }
}

void Guider::write_state(const std::vector<float>& state) {
  const std::size_t n = static_cast<std::size_t>(width_) * height_;
  if (state.size() != n * 8)
    throw GuiderError("write_state: " + std::to_string(state.size()) + " floats given, " +
                      std::to_string(n * 8) + " needed (8 per pixel)");
  std::vector<float> s0(n * 4), s1(n * 4);
  for (std::size_t i = 0; i < n; ++i)
    for (int c = 0; c < 4; ++c) {
      s0[i * 4 + c] = state[i * 8 + c];
      s1[i * 4 + c] = state[i * 8 + 4 + c];
    }
  runtime_.queue().enqueueWriteBuffer(state0_[current_], CL_FALSE, 0, n * 16, s0.data());
  runtime_.queue().enqueueWriteBuffer(state1_[current_], CL_TRUE, 0, n * 16, s1.data());
}

std::size_t Guider::count_trained() {
  const std::size_t n = static_cast<std::size_t>(width_) * height_;
  std::vector<std::uint8_t> flags(n);
  runtime_.queue().enqueueReadBuffer(trained_, CL_TRUE, 0, n, flags.data());
  return static_cast<std::size_t>(std::count(flags.begin(), flags.end(), 1));
}

}  // namespace rtpg
