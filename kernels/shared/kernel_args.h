/* Kernel parameter lists generated from the channel lists of include/rtpg/guiding_layout.h,
 * so that a kernel's signature, the host's clSetKernelArg calls (host/guiding/kernel_args.h)
 * and the buffers themselves come from one description. OpenCL C only.
 *
 * A guiding kernel's parameters come in this order: the current G-buffer (every channel, in
 * list order), then whatever lists the kernel needs (PG_ARGS_*), then the shared-model flags
 * where it reads or writes them (include/rtpg/guiding_layout.h, "Shared models"), then its
 * per-work-group counts (include/rtpg/guiding_layout.h, "Counts"), then its scalars, then its local
 * memory. */
#ifndef RTPG_SHARED_KERNEL_ARGS_H
#define RTPG_SHARED_KERNEL_ARGS_H

#include "rtpg/guiding_layout.h"

#define PG_ARG_IN(name, type, bytes) __global const type *name,
#define PG_ARG_IN_PREV(name, type, bytes) __global const type *prev_##name,
#define PG_ARG_IN_VPL(name, type, bytes) __global const type *vpl_##name,
#define PG_ARG_IN_STATE(name, type, bytes) __global const type *in_##name,
#define PG_ARG_OUT_STATE(name, type, bytes) __global type *out_##name,
#define PG_ARG_STATE(name, type, bytes) __global type *name,
#define PG_ARG_OUT(name, type, bytes) __global type *name,

#define PG_ARG_IN_PACKED(name, type, bytes) __global const type *packed_##name,
#define PG_ARG_OUT_PACKED(name, type, bytes) __global type *packed_##name,
#define PG_ARG_IN_SAMPLE(name, type, bytes) __global const type *sample_##name,
#define PG_ARG_OUT_VPL(name, type, bytes) __global type *vpl_##name,

#define PG_ARGS_GBUFFER PG_GBUFFER_CHANNELS(PG_ARG_IN)      /* this frame's G-buffer */
#define PG_ARGS_OUT_GBUFFER PG_GBUFFER_CHANNELS(PG_ARG_OUT) /* written by unpack_gbuffer */
#define PG_ARGS_PACKED_GBUFFER PG_PACKED_GBUFFER_CHANNELS(PG_ARG_IN_PACKED)
#define PG_ARGS_PREV_GBUFFER PG_GBUFFER_CHANNELS(PG_ARG_IN_PREV) /* last frame's */
#define PG_ARGS_VPLS PG_VPL_CHANNELS(PG_ARG_IN_VPL)
#define PG_ARGS_OUT_VPLS PG_VPL_CHANNELS(PG_ARG_OUT_VPL) /* written by unpack_vpls */
#define PG_ARGS_PACKED_VPLS PG_PACKED_VPL_CHANNELS(PG_ARG_IN_PACKED)
#define PG_ARGS_IN_STATE PG_STATE_CHANNELS(PG_ARG_IN_STATE)
#define PG_ARGS_OUT_STATE PG_STATE_CHANNELS(PG_ARG_OUT_STATE)
/* The state updated in place: train (each work-item reads and writes only its own pixels) and
 * sample (a pixel sharing its model stores it as its own; kernels/shared/guiding_pixel.h). */
#define PG_ARGS_STATE PG_STATE_CHANNELS(PG_ARG_STATE)
#define PG_ARGS_SAMPLES PG_SAMPLE_CHANNELS(PG_ARG_OUT)
#define PG_ARGS_IN_SAMPLES PG_SAMPLE_CHANNELS(PG_ARG_IN_SAMPLE) /* read by pack_samples */
#define PG_ARGS_PACKED_SAMPLES PG_PACKED_SAMPLE_CHANNELS(PG_ARG_OUT_PACKED)

/* The same lists as arguments of a call, for a kernel that hands its buffers to a function of
 * its own (a kernel with a work-group reduction at its end cannot return early). */
#define PG_PASS_CHANNEL(name, type, bytes) name,
#define PG_PASS_VPL_CHANNEL(name, type, bytes) vpl_##name,
#define PG_PASS_GBUFFER PG_GBUFFER_CHANNELS(PG_PASS_CHANNEL)
#define PG_PASS_VPLS PG_VPL_CHANNELS(PG_PASS_VPL_CHANNEL)
#define PG_PASS_STATE PG_STATE_CHANNELS(PG_PASS_CHANNEL)
#define PG_PASS_SAMPLES PG_SAMPLE_CHANNELS(PG_PASS_CHANNEL)

#endif
