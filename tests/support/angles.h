// The angle between two vectors, for tests that bound the error of an encoded direction.
#pragma once

#include <cmath>

#include "shared/compat.h"

namespace rtpg::testing {

// In double precision, by atan2 of the cross and dot products (a float dot product's rounding
// alone would read as 3e-4 rad through acos near 1).
inline double angle_between(shared::float3 a, shared::float3 b) {
  const double ax = a.x, ay = a.y, az = a.z, bx = b.x, by = b.y, bz = b.z;
  const double cx = ay * bz - az * by, cy = az * bx - ax * bz, cz = ax * by - ay * bx;
  return std::atan2(std::sqrt(cx * cx + cy * cy + cz * cz), ax * bx + ay * by + az * bz);
}

}  // namespace rtpg::testing
