// The NDRange of the image kernels (kernels/*.cl: one work-item per `lanes` consecutive pixels of
// a row, work-items past the image return at once) and the shape of their work-groups, shared by
// the guider and the denoiser (docs/design.md, "PoCL and OpenCL facts").
#pragma once

#include <cstddef>
#include <initializer_list>

#include "rtpg/cl_runtime.h"
#include "rtpg/opencl.h"

namespace rtpg {

// Row work-groups hold at most this many work-items: on PoCL's CPU device 128 or 160 were the
// fastest of 40, 128, 160 and 640 (docs/guiding.md, "Work-groups along rows").
constexpr int kRowGroupItems = 128;

// A resolved work-group shape: a tile of x by y work-items, or (rows) runs of at most x
// work-items along one row, as many per row as the row needs and all of one length.
struct WorkGroupShape {
  bool rows = false;
  int x = 16, y = 16;
};

// What a kernel's work-item reads around its own pixels: its pixels alone (or one gathered
// pixel: reproject, sample, SVGF's temporal and remodulate passes), a neighbourhood of them
// through a tile in local memory (train's VPL window), or a neighbourhood straight from global
// memory (SVGF's variance and a-trous filters).
enum class KernelReach { Pixel, Neighbourhood, GlobalNeighbourhood };

// The shape a kernel runs with. local_x and local_y are the settings' (both 0: chosen per
// device; non-zero: a tile as given, for every kernel). Chosen per device: on CPU devices, whose
// OpenCL runs a work-group as a loop over its work-items, pixel kernels run in rows of up to
// kRowGroupItems (and at most max_group) work-items, so that a group streams through memory;
// so do the kernels that read a neighbourhood from global memory (measured faster in rows than in
// tiles: docs/denoising.md, "Cost"); the kernel with a local-memory tile (train), and every
// kernel elsewhere, in a 16x16 tile, whose rows share the neighbourhood rows in cache
// (docs/guiding.md, "Work-groups along rows").
WorkGroupShape resolve_work_groups(const DeviceInfo& info, int local_x, int local_y,
                                   KernelReach reach, std::size_t max_group);

// The most work-items one row group of these kernels may hold on the device: the smallest of
// their CL_KERNEL_WORK_GROUP_SIZE and the device's first CL_DEVICE_MAX_WORK_ITEM_SIZES.
std::size_t largest_row_group(const cl::Device& device, std::initializer_list<cl::Kernel*> kernels);

struct ImageLaunch {
  cl::NDRange global, local;
};

// The global and local ranges of an image kernel over width x height pixels, `lanes` pixels of a
// row per work-item. Rows: the row's work-items split into equal groups of at most shape.x.
ImageLaunch image_launch(int width, int height, int lanes, const WorkGroupShape& shape);

}  // namespace rtpg
