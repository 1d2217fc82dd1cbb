/* rtpg's data layouts: the one description of every per-pixel buffer the guiding kernels
 * read or write, their flag bits and strategies, the random-stream tags, and the settings
 * block the kernels take by value. Plain C: the OpenCL C kernels include it (kernels/, every .cl),
 * the C++ host includes it (include/rtpg/guider.h), and so can a C renderer.
 *
 * Every buffer is one entry per pixel, row-major (pixel i = y * width + x), structure of
 * arrays. The channel lists below are X-macros: X(name, type, bytes) with type an OpenCL C
 * type name (float4, float2, uint) and bytes its size. Host structs, allocation, uploads,
 * size checks and kernel arguments are all generated from them (docs/design.md, "Data
 * layouts"), so a channel is added or changed here and nowhere else. */
#ifndef RTPG_GUIDING_LAYOUT_H
#define RTPG_GUIDING_LAYOUT_H

/* ---- G-buffer: what the camera ray hit, per pixel -------------------------------------- */
/* position_depth       xyz world position of the primary hit, w its linear depth (0 on sky)
 * shading_normal       xyz unit shading normal facing the camera (the guiding hemisphere), w 0
 * view_dir             xyz unit vector from the surface towards the camera, w 0
 * base_color_roughness rgb base colour, w perceptual roughness (alpha = roughness^2)
 * metallic_specular    x metallic, y dielectric F0 (0 = no GGX lobe), zw 0
 * flags                PG_GBUF_* bits
 * material             material id: reprojection keeps history only on the same material
 * motion               offset in pixels from this pixel to where its point was last frame */
#define PG_GBUFFER_CHANNELS(X)        \
  X(position_depth, float4, 16)       \
  X(shading_normal, float4, 16)       \
  X(view_dir, float4, 16)             \
  X(base_color_roughness, float4, 16) \
  X(metallic_specular, float4, 16)    \
  X(flags, uint, 4)                   \
  X(material, uint, 4)                \
  X(motion, float2, 8)

/* ---- Packed G-buffer: the G-buffer as it crosses the bus -----------------------------------
 * Where the device has memory of its own, the host packs each pixel into these 24 bytes
 * (kernels/shared/gbuffer_packing.h, which packs and unpacks them) and the device's
 * unpack_gbuffer kernel writes PG_GBUFFER_CHANNELS from them and the frame's cameras
 * (pg_gbuffer_cameras below; rtpg::Guider::unpack_gbuffer): the position is the depth along
 * the pixel's camera ray, the view direction that ray's reverse, the motion vector where the
 * position was in last frame's camera, so none of them travels.
 * surface  x the depth's float bits, y the shading normal (octahedral), z base colour r and g
 *          as half floats, w base colour b and roughness as half floats (low half first)
 * shading  x metallic and specular as half floats, y the flags (low 8 bits) and the material
 *          id (the high 24) */
#define PG_PACKED_GBUFFER_CHANNELS(X) \
  X(surface, uint4, 16)               \
  X(shading, uint2, 8)

/* Pixels guiding skips (paper, section 5: sky, emitters, transmission, roughness near 0). */
#define PG_GBUF_SKY 1u          /* camera ray escaped: no surface */
#define PG_GBUF_EMITTER 2u      /* surface emits towards the camera */
#define PG_GBUF_DELTA 4u        /* roughness at or below the delta threshold */
#define PG_GBUF_TRANSMISSIVE 8u /* transmissive material */

/* ---- VPLs: the first-bounce hit y of every pixel's path, the trainer's input -------------
 * (paper, section 3.1: the texture Pi)
 * position          xyz hit point y (or the unit direction of an escaped ray); w the density
 *                   of the strategy that generated y (the BSDF's for a BSDF sample, else D), in
 *                   area measure at y (solid angle for an escaped ray), so that a neighbouring
 *                   pixel can convert it to its own solid angle
 * normal_radiance   packed (kernels/shared/vpl_packing.h, which packs and unpacks it): the
 *                   geometric normal at y (facing the pixel's point; octahedral), the full
 *                   mixture density D of the direction whatever the strategy (area measure at
 *                   y, solid angle for an escaped ray; exact), the rgb radiance leaving y
 *                   towards the pixel's point (bfloat16) and the info word: PG_VPL_* bits, the
 *                   strategy in bits 8..15 */
#define PG_VPL_CHANNELS(X) \
  X(position, float4, 16)  \
  X(normal_radiance, uint4, 16)

/* ---- Packed VPLs: the VPLs as they cross the bus ------------------------------------------
 * Where the device has memory of its own, the host sends each pixel's VPL in these 10 bytes
 * (kernels/shared/vpl_packing.h packs and unpacks them) and the device's unpack_vpls kernel
 * writes PG_VPL_CHANNELS from them, the device's G-buffer and the frame's first samples
 * (rtpg::Guider::unpack_vpls): the hit lies along the direction the device sampled, whose
 * densities and strategy the device has, so only its distance, normal and radiance travel.
 * distance  the distance from the pixel's point to y (the float's bits; +infinity: an escaped
 *           ray, PG_VPL_DISTANT; 0: no VPL, PG_VPL_VALID clear)
 * radiance  the rgb radiance leaving y towards the pixel's point, shared exponent
 *           (pg_pack_rgbe, kernels/shared/bit_packing.h)
 * normal    the geometric normal at y, octahedral in two 8-bit signed normalised integers
 *           (pg_pack_unit_vector8) */
#define PG_PACKED_VPL_CHANNELS(X) \
  X(distance, uint, 4)            \
  X(radiance, uint, 4)            \
  X(normal, ushort, 2)

#define PG_VPL_VALID 1u
#define PG_VPL_DISTANT 2u /* escaped ray: position holds a direction */
#define PG_VPL_STRATEGY_SHIFT 8u
#define PG_VPL_STRATEGY(info) (((info) >> PG_VPL_STRATEGY_SHIFT) & 0xffu)

/* ---- Samples: what the sample kernel writes ---------------------------------------------
 * direction_pdf  xyz unit world direction of the first bounce, w the mixture's density in
 *                solid angle (0 = no sample)
 * strategy       PG_STRATEGY_* that produced it
 * mixture_a      the mixture the pixel sampled, in the form the density needs (paper eq. 2):
 *                x pi, yz the Gaussian's mean in the square, w the Cholesky factor's l11
 *                (0: no Gaussian, the pixel samples its BSDF alone)
 * mixture_b      x l21, y l22: the rest of the Cholesky factor of Sigma
 * With the mixture a host renderer evaluates the density for its MIS weights
 * (include/rtpg/guiding_distribution.h) without the state or its regularisation; a renderer
 * that does not can ask the kernel to leave mixture_a and mixture_b unwritten
 * (rtpg::SampleOutputs::directions in include/rtpg/guider.h). */
#define PG_SAMPLE_CHANNELS(X)  \
  X(direction_pdf, float4, 16) \
  X(strategy, uint, 4)         \
  X(mixture_a, float4, 16)     \
  X(mixture_b, float2, 8)

/* ---- Packed samples: the samples as they cross the bus back -----------------------------
 * Where the device has memory of its own, the pack_samples kernel writes each pixel's sample in
 * these 12 bytes (kernels/shared/sample_packing.h packs and unpacks them) and the host reads
 * them instead of direction_pdf and strategy (rtpg::Guider::pack_samples).
 * direction     the unit direction's point on the octahedron, folded into the square (two floats)
 * pdf_strategy  direction_pdf.w with the strategy in its sign bit (set: PG_STRATEGY_GUIDE) */
#define PG_PACKED_SAMPLE_CHANNELS(X) \
  X(direction, float2, 8)            \
  X(pdf_strategy, float, 4)

/* ---- Counts: what the host's statistics need, one record per work-group ---------------
 * The sample and train kernels each sum, over their work-group, one float4 of counts into the
 * group's record (group g = get_group_id(1) * get_num_groups(0) + get_group_id(0)), so the host
 * reads a few bytes per frame instead of a per-pixel buffer (docs/design.md, "What crosses the
 * bus"). Whole counts are exact in float: a group holds at most a few thousand pixels.
 * sample  x surface pixels (not PG_GBUF_SKY), y those whose mixture has a Gaussian (a valid
 *         model: mixture_a.w > 0), z the sum of their pi, w 0 (written at every sample)
 * train   x pixels whose state the step changed, yzw 0 */
#define PG_COUNT_RECORD_BYTES 16

#define PG_STRATEGY_NONE 0u  /* no surface, or no sample */
#define PG_STRATEGY_BSDF 1u  /* the BSDF component: the only samples that train (paper 3.2) */
#define PG_STRATEGY_GUIDE 2u /* the Gaussian component */

/* ---- Guiding state: the per-pixel mixture, kept by the guider --------------------------
 * state0  (W, S0, Sx, Sy)    running means of the EM sufficient statistics
 * state1  (Sxx, Syy, Sxy, k) second moments and the epoch count k (0 = no model)
 * (the model they define: kernels/shared/pmm.h). Host copies interleave them: 8 floats per
 * pixel, state0 then state1. */
#define PG_STATE_CHANNELS(X) \
  X(state0, float4, 16)      \
  X(state1, float4, 16)
#define PG_STATE_FLOATS_PER_PIXEL 8

/* ---- Shared models: which pixels sample with their row group's model, kept by the guider ---
 * With rows_per_model > 1 (docs/guiding.md, "Models shared by rows"), one byte per pixel:
 * shares_model  1 where the pixel samples with the model of the pixel above it in its group's
 *               first row (pg_model_pixel, kernels/shared/guiding_pixel.h), else 0 (every
 *               pixel of a group's first row, every pixel guiding skips)
 * Decided once a frame, by the frame's first kernel that needs it (reproject, else the first
 * sample), from the frame's G-buffer, and read by the frame's later sample and train kernels
 * instead of deciding again (docs/guiding.md, "Which pixels share, decided once a frame"). */
#define PG_SHARES_MODEL_BYTES 1

/* ---- Random streams ---------------------------------------------------------------------
 * Every consumer draws from its own stream per (seed, pixel, frame, sample) (kernels/shared/
 * rng.h): these tags keep the consumers independent. */
#define PG_RNG_STREAM_PATH 0u         /* the host path tracer */
#define PG_RNG_STREAM_FIRST_BOUNCE 1u /* first-bounce sampling: sample kernel, BSDF sampler */
#define PG_RNG_STREAM_CAMERA 2u       /* the camera ray's sub-pixel jitter */
#define PG_RNG_STREAM_TRAIN 3u        /* the train kernel's walk through the neighbourhood */

/* At most this many neighbour VPLs train a pixel per frame (the train kernel's array). */
#define PG_MAX_TRAIN_SAMPLES 32

/* ---- Cameras: what unpack_gbuffer derives a packed G-buffer's position, view direction and
 * motion from (kernels/shared/gbuffer_packing.h), passed by value like the settings below.
 * A pinhole camera: its position, its orthonormal right, up and forward (the view direction),
 * tan(fov_y / 2) and the image's aspect (width / height); film point (sx, sy) in [0, 1]^2 (top
 * left (0, 0)) looks along normalize(forward + (2 sx - 1) tan_half_fov_y aspect right
 * + (1 - 2 sy) tan_half_fov_y up) (host: rtpg::CameraFrame). Pixel (x, y)'s ray passes through
 * film point ((x + jx) / width, (y + jy) / height), with (jx, jy) the first two numbers of its
 * stream (jitter_seed, pixel y * width + x, jitter_frame, sample 0, PG_RNG_STREAM_CAMERA), or
 * (0.5, 0.5) without jitter: the renderer's camera rays (host/render/camera_rays.h). */
#ifdef __cplusplus
namespace rtpg {
#endif

typedef struct pg_pinhole_camera {
  float position_x, position_y, position_z;
  float right_x, right_y, right_z;
  float up_x, up_y, up_z;
  float forward_x, forward_y, forward_z;
  float tan_half_fov_y;
  float aspect;
} pg_pinhole_camera;

typedef struct pg_gbuffer_cameras {
  pg_pinhole_camera current;  /* the frame's: depth = dot(p - position, forward), view direction */
  pg_pinhole_camera previous; /* last frame's: where each point was (the motion vector) */
  int width, height;          /* the image */
  int moved;                  /* 0: the motion is zero (a static camera, whatever the jitter) */
  int jitter;                 /* 0: every ray through its pixel's centre */
  unsigned int jitter_seed, jitter_frame; /* the rays' jitter streams */
} pg_gbuffer_cameras;

#ifdef __cplusplus
} /* namespace rtpg */
#endif

/* ---- Kernel settings --------------------------------------------------------------------
 * Every tunable of the guiding kernels, passed by value. Plain 4-byte fields only, so host
 * and device agree on the layout (checked by static_assert on the host). The host builds it
 * once from rtpg::GuidingSettings (include/rtpg/guiding_settings.h), which documents each. */
#ifdef __cplusplus
namespace rtpg {
#endif

typedef struct pg_kernel_settings {
  float pi_min;          /* clamp of the mixing weight (paper: 0.05) */
  float pi_max;          /* (paper: 0.95; rtpg: 0.5, docs/guiding.md) */
  float pi_init;         /* weight of a new model (paper: 0.05) */
  float k_max;           /* epochs after which the step size stops shrinking */
  float step_alpha;      /* eta_k = max((k+1)^-alpha, 1/(k_max+1)) */
  float sigma_eps;       /* added to Sigma's diagonal: keeps it positive definite */
  float max_correlation; /* |rho| bound: keeps the Cholesky factor well conditioned */
  float roughness_skip;  /* no guiding where roughness is at or below this */
  float n_min;           /* N = (1 - k/k_max) * (n_max - n_min) + n_min (paper 4.2) */
  float n_max;
  float max_weight;         /* training weights above this are treated as absurd input */
  float reproject_position; /* relative position difference that rejects history */
  float reproject_normal;   /* cosine below which normals reject history */
  float sigma_prior;        /* prior variance added as sigma_prior / (k + 1) */
  float reseed_ratio;       /* a sample with a > reseed_ratio * W outside the lobe re-seeds */
  float weight_clamp;       /* training weights are clamped to weight_clamp * W (0 = off) */
  int em_passes;            /* E-step passes over a frame's samples (pg_pmm_train) */
  int apron;                /* neighbourhood radius in pixels (window 2*apron+1 squared) */
  int stride;               /* step through the window, coprime with its size */
  int train_interval;    /* a mature pixel (k >= k_max / 4) trains every train_interval-th frame */
  int train_all_samples; /* 1: train on every VPL at its full mixture density (normal.w);
                            0: BSDF-strategy VPLs only (paper 3.2) */
  int reseed_samples;    /* samples of one batch that must call for a re-seed before it happens */
  int pi_learning;       /* 1: the mixing weight minimises the first bounce's second moment;
                            0: EM's weight (paper 3.2) */
  float reproject_view_memory; /* a glossy model's k falls by 1/e per this many GGX alphas of
                                  view turn (pg_pmm_view_aged_k); 0: k survives reprojection */
  int rows_per_model; /* 1, 2, 4 or 8: a pixel samples with the model of the first pixel of its
                         group of this many rows where the two may share one (pg_shares_model),
                         and then does not train its own */
} pg_kernel_settings;

#ifdef __cplusplus
} /* namespace rtpg */
#endif

#endif /* RTPG_GUIDING_LAYOUT_H */
