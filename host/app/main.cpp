// rtpg: real-time path guiding. Parses the command line and runs one subcommand; bad input
// ends with a one-line message and exit code 2.
#include <algorithm>
#include <cstdio>
#include <exception>
#include <memory>
#include <string>

#include <CLI/CLI.hpp>
#include <tbb/global_control.h>

#include "app/commands.h"
#include "rtpg/cl_error.h"
#include "rtpg/cl_runtime.h"
#include "rtpg/errors.h"

namespace {

// What a subcommand uses besides its scene: an OpenCL device (render; reference and info run on
// the host alone), host threads and a quiet mode (render and reference; info only prints). A
// subcommand offers only the options it uses, so that none is parsed and ignored.
enum CommonOptions { kSceneOnly = 0, kHostWork = 1, kDevice = 2 };

void add_common(CLI::App* cmd, rtpg::CommonArguments& common, bool scene_required, int options) {
  auto* scene =
      cmd->add_option("scene", common.scene, "Scene JSON file (default: scenes/cornell-box.json)");
  if (scene_required) scene->required();
  cmd->add_option("--asset-root", common.asset_root,
                  "Folder for scene assets (default: $RTPG_ASSET_ROOT, else ../shared/scenes)");
  if (options & kDevice)
    cmd->add_option("--device", common.device,
                    "OpenCL device: gpu, cpu, P:D or part of its name (default: $RTPG_DEVICE, "
                    "else a GPU, else the CPU)");
  if (options & kHostWork) {
    cmd->add_option("--threads", common.threads,
                    "Host threads for tracing and shading (0: one per core; at most the cores "
                    "there are); OpenCL devices on the CPU keep their own (PoCL: "
                    "POCL_MAX_PTHREAD_COUNT)")
        ->check(CLI::Range(0, 4096))
        ->capture_default_str();
    cmd->add_flag("-q,--quiet", common.quiet, "Print nothing but errors");
  }
}

// "--pg-" and the setting's name with '-' for '_': every row of the guiding settings table
// (include/rtpg/guiding_settings.h) is a flag; values are checked against the table's range
// by the guider (exit 2 with the setting's name).
std::string guiding_flag(const char* name) {
  std::string flag = std::string("--pg-") + name;
  std::replace(flag.begin(), flag.end(), '_', '-');
  return flag;
}

void add_guiding_options(CLI::App* cmd, rtpg::RenderCommand& r) {
  rtpg::GuidingSettings& g = r.guiding_settings;
  cmd->add_option("--guiding", r.guiding, "First-bounce sampling: pmm (guided) or off (BSDF)")
      ->check(CLI::IsMember({"off", "pmm"}))
      ->capture_default_str();
  cmd->add_option("--guide-vertices", r.guide_vertices,
                  "first (the first bounce only, as the paper), all (with --guiding pmm: later "
                  "vertices seen by the camera borrow their pixel's mixture) or world (later "
                  "vertices sample a world-space hash grid of mixtures trained from every later "
                  "vertex; an experiment)")
      ->check(CLI::IsMember({"first", "all", "world"}))
      ->capture_default_str();
  cmd->add_option("--world-guide-resolution", r.world_guide_resolution,
                  "With --guide-vertices world: cells along the scene's longest extent")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  cmd->add_option("--world-guide-max-depth", r.world_guide_max_depth,
                  "With --guide-vertices world: the deepest path vertex that samples and trains "
                  "the world guide (1: the first bounce's hit; 0: every vertex)")
      ->check(CLI::Range(0, 1000))
      ->capture_default_str();
  cmd->add_option("--world-guide-pi-max", r.world_guide_pi_max,
                  "With --guide-vertices world: the cells' largest mixing weight, below 1 "
                  "(default: --pg-pi-max's)")
      ->check(CLI::Range(0.0f, 1.0f));
  cmd->add_option("--world-guide-min-pi", r.world_guide_min_pi,
                  "With --guide-vertices world: a cell guides only where its mixing weight is "
                  "above this (0: every cell with a model)")
      ->check(CLI::Range(0.0f, 1.0f))
      ->capture_default_str();
  cmd->add_option("--world-guide-record-every", r.world_guide_record_every,
                  "With --guide-vertices world: one path in n (chosen afresh every frame) records "
                  "its vertices to train the world guide")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  cmd->add_option("--guide-direct-light", r.guide_direct_light,
                  "With --guiding pmm and next-event estimation: off (the VPLs leave out the light "
                  "y emits) or mis (they carry it with its MIS weight)")
      ->check(CLI::IsMember({"off", "mis"}))
      ->capture_default_str();
  cmd->add_option("--first-bounce-mis", r.first_bounce_mis,
                  "With --guiding pmm and next-event estimation: the density the primary hit's "
                  "light sample and first bounce weigh each other with, and with "
                  "--guide-vertices all a guided later vertex's: bsdf (the BSDF's; the "
                  "mixture is not evaluated for the light sample) or mixture (the guided "
                  "mixture's); both unbiased")
      ->check(CLI::IsMember({"mixture", "bsdf"}))
      ->capture_default_str();
  auto* grp = cmd->add_option_group("Guiding",
                                    "Settings of the PMM guider (include/rtpg/guiding_settings.h)");
  for (const rtpg::GuidingSettingInfo& row : rtpg::guiding_settings_table()) {
    const std::string help = std::string(row.help) + ", in " + row.range_text();
    if (row.int_field) {
      grp->add_option(guiding_flag(row.name), g.*row.int_field, help)->capture_default_str();
    } else {
      grp->add_option(guiding_flag(row.name), g.*row.float_field, help)->capture_default_str();
    }
  }
  grp->add_option("--pg-train-memory", r.train_memory,
                  "VPL reads of the train kernel: auto, local or global")
      ->check(CLI::IsMember({"auto", "local", "global"}))
      ->capture_default_str();
  grp->add_option("--host-transfer", r.host_transfer,
                  "How the G-buffer and VPLs reach the device and the samples come back: auto "
                  "(in-place where the device shares host memory, else packed), in-place, pinned "
                  "(through mapped staging), packed (as pinned, packed: G-buffer, VPLs and samples "
                  "in 46 bytes a pixel at 1 spp instead of 148) or pageable")
      ->check(CLI::IsMember({"auto", "in-place", "pinned", "packed", "pageable"}))
      ->capture_default_str();
  grp->add_option("--train-overlap", r.train_overlap,
                  "Whether training runs on the device while the host makes the next frame's "
                  "camera rays and G-buffer: auto (where the device has memory of its own), on "
                  "or off")
      ->check(CLI::IsMember({"auto", "on", "off"}))
      ->capture_default_str();
  grp->add_option(
         "--sample-overlap", r.sample_overlap,
         "Whether the G-buffer's upload, reproject and sample run on the device while the "
         "host makes the primary hit's light samples and traces their shadow rays: auto "
         "(off: it cost more than it hid on PoCL and on an H200), on or off (same images; with "
         "--first-bounce-mis mixture the light samples wait for the samples)")
      ->check(CLI::IsMember({"auto", "on", "off"}))
      ->capture_default_str();
}

// "--svgf-" and the setting's name with '-' for '_', one flag per row of the denoiser's table
// (host/denoise/svgf_settings.h), checked against its range before rendering (exit 2).
void add_denoise_options(CLI::App* cmd, rtpg::RenderCommand& r) {
  cmd->add_option("--denoise", r.denoise,
                  "Denoiser of every frame: off or svgf (the output is the filtered image)")
      ->check(CLI::IsMember({"off", "svgf"}))
      ->capture_default_str();
  cmd->add_option("--noisy-output", r.noisy_output,
                  "With --denoise: also write the unfiltered last frame (.exr or .png); "
                  "--save-frames writes its frames beside it");
  auto* grp = cmd->add_option_group("Denoiser",
                                    "Settings of the SVGF denoiser (host/denoise/svgf_settings.h)");
  rtpg::SvgfSettings& s = r.svgf_settings;
  for (const rtpg::SvgfSettingInfo& row : rtpg::svgf_settings_table()) {
    std::string flag = std::string("--svgf-") + row.name;
    std::replace(flag.begin(), flag.end(), '_', '-');
    const std::string help = std::string(row.help) + ", in " + row.range_text();
    if (row.int_field) {
      grp->add_option(flag, s.*row.int_field, help)->capture_default_str();
    } else {
      grp->add_option(flag, s.*row.float_field, help)->capture_default_str();
    }
  }
}

bool parse_resolution(const std::string& text, int& w, int& h) {
  unsigned long long pw = 0, ph = 0;
  char x = 0, extra = 0;
  if (std::sscanf(text.c_str(), "%llu%c%llu%c", &pw, &x, &ph, &extra) != 3 ||
      (x != 'x' && x != 'X'))
    return false;
  if (pw > 1000000 || ph > 1000000) return false;
  w = static_cast<int>(pw);
  h = static_cast<int>(ph);
  return true;
}

// --bounce-ray-order of render and reference (PathTracerSettings::bounce_ray_order).
void add_bounce_ray_order(CLI::App* cmd, std::string& order) {
  cmd->add_option("--bounce-ray-order", order,
                  "Order of each bounce's rays for Embree: grouped (by direction octant and the "
                  "origin's cell of a coarse grid), listed (as the path blocks list them) or auto "
                  "(listed where the scene's BVH fits a core's cache, else whichever of the two "
                  "the first passes time faster); the images are the same")
      ->check(CLI::IsMember({"auto", "grouped", "listed"}))
      ->capture_default_str();
}

}  // namespace

int main(int argc, char** argv) {
  rtpg::request_pinned_cpu_device_threads();  // before any OpenCL call
  CLI::App app{"rtpg: real-time screen-space path guiding (Embree + OpenCL)"};
  app.require_subcommand(1);

  rtpg::RenderCommand render;
  std::string render_res = "640x360";
  auto* render_cmd = app.add_subcommand("render", "Render frames of a scene");
  add_common(render_cmd, render.common, false, kHostWork | kDevice);
  render_cmd->add_option("--res", render_res, "Resolution WxH")->capture_default_str();
  render_cmd->add_option("--spp", render.settings.spp, "Samples per pixel per frame")
      ->capture_default_str();
  render_cmd->add_option("--frames", render.frames, "Number of frames")->capture_default_str();
  render_cmd->add_option("--seed", render.settings.seed, "Random seed")->capture_default_str();
  render_cmd->add_flag(
      "--no-jitter", [&](std::int64_t) { render.settings.jitter = false; },
      "Sample pixel centres (no sub-pixel jitter)");
  render_cmd->add_option("--camera-path", render.settings.camera_path,
                         "Named camera path of the scene");
  render_cmd->add_option(
      "--max-bounces", render.max_bounces,
      "Path vertices after the primary hit (default: the scene's integrator.max_bounces, else 8)");
  render_cmd->add_flag(
      "--no-nee", [&](std::int64_t) { render.settings.path_tracer.next_event = false; },
      "BSDF sampling only (no next-event estimation)");
  render_cmd
      ->add_option("--share-randoms", render.share_randoms,
                   "Diagnostic: every sample of a frame reuses sample 0's random numbers for the "
                   "first bounce (first-bounce), also for the next-event estimate at the primary "
                   "hit (primary-vertex), and also for the light sample and bounce at the first "
                   "bounce's hit (second-vertex), so --spp averages only the rest of the path "
                   "(bench/variance_split.py); none is the renderer")
      ->check(CLI::IsMember({"none", "first-bounce", "primary-vertex", "second-vertex"}))
      ->capture_default_str();
  add_bounce_ray_order(render_cmd, render.bounce_ray_order);
  render_cmd->add_option("-o,--output", render.output,
                         "Last frame: .exr (linear) or .png (tonemapped)");
  render_cmd
      ->add_option("--save-frames", render.save_frames,
                   "Also write these frames (0-based, comma-separated) beside --output (and "
                   "--noisy-output) as NAME-fNNNN.EXT")
      ->delimiter(',');
  render_cmd->add_option("--reference", render.reference, "Reference EXR: relMSE per frame");
  render_cmd->add_flag(
      "--accumulate", render.accumulate,
      "Output the running mean of all frames (a static camera: not with --camera-path); adds "
      "relmse_accumulated");
  render_cmd->add_option("--stats-json", render.stats_json, "Write per-frame statistics as JSON");
  add_guiding_options(render_cmd, render);
  add_denoise_options(render_cmd, render);

  rtpg::ReferenceCommand reference;
  std::string reference_res = "640x360";
  auto* reference_cmd = app.add_subcommand("reference", "Render a many-sample reference image");
  add_common(reference_cmd, reference.common, true, kHostWork);
  reference_cmd->add_option("--res", reference_res, "Resolution WxH")->capture_default_str();
  reference_cmd->add_option("--spp", reference.spp, "Samples per pixel")->capture_default_str();
  reference_cmd->add_option("--seed", reference.seed, "Random seed")->capture_default_str();
  reference_cmd->add_option("-o,--output", reference.output, "Output EXR")->required();
  reference_cmd->add_option("--stats-json", reference.stats_json,
                            "Write the render time and samples per second as JSON");
  reference_cmd->add_option("--camera-path", reference.camera_path,
                            "Named camera path of the scene");
  reference_cmd
      ->add_option("--frame", reference.frame, "Frame of the camera path (its time is frame / fps)")
      ->capture_default_str();
  add_bounce_ray_order(reference_cmd, reference.bounce_ray_order);
  reference_cmd->add_option("--max-bounces", reference.max_bounces,
                            "Path vertices after the primary hit (default: the scene's, else 8)");

  rtpg::CommonArguments info;
  auto* info_cmd = app.add_subcommand("info", "Describe a scene");
  add_common(info_cmd, info, true, kSceneOnly);

  app.add_subcommand("devices", "List OpenCL devices");

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "rtpg: %s\n", e.what());
    return 2;
  }

  try {
    // The host's thread pool for the whole run (TBB: every parallel loop of the renderer).
    const int threads = *render_cmd      ? render.common.threads
                        : *reference_cmd ? reference.common.threads
                                         : 0;
    std::unique_ptr<tbb::global_control> thread_limit;
    if (threads > 0)
      thread_limit = std::make_unique<tbb::global_control>(
          tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(threads));
    if (*render_cmd) {
      if (!parse_resolution(render_res, render.settings.width, render.settings.height))
        throw rtpg::InputError("--res", "expected WxH, got '" + render_res + "'");
      if (!rtpg::parse_train_memory(render.train_memory, render.guiding_settings.train_memory))
        throw rtpg::InputError("--pg-train-memory", "unknown value '" + render.train_memory + "'");
      return rtpg::run_render(render);
    }
    if (*reference_cmd) {
      if (!parse_resolution(reference_res, reference.width, reference.height))
        throw rtpg::InputError("--res", "expected WxH, got '" + reference_res + "'");
      return rtpg::run_reference(reference);
    }
    if (*info_cmd) return rtpg::run_info(info);
    return rtpg::run_devices();
  } catch (const rtpg::InputError& e) {
    std::fprintf(stderr, "rtpg: %s\n", e.what());
    return 2;
  } catch (const rtpg::GuiderError& e) {
    std::fprintf(stderr, "rtpg: %s\n", e.what());
    return 2;
  } catch (const rtpg::ClError& e) {
    std::fprintf(stderr, "rtpg: OpenCL: %s\n", e.what());
    return 3;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rtpg: %s\n", e.what());
    return 1;
  }
}
