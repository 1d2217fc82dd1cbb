// The subcommands of the rtpg program. main.cpp parses flags into these commands.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "denoise/svgf_settings.h"
#include "render/renderer.h"
#include "rtpg/guider.h"

namespace rtpg {

struct CommonArguments {
  std::string scene;       // "" = the built-in default scene
  std::string asset_root;  // "" = RTPG_ASSET_ROOT or ../shared/scenes
  std::string device;      // "" = RTPG_DEVICE or a GPU, else the CPU
  int threads = 0;         // host worker threads; 0 = one per core (TBB's default)
  bool quiet = false;
};

struct RenderCommand {
  CommonArguments common;
  RenderSettings settings;
  int frames = 1;
  bool accumulate = false;       // output = running mean of all frames instead of the last one
  int max_bounces = 0;           // 0 = the scene's integrator.max_bounces, else the default
  std::string output;            // .exr or .png; "" = none
  std::vector<int> save_frames;  // also written beside `output` (frame_output_path)
  std::string reference;         // EXR to compute relMSE against
  std::string stats_json;        // "" = none
  std::string guiding = "pmm";   // "off" or "pmm"
  std::string guide_direct_light = "mis";  // "off" or "mis": the VPLs carry y's emission
                                           // with its MIS weight (PathTracerSettings)
  std::string first_bounce_mis = "bsdf";   // "bsdf" or "mixture": FirstBounceMis by name
                                           // (host/render/path_tracer.h)
  std::string guide_vertices = "first";    // "first" (the paper) or "all" (secondary vertices
                                           // borrow the mixture of the pixel showing them)
                                           // or "world" (the world-space guide's
                                           // cells, render/world_guide.h)
  int world_guide_resolution = 32;         // --world-guide-resolution
  int world_guide_max_depth = 2;           // --world-guide-max-depth (0: every vertex)
  int world_guide_record_every = 1;        // --world-guide-record-every
  float world_guide_min_pi = 0.0f;         // --world-guide-min-pi
  float world_guide_pi_max = -1.0f;        // --world-guide-pi-max (< 0: the pixels' --pg-pi-max)
  std::string share_randoms = "none";      // --share-randoms: SharedRandoms by name
  std::string bounce_ray_order = "auto";   // --bounce-ray-order: BounceRayOrder by name
                                           // (host/render/path_tracer.h)
  GuidingSettings guiding_settings;
  std::string train_memory = "auto";
  std::string host_transfer = "auto";   // parse_host_transfer (host/render/guided_first_bounce.h)
  std::string train_overlap = "auto";   // parse_overlap (host/render/guided_first_bounce.h)
  std::string sample_overlap = "auto";  // parse_overlap (host/render/guided_first_bounce.h)
  std::string denoise = "off";          // "off" or "svgf" (docs/denoising.md)
  SvgfSettings svgf_settings;
  std::string noisy_output;  // with --denoise: the unfiltered last frame; "" = none
};

struct ReferenceCommand {
  CommonArguments common;
  int width = 640, height = 360, spp = 1024;
  std::uint32_t seed = 0;
  int max_bounces = 0;      // 0 = the scene's, else the default
  std::string camera_path;  // "" = static camera
  int frame = 0;            // the camera path's frame to render
  std::string output;
  std::string stats_json;                 // "" = none; else spp, time and samples per second
  std::string bounce_ray_order = "auto";  // --bounce-ray-order: BounceRayOrder by name
};

// Where --save-frames writes frame `frame` of a render whose --output is `output`:
// "dir/name.exr" -> "dir/name-f0007.exr".
std::string frame_output_path(const std::string& output, int frame);

int run_render(const RenderCommand& command);
int run_reference(const ReferenceCommand& command);
int run_info(const CommonArguments& command);
int run_devices();

// The scene used when none is given: scenes/cornell-box.json of the source tree or of the
// installed share folder.
std::string default_scene_path();

}  // namespace rtpg
