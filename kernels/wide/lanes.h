/* Several pixels per work-item in OpenCL vector types (docs/guiding.md, "Several pixels per
 * work-item"): PG_LANES (2, 4, 8 or 16, a build option) pixels of one row run in the lanes of
 * floatN/intN, so a CPU device's compiler emits SIMD code for loops whose trip counts differ
 * from pixel to pixel, which a work-group vectoriser cannot do. OpenCL C only.
 *
 * Conventions: a comparison gives an intN mask (-1 true, 0 false), select(a, b, mask) takes b
 * where the mask is set, and a lane whose work is done or absent is masked, never branched
 * around. A work-item's lanes are consecutive pixels of a row, so their G-buffer and state
 * channels load as vectors (pg_load_row_float4_rows), lane by lane only at the row's right end;
 * the sample kernel stores its results the same way (pg_store_row_float4_rows; the train
 * kernel's state, stored so, was 3% slower: docs/guiding.md, "Samples stored as vectors"). */
#ifndef RTPG_WIDE_LANES_H
#define RTPG_WIDE_LANES_H

#ifndef PG_LANES
#define PG_LANES 8
#endif

/* The float4 row loads below (pg_load_float4_rows, pg_load_row_float4_rows) are small, but
 * PoCL's compiler (clang) kept them out of line, their output rows passed through memory: train
 * and sample kernels 17% and 11% slower (docs/guiding.md, "Training in place; row loads
 * inlined"). Forced inline where the compiler is clang, elsewhere its choice. Not the float row
 * loads: forced inline in the a-trous filter's 25 taps, they made it 30% slower. */
#ifdef __clang__
#define PG_ROW_LOAD static inline __attribute__((always_inline))
#else
#define PG_ROW_LOAD static inline
#endif

#define PG_PASTE2(a, b) a##b
#define PG_PASTE(a, b) PG_PASTE2(a, b)
#define pg_floatw PG_PASTE(float, PG_LANES)
#define pg_intw PG_PASTE(int, PG_LANES)
#define pg_uintw PG_PASTE(uint, PG_LANES)
#define pg_vloadw PG_PASTE(vload, PG_LANES)
#define pg_vstorew PG_PASTE(vstore, PG_LANES)
#define pg_convert_uintw PG_PASTE(convert_uint, PG_LANES)
#define pg_convert_intw PG_PASTE(convert_int, PG_LANES)
#define pg_convert_floatw PG_PASTE(convert_float, PG_LANES)
#define pg_ucharw PG_PASTE(uchar, PG_LANES)
#define pg_convert_ucharw PG_PASTE(convert_uchar, PG_LANES)

/* Three coordinates of PG_LANES points or directions. */
typedef struct {
  pg_floatw x, y, z;
} pg_float3w;

static inline pg_float3w pg_make_float3w(pg_floatw x, pg_floatw y, pg_floatw z) {
  pg_float3w v;
  v.x = x;
  v.y = y;
  v.z = z;
  return v;
}

/* The lane numbers 0 .. PG_LANES - 1. */
static inline pg_intw pg_lane_numbers(void) {
#if PG_LANES == 16
  return (int16)(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
#elif PG_LANES == 8
  return (int8)(0, 1, 2, 3, 4, 5, 6, 7);
#elif PG_LANES == 4
  return (int4)(0, 1, 2, 3);
#else
  return (int2)(0, 1);
#endif
}

/* One float4 of one lane into four private rows (rows field..field+3), as the wide kernels'
 * lane-by-lane paths gather them before loading the rows as vectors. */
static inline void pg_put4_rows(__private float (*rows)[PG_LANES], int field, int lane, float4 v) {
  rows[field][lane] = v.x;
  rows[field + 1][lane] = v.y;
  rows[field + 2][lane] = v.z;
  rows[field + 3][lane] = v.w;
}

/* PG_LANES consecutive float4 (one per lane, as a channel of consecutive pixels) turned into
 * four rows: the x, y, z and w of every lane (a transposition by swizzles, no scalar code).
 * pg_load_uint4_rows does the same for uint4: a channel of packed words is loaded as integers,
 * never through float registers, where a device may flush a word that reads as a denormal. One
 * body for both element types (OpenCL C has no templates). */
#if PG_LANES == 16
#define PG_LOAD_4_ROWS_BODY(T)                                                                   \
  PG_PASTE(T, 16) a = vload16(0, f), b = vload16(1, f), c = vload16(2, f), d = vload16(3, f);    \
  *x = (PG_PASTE(T, 16))(a.s0, a.s4, a.s8, a.sc, b.s0, b.s4, b.s8, b.sc, c.s0, c.s4, c.s8, c.sc, \
                         d.s0, d.s4, d.s8, d.sc);                                                \
  *y = (PG_PASTE(T, 16))(a.s1, a.s5, a.s9, a.sd, b.s1, b.s5, b.s9, b.sd, c.s1, c.s5, c.s9, c.sd, \
                         d.s1, d.s5, d.s9, d.sd);                                                \
  *z = (PG_PASTE(T, 16))(a.s2, a.s6, a.sa, a.se, b.s2, b.s6, b.sa, b.se, c.s2, c.s6, c.sa, c.se, \
                         d.s2, d.s6, d.sa, d.se);                                                \
  *w = (PG_PASTE(T, 16))(a.s3, a.s7, a.sb, a.sf, b.s3, b.s7, b.sb, b.sf, c.s3, c.s7, c.sb, c.sf, \
                         d.s3, d.s7, d.sb, d.sf);
#elif PG_LANES == 8
#define PG_LOAD_4_ROWS_BODY(T)                                           \
  PG_PASTE(T, 16) a = vload16(0, f), b = vload16(1, f);                  \
  *x = (PG_PASTE(T, 8))(a.s0, a.s4, a.s8, a.sc, b.s0, b.s4, b.s8, b.sc); \
  *y = (PG_PASTE(T, 8))(a.s1, a.s5, a.s9, a.sd, b.s1, b.s5, b.s9, b.sd); \
  *z = (PG_PASTE(T, 8))(a.s2, a.s6, a.sa, a.se, b.s2, b.s6, b.sa, b.se); \
  *w = (PG_PASTE(T, 8))(a.s3, a.s7, a.sb, a.sf, b.s3, b.s7, b.sb, b.sf);
#elif PG_LANES == 4
#define PG_LOAD_4_ROWS_BODY(T)                   \
  PG_PASTE(T, 16) a = vload16(0, f);             \
  *x = (PG_PASTE(T, 4))(a.s0, a.s4, a.s8, a.sc); \
  *y = (PG_PASTE(T, 4))(a.s1, a.s5, a.s9, a.sd); \
  *z = (PG_PASTE(T, 4))(a.s2, a.s6, a.sa, a.se); \
  *w = (PG_PASTE(T, 4))(a.s3, a.s7, a.sb, a.sf);
#elif PG_LANES == 2
#define PG_LOAD_4_ROWS_BODY(T)       \
  PG_PASTE(T, 8) a = vload8(0, f);   \
  *x = (PG_PASTE(T, 2))(a.s0, a.s4); \
  *y = (PG_PASTE(T, 2))(a.s1, a.s5); \
  *z = (PG_PASTE(T, 2))(a.s2, a.s6); \
  *w = (PG_PASTE(T, 2))(a.s3, a.s7);
#else
#error "PG_LANES must be 2, 4, 8 or 16"
#endif
PG_ROW_LOAD void pg_load_float4_rows(__global const float4* p, pg_floatw* x, pg_floatw* y,
                                     pg_floatw* z, pg_floatw* w) {
  __global const float* f = (__global const float*)p;
  PG_LOAD_4_ROWS_BODY(float)
}
PG_ROW_LOAD void pg_load_uint4_rows(__global const uint4* p, pg_uintw* x, pg_uintw* y, pg_uintw* z,
                                    pg_uintw* w) {
  __global const uint* f = (__global const uint*)p;
  PG_LOAD_4_ROWS_BODY(uint)
}
#undef PG_LOAD_4_ROWS_BODY

/* A float4 channel of the pixels x0 .. x0 + PG_LANES - 1 of one row (row: its first pixel) as
 * four rows: vector loads where every lane lies inside the row; at either end of the row lane
 * by lane, a lane outside it reading the nearest pixel of the row (callers mask it). x0 may be
 * negative (the a-trous filter's taps left of the image). */
PG_ROW_LOAD void pg_load_row_float4_rows(__global const float4* row, int x0, int width,
                                         pg_floatw* x, pg_floatw* y, pg_floatw* z, pg_floatw* w) {
  if (x0 >= 0 && x0 + PG_LANES <= width) {
    pg_load_float4_rows(row + x0, x, y, z, w);
    return;
  }
  float v[4][PG_LANES];
  for (int l = 0; l < PG_LANES; ++l) pg_put4_rows(v, 0, l, row[clamp(x0 + l, 0, width - 1)]);
  *x = pg_vloadw(0, v[0]);
  *y = pg_vloadw(0, v[1]);
  *z = pg_vloadw(0, v[2]);
  *w = pg_vloadw(0, v[3]);
}

/* A uint (byte) channel of the same pixels (pg_load_row_float4_rows' rule at the row's ends).
 * One body for both element types, as PG_STORE_ROW below. */
#define PG_LOAD_ROW(name, type, typew)                                          \
  static inline typew name(__global const type* row, int x0, int width) {       \
    if (x0 >= 0 && x0 + PG_LANES <= width) return pg_vloadw(0, row + x0);       \
    type v[PG_LANES];                                                           \
    for (int l = 0; l < PG_LANES; ++l) v[l] = row[clamp(x0 + l, 0, width - 1)]; \
    return pg_vloadw(0, v);                                                     \
  }
PG_LOAD_ROW(pg_load_row_uints, uint, pg_uintw)
PG_LOAD_ROW(pg_load_row_bytes, uchar, pg_ucharw)
#undef PG_LOAD_ROW

/* A byte flag channel of the same pixels as a mask: -1 where the byte is not 0
 * (include/rtpg/guiding_layout.h, "Shared models"). */
static inline pg_intw pg_load_row_flags(__global const uchar* row, int x0, int width) {
  return pg_convert_intw(pg_load_row_bytes(row, x0, width)) != 0;
}

/* A float channel of the same pixels (the same rule). At a row's end (and a row of at least
 * PG_LANES pixels) one vector load from inside the row, placed in a private row of 2 PG_LANES
 * floats beside copies of the end pixel, and one load from there at the lanes' offset, instead
 * of lane-by-lane loads: the a-trous filter's wide taps cross the ends often. */
static inline pg_floatw pg_load_row_floats(__global const float* row, int x0, int width) {
  if (x0 >= 0 && x0 + PG_LANES <= width) return pg_vloadw(0, row + x0);
  if (width >= PG_LANES) {
    float padded[2 * PG_LANES];
    if (x0 < 0) { /* [pixel 0 repeated | pixels 0 .. PG_LANES - 1] */
      pg_vstorew((pg_floatw)(row[0]), 0, padded);
      pg_vstorew(pg_vloadw(0, row), 1, padded);
      return pg_vloadw(0, padded + PG_LANES + max(x0, -PG_LANES));
    }
    /* [the last PG_LANES pixels | the last pixel repeated] */
    pg_vstorew(pg_vloadw(0, row + width - PG_LANES), 0, padded);
    pg_vstorew((pg_floatw)(row[width - 1]), 1, padded);
    return pg_vloadw(0, padded + min(x0 - (width - PG_LANES), PG_LANES));
  }
  float v[PG_LANES];
  for (int l = 0; l < PG_LANES; ++l) v[l] = row[clamp(x0 + l, 0, width - 1)];
  return pg_vloadw(0, v);
}

/* Stores v to the pixels x0 .. x0 + PG_LANES - 1 of a float (uint, byte) row (x0 >= 0): one
 * vector store where every lane lies inside the row, lane by lane up to its end otherwise. One
 * body for every element type (OpenCL C has no templates). */
#define PG_STORE_ROW(name, type, typew)                                     \
  static inline void name(__global type* row, int x0, int width, typew v) { \
    if (x0 + PG_LANES <= width) {                                           \
      pg_vstorew(v, 0, row + x0);                                           \
      return;                                                               \
    }                                                                       \
    type lanes[PG_LANES];                                                   \
    pg_vstorew(v, 0, lanes);                                                \
    for (int l = 0; x0 + l < width; ++l) row[x0 + l] = lanes[l];            \
  }
PG_STORE_ROW(pg_store_row_floats, float, pg_floatw)
PG_STORE_ROW(pg_store_row_uints, uint, pg_uintw)
PG_STORE_ROW(pg_store_row_bytes, uchar, pg_ucharw)
#undef PG_STORE_ROW

/* Stores a mask as the byte flags pg_load_row_flags reads: 1 where it is set, else 0. */
static inline void pg_store_row_flags(__global uchar* row, int x0, int width, pg_intw mask) {
  pg_store_row_bytes(row, x0, width, pg_convert_ucharw(mask & 1));
}

/* The x, y, z and w of four lanes (a, b, c, d: their swizzle digits), interleaved. */
#define PG_XYZW_OF_4(a, b, c, d)                                                            \
  (float16)(x.s##a, y.s##a, z.s##a, w.s##a, x.s##b, y.s##b, z.s##b, w.s##b, x.s##c, y.s##c, \
            z.s##c, w.s##c, x.s##d, y.s##d, z.s##d, w.s##d)
/* The inverse of pg_load_float4_rows: the x, y, z and w rows of every lane stored as PG_LANES
 * consecutive float4 (a transposition by swizzles and whole-vector stores, where storing lane by
 * lane from private rows took a scalar store per field). */
PG_ROW_LOAD void pg_store_float4_rows(__global float4* p, pg_floatw x, pg_floatw y, pg_floatw z,
                                      pg_floatw w) {
  __global float* f = (__global float*)p;
#if PG_LANES == 2
  vstore8((float8)(x.s0, y.s0, z.s0, w.s0, x.s1, y.s1, z.s1, w.s1), 0, f);
#else
  vstore16(PG_XYZW_OF_4(0, 1, 2, 3), 0, f);
#if PG_LANES >= 8
  vstore16(PG_XYZW_OF_4(4, 5, 6, 7), 1, f);
#endif
#if PG_LANES == 16
  vstore16(PG_XYZW_OF_4(8, 9, a, b), 2, f);
  vstore16(PG_XYZW_OF_4(c, d, e, f), 3, f);
#endif
#endif
}
#undef PG_XYZW_OF_4

/* The same for two rows stored as PG_LANES consecutive float2. */
#define PG_XY_OF_8(a, b, c, d, e, g, h, i)                                                  \
  (float16)(x.s##a, y.s##a, x.s##b, y.s##b, x.s##c, y.s##c, x.s##d, y.s##d, x.s##e, y.s##e, \
            x.s##g, y.s##g, x.s##h, y.s##h, x.s##i, y.s##i)
PG_ROW_LOAD void pg_store_float2_rows(__global float2* p, pg_floatw x, pg_floatw y) {
  __global float* f = (__global float*)p;
#if PG_LANES == 2
  vstore4((float4)(x.s0, y.s0, x.s1, y.s1), 0, f);
#elif PG_LANES == 4
  vstore8((float8)(x.s0, y.s0, x.s1, y.s1, x.s2, y.s2, x.s3, y.s3), 0, f);
#else
  vstore16(PG_XY_OF_8(0, 1, 2, 3, 4, 5, 6, 7), 0, f);
#if PG_LANES == 16
  vstore16(PG_XY_OF_8(8, 9, a, b, c, d, e, f), 1, f);
#endif
#endif
}
#undef PG_XY_OF_8

/* Four rows stored as the float4 channel of the pixels x0 .. x0 + PG_LANES - 1 of one row (x0 >=
 * 0): vector stores where every lane lies inside the row, lane by lane up to its end otherwise. */
PG_ROW_LOAD void pg_store_row_float4_rows(__global float4* row, int x0, int width, pg_floatw x,
                                          pg_floatw y, pg_floatw z, pg_floatw w) {
  if (x0 + PG_LANES <= width) {
    pg_store_float4_rows(row + x0, x, y, z, w);
    return;
  }
  float v[4][PG_LANES];
  pg_vstorew(x, 0, v[0]);
  pg_vstorew(y, 0, v[1]);
  pg_vstorew(z, 0, v[2]);
  pg_vstorew(w, 0, v[3]);
  for (int l = 0; x0 + l < width; ++l) row[x0 + l] = (float4)(v[0][l], v[1][l], v[2][l], v[3][l]);
}

/* Two rows stored as a float2 channel (the same rule). */
PG_ROW_LOAD void pg_store_row_float2_rows(__global float2* row, int x0, int width, pg_floatw x,
                                          pg_floatw y) {
  if (x0 + PG_LANES <= width) {
    pg_store_float2_rows(row + x0, x, y);
    return;
  }
  float v[2][PG_LANES];
  pg_vstorew(x, 0, v[0]);
  pg_vstorew(y, 0, v[1]);
  for (int l = 0; x0 + l < width; ++l) row[x0 + l] = (float2)(v[0][l], v[1][l]);
}

/* The sum of a float vector's lanes, by halves (lanes l and l + PG_LANES / 2 first): a lane-by-
 * lane chain of PG_LANES - 1 dependent additions through memory was 5% of the sample kernel on
 * PoCL's CPU device. Exact for counts (whole numbers); a sum of fractions (pi's, a statistic)
 * rounds differently from the chain's. */
static inline float pg_sum_lanes(pg_floatw v) {
#if PG_LANES == 16
  float8 v8 = v.lo + v.hi;
  float4 v4 = v8.lo + v8.hi;
#elif PG_LANES == 8
  float4 v4 = v.lo + v.hi;
#elif PG_LANES == 4
  float4 v4 = v;
#endif
#if PG_LANES >= 4
  float2 v2 = v4.lo + v4.hi;
#else
  float2 v2 = v;
#endif
  return v2.x + v2.y;
}

/* The largest lane of an int vector. */
static inline int pg_max_lane(pg_intw v) {
  int a[PG_LANES];
  pg_vstorew(v, 0, a);
  int m = a[0];
  for (int l = 1; l < PG_LANES; ++l) m = max(m, a[l]);
  return m;
}

static inline pg_floatw pg_dot3w(pg_float3w a, pg_float3w b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}

static inline pg_float3w pg_sub3w(pg_float3w a, pg_float3w b) {
  return pg_make_float3w(a.x - b.x, a.y - b.y, a.z - b.z);
}

static inline pg_float3w pg_add3w(pg_float3w a, pg_float3w b) {
  return pg_make_float3w(a.x + b.x, a.y + b.y, a.z + b.z);
}

static inline pg_float3w pg_mul3w(pg_float3w a, pg_float3w b) {
  return pg_make_float3w(a.x * b.x, a.y * b.y, a.z * b.z);
}

static inline pg_float3w pg_scale3w(pg_float3w a, pg_floatw s) {
  return pg_make_float3w(a.x * s, a.y * s, a.z * s);
}

static inline pg_float3w pg_select3w(pg_float3w a, pg_float3w b, pg_intw mask) {
  return pg_make_float3w(select(a.x, b.x, mask), select(a.y, b.y, mask), select(a.z, b.z, mask));
}

static inline pg_float3w pg_cross3w(pg_float3w a, pg_float3w b) {
  return pg_make_float3w(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}

static inline pg_float3w pg_normalize3w(pg_float3w a) {
  return pg_scale3w(a, 1.0f / sqrt(pg_dot3w(a, a)));
}

static inline pg_floatw pg_luminance3w(pg_float3w c) {
  return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z;
}

static inline pg_floatw pg_max3w(pg_float3w c) {
  return fmax(c.x, fmax(c.y, c.z));
}

#endif
