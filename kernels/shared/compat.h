/* The one place that knows whether shared math is compiled as OpenCL C 1.2 or as C++17.
 *
 * Everything under kernels/shared/ includes only this file, each other and the public layout
 * header (include/rtpg/guiding_layout.h, plain C), so the same functions run in kernels and
 * in host code and tests (as Cycles' compat.h and pbrt-v4's
 * PBRT_CPU_GPU do). Shared code follows these rules so that both languages accept it:
 *   - vectors are float2/float3/float4 built with pg_make_float*; no swizzles, no vector
 *     ternaries, no vector literals;
 *   - functions are PG_FN (static inline in OpenCL C, inline in C++) and take values or
 *     private pointers only;
 *   - math uses the OpenCL built-in names (sqrt, fmax, dot, normalize, ...), which this file
 *     maps onto <cmath> and GLM for C++. */
#ifndef RTPG_SHARED_COMPAT_H
#define RTPG_SHARED_COMPAT_H

#ifdef __OPENCL_C_VERSION__

#define PG_FN static inline
#define PG_NAMESPACE_BEGIN
#define PG_NAMESPACE_END
#define pg_make_float2(x, y) ((float2)((x), (y)))
#define pg_make_float3(x, y, z) ((float3)((x), (y), (z)))
#define pg_make_float4(x, y, z, w) ((float4)((x), (y), (z), (w)))
#define pg_make_uint2(x, y) ((uint2)((x), (y)))
#define pg_make_uint4(x, y, z, w) ((uint4)((x), (y), (z), (w)))
#define pg_float4_xyz(v) ((v).xyz)
#define PG_PRIVATE __private

#else /* C++17 */

#include <cmath>
#include <cstdint>
#include <cstring>
#include <glm/glm.hpp>

#define PG_FN inline
#define PG_NAMESPACE_BEGIN \
  namespace rtpg {         \
  namespace shared {
#define PG_NAMESPACE_END \
  }                      \
  }
#define PG_PRIVATE

PG_NAMESPACE_BEGIN
typedef glm::vec2 float2;
typedef glm::vec3 float3;
typedef glm::vec4 float4;
typedef std::uint32_t uint;
typedef std::uint16_t ushort;
typedef std::uint64_t ulong;
typedef glm::uvec2 uint2;
typedef glm::uvec4 uint4;

using glm::cross;
using glm::dot;
using glm::length;
using glm::normalize;
using std::acos;
using std::atan2;
using std::cos;
using std::exp;
using std::fabs;
using std::floor;
using std::log;
using std::sin;
using std::sqrt;

PG_FN float2 pg_make_float2(float x, float y) {
  return float2(x, y);
}
PG_FN float3 pg_make_float3(float x, float y, float z) {
  return float3(x, y, z);
}
PG_FN float4 pg_make_float4(float x, float y, float z, float w) {
  return float4(x, y, z, w);
}
PG_FN uint2 pg_make_uint2(uint x, uint y) {
  return uint2(x, y);
}
PG_FN uint4 pg_make_uint4(uint x, uint y, uint z, uint w) {
  return uint4(x, y, z, w);
}
PG_FN float3 pg_float4_xyz(float4 v) {
  return float3(v.x, v.y, v.z);
}
/* OpenCL C's reinterpretations of a float's bits. */
PG_FN uint as_uint(float x) {
  uint u;
  std::memcpy(&u, &x, sizeof u);
  return u;
}
PG_FN float as_float(uint u) {
  float x;
  std::memcpy(&x, &u, sizeof x);
  return x;
}
/* fmax and fmin with the results of OpenCL C and glibc (the other operand where one is NaN, the
 * second where both compare equal, so signed zeros come out as glibc's, bit for bit), inline:
 * std::fmax is a call into libm, made several times per path vertex on the host
 * (docs/host-path-tracer.md, "Tried and kept"). */
PG_FN float fmax(float a, float b) {
  return (a > b || b != b) ? a : b;
}
PG_FN float fmin(float a, float b) {
  return (a < b || b != b) ? a : b;
}
PG_FN float clamp(float x, float lo, float hi) {
  return fmin(fmax(x, lo), hi);
}
PG_FN int isfinite(float x) {
  return std::isfinite(x) ? 1 : 0;
}
PG_FN float mix(float a, float b, float t) {
  return a + (b - a) * t;
}
PG_FN float3 mix(float3 a, float3 b, float t) {
  return a + (b - a) * t;
}
PG_FN float sign(float x) {
  return x > 0.0f ? 1.0f : (x < 0.0f ? -1.0f : 0.0f);
}
PG_FN float copysign(float x, float y) {
  return std::copysign(x, y);
}
PG_NAMESPACE_END

#endif

PG_NAMESPACE_BEGIN

#define PG_PI 3.14159265358979323846f
#define PG_INV_PI 0.31830988618379067154f
#define PG_TWO_PI 6.28318530717958647692f
#define PG_INV_TWO_PI 0.15915494309189533577f
#define PG_FLOAT_MAX 3.402823466e+38f

PG_FN float pg_sqr(float x) {
  return x * x;
}
PG_FN float pg_safe_sqrt(float x) {
  return sqrt(fmax(x, 0.0f));
}
PG_FN float pg_luminance(float3 c) {
  return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z;
}
PG_FN int pg_all_finite3(float3 v) {
  return isfinite(v.x) && isfinite(v.y) && isfinite(v.z);
}
PG_FN float pg_max3(float3 v) {
  return fmax(v.x, fmax(v.y, v.z));
}

/* Orthonormal basis around n (Duff et al. 2017, "Building an Orthonormal Basis, Revisited").
 * The hemisphere frame of a pixel: the guiding distribution lives in this frame, so
 * reprojection must use exactly this construction on both sides. */
typedef struct {
  float3 t;
  float3 b;
  float3 n;
} pg_frame;

PG_FN pg_frame pg_frame_from_normal(float3 n) {
  float s = copysign(1.0f, n.z);
  float a = -1.0f / (s + n.z);
  float b = n.x * n.y * a;
  pg_frame f;
  f.t = pg_make_float3(1.0f + s * n.x * n.x * a, s * b, -s * n.x);
  f.b = pg_make_float3(b, s + n.y * n.y * a, -n.y);
  f.n = n;
  return f;
}

PG_FN float3 pg_to_local(pg_frame f, float3 v) {
  return pg_make_float3(dot(v, f.t), dot(v, f.b), dot(v, f.n));
}

PG_FN float3 pg_to_world(pg_frame f, float3 v) {
  return f.t * v.x + f.b * v.y + f.n * v.z;
}

PG_NAMESPACE_END

#endif /* RTPG_SHARED_COMPAT_H */
