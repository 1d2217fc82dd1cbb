/* The per-work-group count records of the sample and train kernels (include/rtpg/guiding_layout.h,
 * "Counts"): a sum over the work-group of one float4 per work-item, in local memory. OpenCL C
 * only. Every work-item of the group must reach it (it has barriers), so a kernel that calls it
 * cannot return early. */
#ifndef RTPG_SHARED_WORK_GROUP_SUM_H
#define RTPG_SHARED_WORK_GROUP_SUM_H

#ifdef __OPENCL_C_VERSION__

/* Pairwise sums from the halves of the smallest power of two at or above the group's size, so
 * any size works (rows of 120 work-items on CPU devices); scratch holds one float4 per
 * work-item. Work-item (0, 0) writes the sum into the group's record. */
static inline void pg_store_work_group_counts(__global float4* records, __local float4* scratch,
                                              float4 value) {
  uint n = (uint)(get_local_size(0) * get_local_size(1));
  uint i = (uint)(get_local_id(1) * get_local_size(0) + get_local_id(0));
  scratch[i] = value;
  barrier(CLK_LOCAL_MEM_FENCE);
  uint stride = 1u;
  while (stride < n) stride <<= 1;
  for (stride >>= 1; stride > 0u; stride >>= 1) {
    if (i < stride && i + stride < n) scratch[i] += scratch[i + stride];
    barrier(CLK_LOCAL_MEM_FENCE);
  }
  if (i == 0u) records[get_group_id(1) * get_num_groups(0) + get_group_id(0)] = scratch[0];
}

#endif

#endif
