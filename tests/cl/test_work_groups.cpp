// The image kernels' launch shape (host/cl/work_groups.h): which shape a device gets, and that
// every launch covers the image with whole work-groups, rows split into equal groups.
#include <gtest/gtest.h>

#include "cl/work_groups.h"

namespace rtpg {
namespace {

DeviceInfo device_of_type(const std::string& type) {
  DeviceInfo info;
  info.type = type;
  return info;
}

TEST(WorkGroups, RowsForPixelKernelsOnCpusTilesElsewhereAndAsGiven) {
  const DeviceInfo cpu = device_of_type("cpu"), gpu = device_of_type("gpu");
  const WorkGroupShape rows = resolve_work_groups(cpu, 0, 0, KernelReach::Pixel, 4096);
  EXPECT_TRUE(rows.rows);
  EXPECT_EQ(rows.x, kRowGroupItems);
  EXPECT_EQ(rows.y, 1);
  // A kernel that allows fewer work-items per group caps the rows.
  EXPECT_EQ(resolve_work_groups(cpu, 0, 0, KernelReach::Pixel, 64).x, 64);
  // Filters that read their neighbourhood from global memory run in rows on CPUs too.
  const WorkGroupShape filter_rows =
      resolve_work_groups(cpu, 0, 0, KernelReach::GlobalNeighbourhood, 4096);
  EXPECT_TRUE(filter_rows.rows);
  EXPECT_EQ(filter_rows.x, kRowGroupItems);
  EXPECT_EQ(filter_rows.y, 1);
  // The kernel with a local-memory tile keeps it on CPUs; GPUs get a tile for every kernel.
  for (const WorkGroupShape& s :
       {resolve_work_groups(cpu, 0, 0, KernelReach::Neighbourhood, 4096),
        resolve_work_groups(gpu, 0, 0, KernelReach::Pixel, 1024),
        resolve_work_groups(gpu, 0, 0, KernelReach::Neighbourhood, 1024),
        resolve_work_groups(gpu, 0, 0, KernelReach::GlobalNeighbourhood, 1024)}) {
    EXPECT_FALSE(s.rows);
    EXPECT_EQ(s.x, 16);
    EXPECT_EQ(s.y, 16);
  }
  // A size given is a tile for every kernel.
  for (KernelReach reach :
       {KernelReach::Pixel, KernelReach::Neighbourhood, KernelReach::GlobalNeighbourhood}) {
    const WorkGroupShape given = resolve_work_groups(cpu, 12, 6, reach, 4096);
    EXPECT_FALSE(given.rows);
    EXPECT_EQ(given.x, 12);
    EXPECT_EQ(given.y, 6);
  }
}

TEST(WorkGroups, LaunchesCoverTheImageWithWholeGroups) {
  const WorkGroupShape rows{true, kRowGroupItems, 1};
  const WorkGroupShape tile{false, 16, 16};
  for (int width : {1, 7, 97, 128, 129, 300, 960, 1920})
    for (int lanes : {1, 8, 16})
      for (const WorkGroupShape& shape : {rows, tile}) {
        SCOPED_TRACE("width " + std::to_string(width) + ", lanes " + std::to_string(lanes) +
                     (shape.rows ? ", rows" : ", tile"));
        const int height = 23;
        const ImageLaunch l = image_launch(width, height, lanes, shape);
        const std::size_t items = static_cast<std::size_t>((width + lanes - 1) / lanes);
        ASSERT_EQ(l.global.dimensions(), 2u);
        EXPECT_EQ(l.global[0] % l.local[0], 0u);
        EXPECT_EQ(l.global[1] % l.local[1], 0u);
        EXPECT_GE(l.global[0], items);
        EXPECT_GE(l.global[1], static_cast<std::size_t>(height));
        if (shape.rows) {
          EXPECT_EQ(l.local[1], 1u);
          EXPECT_LE(l.local[0], static_cast<std::size_t>(kRowGroupItems));
          // Equal groups: fewer idle work-items per row than groups in it.
          const std::size_t groups = l.global[0] / l.local[0];
          EXPECT_LT(l.global[0] - items, groups);
          EXPECT_EQ(groups, (items + kRowGroupItems - 1) / kRowGroupItems);
        } else {
          EXPECT_EQ(l.local[0], 16u);
          EXPECT_LT(l.global[0] - items, 16u);
        }
      }
  // The widths of the docs: 960 pixels, one per work-item, in 8 groups of 120.
  const ImageLaunch l = image_launch(960, 540, 1, rows);
  EXPECT_EQ(l.local[0], 120u);
  EXPECT_EQ(l.global[0], 960u);
}

}  // namespace
}  // namespace rtpg
