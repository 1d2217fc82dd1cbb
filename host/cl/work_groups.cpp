#include "cl/work_groups.h"

#include <algorithm>

namespace rtpg {

WorkGroupShape resolve_work_groups(const DeviceInfo& info, int local_x, int local_y,
                                   KernelReach reach, std::size_t max_group) {
  WorkGroupShape shape;
  if (local_x != 0 || local_y != 0) {
    shape.x = local_x;
    shape.y = local_y;
    return shape;
  }
  if (info.type != "cpu" || reach == KernelReach::Neighbourhood) return shape;
  // Pixel and GlobalNeighbourhood kernels on a CPU: rows.
  shape.rows = true;
  shape.x =
      static_cast<int>(std::min<std::size_t>(kRowGroupItems, std::max<std::size_t>(max_group, 1)));
  shape.y = 1;
  return shape;
}

std::size_t largest_row_group(const cl::Device& device,
                              std::initializer_list<cl::Kernel*> kernels) {
  std::size_t largest = device.getInfo<CL_DEVICE_MAX_WORK_ITEM_SIZES>().at(0);
  for (cl::Kernel* k : kernels)
    largest = std::min(largest, k->getWorkGroupInfo<CL_KERNEL_WORK_GROUP_SIZE>(device));
  return largest;
}

ImageLaunch image_launch(int width, int height, int lanes, const WorkGroupShape& shape) {
  const int items = (width + lanes - 1) / lanes;  // work-items per row
  auto round_up = [](int v, int m) { return static_cast<std::size_t>((v + m - 1) / m * m); };
  if (shape.rows) {
    // Equal groups: 120 work-items a row make one group of 120, not one of 128 with 8 idle.
    const int groups = (items + shape.x - 1) / shape.x;
    const int group = (items + groups - 1) / groups;
    return {cl::NDRange(round_up(items, group), static_cast<std::size_t>(height)),
            cl::NDRange(static_cast<std::size_t>(group), 1)};
  }
  return {cl::NDRange(round_up(items, shape.x), round_up(height, shape.y)),
          cl::NDRange(static_cast<std::size_t>(shape.x), static_cast<std::size_t>(shape.y))};
}

}  // namespace rtpg
