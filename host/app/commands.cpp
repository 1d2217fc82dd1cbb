#include "app/commands.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <numeric>
#include <set>

#include <unistd.h>

#include <fmt/format.h>
#include <tbb/global_control.h>
#include <tbb/task_arena.h>
#include <nlohmann/json.hpp>

#include "rtpg/cl_runtime.h"
#include "cl/device.h"
#include "denoise/svgf_denoiser.h"
#include "render/temporal_flicker.h"
#include "render/image_kernels.h"
#include "render/guided_first_bounce.h"
#include "render/image_io.h"
#include "scene/scene_loader.h"
#include "util/atomic_file.h"
#include "rtpg/errors.h"
#include "rtpg/guiding_settings.h"
#include "util/stderr_capture.h"

#ifndef RTPG_SOURCE_DIR
#define RTPG_SOURCE_DIR "."
#endif

namespace rtpg {
namespace fs = std::filesystem;
namespace {

std::string extension_of(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  return ext;
}

// Every output's folder is checked before any work, so that a bad path fails before an
// earlier output of the same run has been written: it must exist and take a new file (a
// folder such as /proc exists and refuses one); so is the output itself, which must not be an
// existing folder (the rename into place would fail only after the render and the other
// outputs).
void check_output_folder(const std::string& path) {
  const fs::path parent = fs::path(path).parent_path();
  if (!parent.empty() && !fs::is_directory(parent))
    throw InputError(path, "folder '" + parent.string() + "' does not exist");
  if (fs::is_directory(path)) throw InputError(path, "is a folder, not a file");
  check_can_create(path);
}

// A file named by a flag: an output the run writes, or an input it reads.
struct NamedFile {
  const char* flag;
  std::string path;
};

// The same file however it is spelt (relative or absolute, "./", "..", links).
fs::path file_identity(const std::string& path) {
  std::error_code error;
  const fs::path canonical = fs::weakly_canonical(fs::absolute(path), error);
  return error ? fs::absolute(path).lexically_normal() : canonical;
}

// No two outputs of a run may be one file (the later would replace the earlier: an EXR holding
// the statistics' JSON), and no output may be one of its inputs (the reference, read before the
// render, would be replaced by it). Checked before any work, like the folders.
void check_distinct_files(const std::vector<NamedFile>& outputs,
                          const std::vector<NamedFile>& inputs) {
  std::vector<std::pair<fs::path, const NamedFile*>> seen;
  for (const NamedFile& input : inputs)
    if (!input.path.empty()) seen.emplace_back(file_identity(input.path), &input);
  const std::size_t input_count = seen.size();
  for (const NamedFile& output : outputs) {
    if (output.path.empty()) continue;
    const fs::path id = file_identity(output.path);
    for (std::size_t k = 0; k < seen.size(); ++k)
      if (seen[k].first == id)
        throw InputError(output.flag,
                         fmt::format("'{}' is also the {} ({} '{}'): {}", output.path,
                                     k < input_count ? "input" : "output", seen[k].second->flag,
                                     seen[k].second->path,
                                     k < input_count ? "the run would overwrite what it reads"
                                                     : "one output would replace the other"));
    seen.emplace_back(id, &output);
  }
}

void check_output_path(const std::string& path, const char* flag, bool png_allowed) {
  if (path.empty()) return;
  const std::string ext = extension_of(path);
  if (ext != ".exr" && !(png_allowed && ext == ".png"))
    throw InputError(flag, "output must end in .exr" + std::string(png_allowed ? " or .png" : "") +
                               ", got '" + path + "'");
  check_output_folder(path);
}

Scene load(const CommonArguments& common) {
  const std::string path = common.scene.empty() ? default_scene_path() : common.scene;
  SceneLoadSettings settings;
  settings.asset_root = common.asset_root;
  Scene scene = load_quietly([&] { return load_scene(path, settings); });
  for (const std::string& warning : scene.warnings)
    std::fprintf(stderr, "rtpg: warning: %s\n", warning.c_str());
  return scene;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const std::size_t m = v.size() / 2;
  return v.size() % 2 ? v[m] : 0.5 * (v[m - 1] + v[m]);
}

ImageRgb to_image(const Renderer& renderer, const std::vector<glm::vec3>& pixels) {
  ImageRgb image;
  image.width = renderer.settings().width;
  image.height = renderer.settings().height;
  image.pixels = pixels;
  return image;
}

// EXR: linear radiance; PNG: the documented display transform (kernels/shared/tonemap.h) after
// the scene's exposure (Scene::exposure).
void write_output(const std::string& path, const ImageRgb& image, ClRuntime& cl,
                  const std::map<std::string, std::string>& metadata, float exposure) {
  if (extension_of(path) == ".png") {
    std::vector<glm::vec4> radiance(image.pixels.size());
    for (std::size_t i = 0; i < radiance.size(); ++i)
      radiance[i] = glm::vec4(image.pixels[i], 1.0f);
    std::vector<std::uint8_t> rgba8;
    tonemap_on_device(cl, radiance, image.width, image.height, exposure, rgba8);
    write_png(path, image.width, image.height, rgba8);
  } else {
    write_exr(path, image, metadata);
  }
}

// The renderer names its settings; the command line names the flags that set them.
template <class F>
decltype(auto) with_flag_names(F&& f) {
  try {
    return f();
  } catch (const RenderSettingError& e) {
    static const std::map<std::string, std::string> flags = {{"resolution", "--res"},
                                                             {"spp", "--spp"},
                                                             {"camera_path", "--camera-path"},
                                                             {"max_bounces", "--max-bounces"}};
    const auto it = flags.find(e.setting());
    throw InputError(it != flags.end() ? it->second : e.setting(), e.problem());
  }
}

// Every row of a settings table (guiding's or the denoiser's) by its name.
template <class Settings>
nlohmann::json settings_json(const std::vector<SettingInfo<Settings>>& table, const Settings& s) {
  nlohmann::json out = nlohmann::json::object();
  for (const SettingInfo<Settings>& row : table) {
    if (row.int_field) {
      out[row.name] = s.*row.int_field;
    } else {
      out[row.name] = s.*row.float_field;
    }
  }
  return out;
}

nlohmann::json guiding_settings_json(const GuidingSettings& s, int image_height) {
  nlohmann::json out = settings_json(guiding_settings_table(), s);
  out["train_memory"] = train_memory_name(s.train_memory);
  // What rows_per_model 0 (by the image's height) came to for this image.
  out["rows_per_model_for_image"] = to_kernel_settings(s, image_height).rows_per_model;
  return out;
}

const char* shared_randoms_name(SharedRandoms s) {
  switch (s) {
    case SharedRandoms::first_bounce:
      return "first-bounce";
    case SharedRandoms::primary_vertex:
      return "primary-vertex";
    case SharedRandoms::second_vertex:
      return "second-vertex";
    case SharedRandoms::none:
      break;
  }
  return "none";
}

const char* bounce_ray_order_name(BounceRayOrder order) {
  switch (order) {
    case BounceRayOrder::grouped:
      return "grouped";
    case BounceRayOrder::listed:
      return "listed";
    case BounceRayOrder::automatic:
      break;
  }
  return "auto";
}

// The value of --bounce-ray-order (checked by the command line's parser; a wrong name from
// elsewhere is an input error naming the flag).
BounceRayOrder parse_bounce_ray_order(const std::string& name) {
  if (name == "auto") return BounceRayOrder::automatic;
  if (name == "grouped") return BounceRayOrder::grouped;
  if (name == "listed") return BounceRayOrder::listed;
  throw InputError("--bounce-ray-order", "unknown value '" + name + "' (auto, grouped or listed)");
}

nlohmann::json path_tracer_settings_json(const PathTracerSettings& s) {
  return {{"max_bounces", s.max_bounces},
          {"roulette_start", s.roulette_start},
          {"next_event", s.next_event},
          {"guide_secondary", s.guide_secondary},
          {"direct_light_in_vpls", s.direct_light_in_vpls},
          {"first_bounce_mis", s.first_bounce_mis == FirstBounceMis::bsdf ? "bsdf" : "mixture"},
          {"shared_randoms", shared_randoms_name(s.shared_randoms)},
          {"bounce_ray_order", bounce_ray_order_name(s.bounce_ray_order)}};
}

// The value of --share-randoms (checked by the command line's parser; a wrong name from
// elsewhere is an input error naming the flag).
SharedRandoms parse_shared_randoms(const std::string& name) {
  if (name == "none") return SharedRandoms::none;
  if (name == "first-bounce") return SharedRandoms::first_bounce;
  if (name == "primary-vertex") return SharedRandoms::primary_vertex;
  if (name == "second-vertex") return SharedRandoms::second_vertex;
  throw InputError(
      "--share-randoms",
      "unknown value '" + name + "' (none, first-bounce, primary-vertex or second-vertex)");
}

// --max-bounces: not negative (0 = the scene's default); its upper bound, kMaxPathBounces, is the
// renderer's to check (with_flag_names names the flag).
void check_max_bounces(int flag) {
  if (flag < 0) throw InputError("--max-bounces", "must not be negative (0 = the scene's default)");
}

// The flag wins, then the scene's integrator setting, then the renderer's default.
int bounces_for(const Scene& scene, int flag) {
  check_max_bounces(flag);
  if (flag > 0) return flag;
  return scene.max_bounces > 0 ? scene.max_bounces : PathTracerSettings{}.max_bounces;
}

}  // namespace

std::string frame_output_path(const std::string& output, int frame) {
  const fs::path path(output);
  return (path.parent_path() /
          fmt::format("{}-f{:04d}{}", path.stem().string(), frame, path.extension().string()))
      .string();
}

// The host threads that ran the parallel loops: --threads caps TBB's pool (global_control, which
// the arena's own concurrency does not show), and the pool never grows past the cores there are.
int host_threads() {
  return static_cast<int>(std::min<std::size_t>(
      tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism),
      static_cast<std::size_t>(tbb::this_task_arena::max_concurrency())));
}

// The statistics as text; a string that is not UTF-8 (a scene file's name in another encoding)
// has its bad bytes replaced rather than failing the run after its images were written.
std::string dump_json(const nlohmann::json& stats) {
  return stats.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
}

std::string default_scene_path() {
  if (fs::exists("scenes/cornell-box.json")) return "scenes/cornell-box.json";
  return std::string(RTPG_SOURCE_DIR) + "/scenes/cornell-box.json";
}

int run_render(const RenderCommand& command) {
  check_output_path(command.output, "--output", true);
  check_output_path(command.noisy_output, "--noisy-output", true);
  if (!command.noisy_output.empty() && command.denoise == "off")
    throw InputError("--noisy-output", "needs --denoise (without it --output is the noisy image)");
  if (command.denoise != "off" && command.denoise != "svgf")
    throw InputError("--denoise", "unknown denoiser '" + command.denoise + "' (off or svgf)");
  if (command.denoise == "svgf") validate(command.svgf_settings);
  if (!command.stats_json.empty()) check_output_folder(command.stats_json);
  if (command.frames <= 0) throw InputError("--frames", "must be at least 1");
  if (!command.save_frames.empty() && command.output.empty() && command.noisy_output.empty())
    throw InputError("--save-frames", "needs --output (the frames are written beside it)");
  for (int f : command.save_frames)
    if (f < 0 || f >= command.frames)
      throw InputError("--save-frames", fmt::format("frame {} is outside 0..{} (--frames {})", f,
                                                    command.frames - 1, command.frames));
  check_max_bounces(command.max_bounces);
  if (command.guide_vertices == "all" && command.guiding != "pmm")
    throw InputError("--guide-vertices",
                     "all borrows the pixels' guided mixtures: it needs "
                     "--guiding pmm");
  if (command.accumulate && !command.settings.camera_path.empty())
    throw InputError("--accumulate", "needs a static camera: it would average the views along '" +
                                         command.settings.camera_path + "'");
  // CLI11's ranges let NaN through (no comparison with it is true).
  if (std::isnan(command.world_guide_min_pi))
    throw InputError("--world-guide-min-pi", "must be a number in [0, 1]");
  if (std::isnan(command.world_guide_pi_max))
    throw InputError("--world-guide-pi-max", "must be a number in [0, 1)");
  {
    std::vector<NamedFile> outputs = {{"--output", command.output},
                                      {"--noisy-output", command.noisy_output},
                                      {"--stats-json", command.stats_json}};
    // Each frame once (--save-frames 2,2 writes frame 2 once).
    const std::set<int> frames(command.save_frames.begin(), command.save_frames.end());
    for (int f : frames) {
      if (!command.output.empty())
        outputs.push_back({"--save-frames", frame_output_path(command.output, f)});
      if (!command.noisy_output.empty())
        outputs.push_back({"--save-frames", frame_output_path(command.noisy_output, f)});
    }
    check_distinct_files(outputs,
                         {{"--reference", command.reference}, {"the scene", command.common.scene}});
  }
  ImageRgb reference;
  if (!command.reference.empty()) {
    // Its size is checked against the render's before its pixels are read.
    reference = load_quietly([&] {
      return read_image(command.reference, command.settings.width, command.settings.height);
    });
  }
  const std::string scene_path =
      command.common.scene.empty() ? default_scene_path() : command.common.scene;
  const Scene scene = load(command.common);
  ClRuntime cl(command.common.device);
  RenderSettings settings = command.settings;
  settings.path_tracer.max_bounces = bounces_for(scene, command.max_bounces);
  settings.path_tracer.guide_secondary =
      command.guiding == "pmm" && command.guide_vertices == "all";
  settings.path_tracer.direct_light_in_vpls = command.guide_direct_light == "mis";
  settings.world_guide = command.guide_vertices == "world";
  settings.world_guide_settings.resolution = command.world_guide_resolution;
  settings.world_guide_settings.record_every = command.world_guide_record_every;
  settings.world_guide_settings.min_guiding_pi = command.world_guide_min_pi;
  settings.world_guide_settings.max_depth =
      command.world_guide_max_depth > 0 ? command.world_guide_max_depth : 1 << 30;
  settings.world_guide_settings.em = to_kernel_settings(command.guiding_settings);
  if (command.world_guide_pi_max >= 0.0f) {
    // Below 1, as --pg-pi-max: at 1 a guided vertex never samples its BSDF, and the directions
    // outside its cell's hemisphere (up to about 55 degrees from its own) could not be reached.
    if (!(command.world_guide_pi_max < 1.0f))
      throw InputError("--world-guide-pi-max",
                       fmt::format("must be below 1, got {}", command.world_guide_pi_max));
    if (command.world_guide_pi_max < settings.world_guide_settings.em.pi_min)
      throw InputError("--world-guide-pi-max",
                       fmt::format("{} is below --pg-pi-min ({})", command.world_guide_pi_max,
                                   settings.world_guide_settings.em.pi_min));
    settings.world_guide_settings.em.pi_max = command.world_guide_pi_max;
  }
  settings.path_tracer.first_bounce_mis =
      command.first_bounce_mis == "bsdf" ? FirstBounceMis::bsdf : FirstBounceMis::mixture;
  settings.path_tracer.shared_randoms = parse_shared_randoms(command.share_randoms);
  settings.path_tracer.bounce_ray_order = parse_bounce_ray_order(command.bounce_ray_order);
  settings.path_tracer.guide_position = command.guiding_settings.reproject_position;
  settings.path_tracer.guide_normal = command.guiding_settings.reproject_normal;
  Renderer renderer = with_flag_names([&] { return Renderer(scene, settings); });
  const GuidedFirstBounce* guided = nullptr;  // owned by the renderer
  if (command.guiding == "pmm") {
    auto sampler = std::make_unique<GuidedFirstBounce>(
        cl, command.settings.width, command.settings.height, command.guiding_settings,
        parse_host_transfer(command.host_transfer), parse_overlap(command.train_overlap),
        parse_overlap(command.sample_overlap));
    guided = sampler.get();
    renderer.set_first_bounce_sampler(std::move(sampler));
  }
  std::unique_ptr<SvgfDenoiser> denoiser;
  if (command.denoise == "svgf")
    denoiser =
        std::make_unique<SvgfDenoiser>(cl, settings.width, settings.height, command.svgf_settings);

  nlohmann::json frames = nlohmann::json::array();
  std::vector<double> totals;
  double last_relmse = -1.0;
  std::uint64_t nonfinite = 0;
  // --accumulate: the running mean of all frames, kept on the device (kernels/accumulate.cl).
  std::unique_ptr<Accumulator> accumulator;
  if (command.accumulate)
    accumulator = std::make_unique<Accumulator>(cl, settings.width, settings.height);
  // Last frame's output and unfiltered image, for the temporal flicker metric; the same through
  // the motion vectors, for a moving camera.
  std::vector<glm::vec3> previous, previous_noisy;
  ReprojectedFlicker reprojected_flicker, reprojected_flicker_noisy;
  std::vector<glm::vec4> frame_rgba;
  // This frame's output: the renderer's image, or with --denoise the denoised one (the
  // denoiser's, valid until its next frame).
  const std::vector<glm::vec3>* shown = &renderer.image();
  ImageRgb accumulated{settings.width, settings.height, {}};
  const std::map<std::string, std::string> metadata = {
      {"scene", scene_path},
      {"spp", std::to_string(command.settings.spp)},
      {"seed", std::to_string(command.settings.seed)},
      {"guiding", command.guiding},
      {"denoise", command.denoise}};
  // The current frame's output (the running mean with --accumulate) to --output or a
  // --save-frames file, with the metadata that says which frame it is.
  auto write_frame = [&](const std::string& path, int f) {
    ImageRgb out = to_image(renderer, *shown);
    if (accumulator) {
      const std::vector<glm::vec4> mean = accumulator->read();
      for (std::size_t i = 0; i < mean.size(); ++i) out.pixels[i] = glm::vec3(mean[i]);
    }
    std::map<std::string, std::string> m = metadata;
    m["frame"] = std::to_string(f);
    m["accumulated_frames"] = std::to_string(accumulator ? f + 1 : 1);
    // The time the image took: with --accumulate every frame it averages (frames 0..f).
    m["render_time_ms"] = fmt::format(
        "{:.3f}", accumulator ? std::accumulate(totals.begin(), totals.end(), 0.0) : totals.back());
    write_output(path, out, cl, m, scene.exposure);
  };
  // The unfiltered frame (with --denoise) to --noisy-output or its --save-frames file.
  auto write_noisy_frame = [&](const std::string& path, int f) {
    std::map<std::string, std::string> m = metadata;
    m["denoise"] = "off";
    m["frame"] = std::to_string(f);
    m["render_time_ms"] = fmt::format("{:.3f}", totals.back());
    write_output(path, to_image(renderer, renderer.image()), cl, m, scene.exposure);
  };
  // Each frame's wall time, from its start to the next frame's (the last frame's: to the end of
  // the loop), in the stats JSON as wall_ms: everything the run does per frame, including what
  // the frame's `total` leaves out (the statistics below) and the work that a device with cores
  // of its own does beside the host (docs/guiding.md, "Training overlapped with the next frame,
  // on a GPU").
  using WallClock = std::chrono::steady_clock;
  auto wall_ms_since = [](WallClock::time_point t) {
    return std::chrono::duration<double, std::milli>(WallClock::now() - t).count();
  };
  WallClock::time_point frame_started{};
  for (int f = 0; f < command.frames; ++f) {
    if (f > 0) frames.back()["wall_ms"] = wall_ms_since(frame_started);
    frame_started = WallClock::now();
    FrameStats stats = renderer.render_frame(f);
    const std::vector<glm::vec3>& image = renderer.image();
    // The flicker metrics and their copies of last frame's images go only to the stats JSON.
    const bool want_stats = !command.stats_json.empty();
    double svgf_bytes = 0.0;
    shown = &image;
    if (denoiser) {
      // The renderer's image in, the denoised image out, both as they are (three floats a
      // pixel, in place where memory is shared). Where the guided sampler copied this frame's
      // G-buffer to the device, the denoiser reads it there (docs/denoising.md, "On a GPU").
      shown = &denoiser->denoise(image, renderer.gbuffer(),
                                 guided ? guided->device_gbuffer_of(renderer.gbuffer()) : nullptr);
      for (const auto& [name, ms] : denoiser->times_ms()) stats.time_ms[name] = ms;
      stats.time_ms["total"] += denoiser->times_ms().at("svgf_total");
      svgf_bytes = denoiser->host_device_bytes_per_pixel();
    }
    totals.push_back(stats.time_ms["total"]);
    const double flicker = want_stats ? flicker_mse(*shown, previous) : -1.0;
    const double flicker_noisy = want_stats && denoiser ? flicker_mse(image, previous_noisy) : -1.0;
    // One pass over the image that also keeps the next frame's history (temporal_flicker.h).
    const ReprojectedFlicker::Frame tracked =
        want_stats ? reprojected_flicker.add(*shown, renderer.gbuffer(), scene.exposure)
                   : ReprojectedFlicker::Frame{};
    const ReprojectedFlicker::Frame tracked_noisy =
        want_stats && denoiser
            ? reprojected_flicker_noisy.add(image, renderer.gbuffer(), scene.exposure)
            : ReprojectedFlicker::Frame{};
    if (want_stats) previous = *shown;
    if (want_stats && denoiser) previous_noisy = image;
    if (accumulator) {
      frame_rgba.resize(shown->size());
      for (std::size_t i = 0; i < shown->size(); ++i) frame_rgba[i] = glm::vec4((*shown)[i], 1.0f);
      const auto t = std::chrono::steady_clock::now();
      accumulator->add(frame_rgba).wait();
      stats.time_ms["accumulate_kernel"] =
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count();
    }
    nonfinite += stats.nonfinite_samples;
    nlohmann::json frame = {{"index", f},
                            {"time_ms", stats.time_ms},
                            {"nonfinite_samples", stats.nonfinite_samples},
                            {"rays",
                             {{"primary", stats.primary_rays},
                              {"secondary", stats.secondary_rays},
                              {"shadow", stats.shadow_rays}}},
                            {"guided_vertices", stats.guided_vertices}};
    for (const auto& [key, value] : stats.extra) frame[key] = value;
    if (flicker >= 0.0) frame["flicker_mse"] = flicker;
    if (flicker_noisy >= 0.0) frame["flicker_mse_noisy"] = flicker_noisy;
    if (tracked.mse >= 0.0) {
      frame["flicker_reprojected"] = tracked.mse;
      frame["flicker_tracked_fraction"] = tracked.tracked_fraction;
    }
    if (tracked_noisy.mse >= 0.0) frame["flicker_reprojected_noisy"] = tracked_noisy.mse;
    if (denoiser) frame["svgf_host_device_bytes_per_pixel"] = svgf_bytes;
    if (!command.reference.empty()) {
      last_relmse = relative_mse(to_image(renderer, *shown), reference);
      frame["relmse"] = last_relmse;
      if (denoiser) frame["relmse_noisy"] = relative_mse(to_image(renderer, image), reference);
      if (accumulator) {
        const std::vector<glm::vec4> mean = accumulator->read();
        accumulated.pixels.resize(mean.size());
        for (std::size_t i = 0; i < mean.size(); ++i) accumulated.pixels[i] = glm::vec3(mean[i]);
        frame["relmse_accumulated"] = relative_mse(accumulated, reference);
      }
    }
    frames.push_back(frame);
    if (std::find(command.save_frames.begin(), command.save_frames.end(), f) !=
        command.save_frames.end()) {
      if (!command.output.empty()) write_frame(frame_output_path(command.output, f), f);
      if (!command.noisy_output.empty())
        write_noisy_frame(frame_output_path(command.noisy_output, f), f);
    }
    if (!command.common.quiet && command.frames > 1)
      std::printf("frame %d: %.1f ms%s\n", f, stats.time_ms["total"],
                  last_relmse >= 0.0 ? fmt::format(", relMSE {:.4g}", last_relmse).c_str() : "");
  }

  if (!frames.empty()) frames.back()["wall_ms"] = wall_ms_since(frame_started);
  if (!command.output.empty()) write_frame(command.output, command.frames - 1);
  if (!command.noisy_output.empty()) write_noisy_frame(command.noisy_output, command.frames - 1);
  if (!command.stats_json.empty()) {
    const nlohmann::json stats = {
        {"scene", scene_path},
        {"width", command.settings.width},
        {"height", command.settings.height},
        {"spp", command.settings.spp},
        {"seed", command.settings.seed},
        {"jitter", command.settings.jitter},
        {"accumulate", command.accumulate},
        {"camera_path", command.settings.camera_path},
        {"guiding", command.guiding},
        {"guiding_settings",
         guiding_settings_json(command.guiding_settings, command.settings.height)},
        {"guide_vertices", command.guide_vertices},
        {"world_guide",
         {{"resolution", command.world_guide_resolution},
          {"max_depth", command.world_guide_max_depth},
          {"record_every", command.world_guide_record_every},
          {"min_pi", command.world_guide_min_pi},
          {"pi_max", settings.world_guide_settings.em.pi_max}}},
        {"reference", command.reference},
        {"denoise", command.denoise},
        {"svgf_settings", settings_json(svgf_settings_table(), command.svgf_settings)},
        {"max_bounces", settings.path_tracer.max_bounces},
        {"path_tracer", path_tracer_settings_json(settings.path_tracer)},
        {"camera_frame", settings.camera_frame},
        {"frame_count", command.frames},
        {"device", cl.info().device_name},
        {"threads", host_threads()},
        {"bvh_build_ms", renderer.tracer().build_seconds() * 1e3},
        {"frames", frames}};
    write_text_atomically(command.stats_json, dump_json(stats));
  }
  if (!command.common.quiet) {
    std::printf(
        "rendered %s at %dx%d, %d spp, %d frame%s (guiding %s, denoise %s) on %s + Embree\n",
        scene_path.c_str(), command.settings.width, command.settings.height, command.settings.spp,
        command.frames, command.frames == 1 ? "" : "s", command.guiding.c_str(),
        command.denoise.c_str(), cl.info().device_name.c_str());
    std::printf("time per frame: %.1f ms (median of %zu)%s\n", median(totals), totals.size(),
                nonfinite ? fmt::format(", {} non-finite samples dropped", nonfinite).c_str() : "");
    if (last_relmse >= 0.0) std::printf("relMSE of the last frame: %.5g\n", last_relmse);
    if (!command.output.empty()) std::printf("wrote %s\n", command.output.c_str());
    if (!command.noisy_output.empty()) std::printf("wrote %s\n", command.noisy_output.c_str());
  }
  return 0;
}

int run_reference(const ReferenceCommand& command) {
  check_output_path(command.output, "--output", false);
  if (!command.stats_json.empty()) check_output_folder(command.stats_json);
  check_distinct_files({{"--output", command.output}, {"--stats-json", command.stats_json}},
                       {{"the scene", command.common.scene}});
  if (command.spp <= 0) throw InputError("--spp", "must be at least 1");
  check_max_bounces(command.max_bounces);
  const Scene scene = load(command.common);
  RenderSettings settings;
  settings.width = command.width;
  settings.height = command.height;
  settings.seed = command.seed;
  settings.path_tracer.max_bounces = bounces_for(scene, command.max_bounces);
  settings.path_tracer.bounce_ray_order = parse_bounce_ray_order(command.bounce_ray_order);
  settings.camera_path = command.camera_path;
  if (command.frame < 0) throw InputError("--frame", "must not be negative");
  if (command.frame != 0 && command.camera_path.empty())
    throw InputError("--frame", "needs --camera-path (the scene's static camera has one view)");
  settings.camera_frame = command.frame;
  // Several samples share a G-buffer; new jitter per pass gives the pixel filter's integral.
  settings.spp = command.spp % 4 == 0 ? 4 : 1;
  const int passes = command.spp / settings.spp;
  Renderer renderer = with_flag_names([&] { return Renderer(scene, settings); });
  const bool progress = !command.common.quiet && ::isatty(STDERR_FILENO);
  ImageRgb sum;
  sum.width = command.width;
  sum.height = command.height;
  sum.pixels.assign(static_cast<std::size_t>(command.width) * command.height, glm::vec3(0.0f));
  std::uint64_t nonfinite = 0;
  const auto start = std::chrono::steady_clock::now();
  for (int p = 0; p < passes; ++p) {
    nonfinite += renderer.render_frame(p).nonfinite_samples;
    const auto& img = renderer.image();
    for (std::size_t i = 0; i < img.size(); ++i) sum.pixels[i] += img[i];
    if (progress) {
      const int width = 40, filled = (p + 1) * width / passes;
      std::fprintf(stderr, "\r[%s%s] %d/%d spp", std::string(filled, '#').c_str(),
                   std::string(width - filled, ' ').c_str(), (p + 1) * settings.spp, command.spp);
      std::fflush(stderr);
    }
  }
  if (progress) std::fprintf(stderr, "\n");
  for (auto& px : sum.pixels) px /= static_cast<float>(passes);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  // Paths per second, each a whole path with its next-event rays: what the benchmark suite's
  // references cost (they dominate its run time).
  const double samples = static_cast<double>(command.width) * command.height * command.spp;
  const double samples_per_second = seconds > 0.0 ? samples / seconds : 0.0;
  write_exr(command.output, sum,
            {{"scene", command.common.scene},
             {"spp", std::to_string(command.spp)},
             {"seed", std::to_string(command.seed)},
             {"render_time_ms", fmt::format("{:.1f}", seconds * 1e3)},
             {"samples_per_second", fmt::format("{:.0f}", samples_per_second)},
             {"nonfinite_samples", std::to_string(nonfinite)}});
  if (!command.stats_json.empty()) {
    const nlohmann::json stats = {{"scene", command.common.scene},
                                  {"width", command.width},
                                  {"height", command.height},
                                  {"spp", command.spp},
                                  {"seconds", seconds},
                                  {"samples_per_second", samples_per_second},
                                  {"threads", host_threads()},
                                  {"nonfinite_samples", nonfinite}};
    write_text_atomically(command.stats_json, dump_json(stats));
  }
  if (!command.common.quiet)
    std::printf("reference %s: %dx%d, %d spp in %.1f s (%.2f M samples/s) -> %s\n",
                command.common.scene.c_str(), command.width, command.height, command.spp, seconds,
                samples_per_second * 1e-6, command.output.c_str());
  return 0;
}

int run_info(const CommonArguments& command) {
  const Scene scene = load(command);
  const SceneFeatures f = scene.features();
  std::size_t emissive_triangles = 0;
  for (const Mesh& m : scene.meshes)
    if (scene.materials[m.material].is_emissive()) emissive_triangles += m.triangles.size();
  const glm::vec3 lo = scene.bounds_min(), hi = scene.bounds_max();
  std::printf("scene: %s\n", scene.source_path.c_str());
  std::printf("triangles: %zu\nmeshes: %zu\nmaterials: %zu\ntextures: %zu\n",
              scene.triangle_count(), scene.meshes.size(), scene.materials.size(),
              scene.textures.size());
  std::printf("lights: %zu emissive triangles, sun: %s, environment: %s\n", emissive_triangles,
              scene.sun.enabled ? "yes" : "no",
              scene.environment.kind == Environment::Kind::None       ? "none"
              : scene.environment.kind == Environment::Kind::Constant ? "constant"
                                                                      : "map");
  std::printf("degenerate triangles dropped: %zu\n", scene.degenerate_triangles);
  std::printf("bounds: [%g %g %g] - [%g %g %g]\n", lo.x, lo.y, lo.z, hi.x, hi.y, hi.z);
  std::printf("exposure: %g\n", static_cast<double>(scene.exposure));
  std::printf("camera paths: %zu", scene.camera.paths.size());
  for (const auto& [name, path] : scene.camera.paths) std::printf(" %s", name.c_str());
  std::printf("\nfeatures:");
  const std::pair<const char*, bool> list[] = {{"textures", f.textures},
                                               {"normal_maps", f.normal_maps},
                                               {"bump_maps", f.bump_maps},
                                               {"alpha_masks", f.alpha_masks},
                                               {"area_lights", f.area_lights},
                                               {"sun", f.sun},
                                               {"environment", f.environment},
                                               {"environment_map", f.environment_map},
                                               {"glossy", f.glossy},
                                               {"metallic", f.metallic},
                                               {"transmission", f.transmission},
                                               {"camera_paths", f.camera_paths}};
  for (const auto& [name, on] : list)
    if (on) std::printf(" %s", name);
  std::printf("\n");
  return 0;
}

int run_devices() {
  const auto devices = list_devices();
  for (const DeviceInfo& d : devices)
    std::printf("%u:%u  %-5s %s (%s), %s, %u compute units, %llu KiB local memory\n",
                d.platform_index, d.device_index, d.type.c_str(), d.device_name.c_str(),
                d.platform_name.c_str(), d.opencl_c_version.c_str(), d.compute_units,
                static_cast<unsigned long long>(d.local_mem_size / 1024));
  if (devices.empty()) std::printf("no OpenCL devices\n");
  return devices.empty() ? 1 : 0;
}

}  // namespace rtpg
