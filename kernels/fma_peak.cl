/* The arithmetic yardstick beside copy_float4.cl: the device's multiply-add rate. Each
 * work-item runs `rounds` rounds of PG_FMA_CHAINS independent multiply-add chains on vectors of
 * PG_FMA_WIDTH floats (build options; 16 and 1 give the vector and the scalar rate), 2 flops per
 * lane and chain per round. The chains are independent so the latency of one hides behind the
 * others; the result is stored so that nothing can be left out (bench/bench_guiding_kernels.cpp,
 * FmaPeak; docs/design.md, "Metrics"). */
#ifndef PG_FMA_WIDTH
#define PG_FMA_WIDTH 16
#endif
#define PG_FMA_CHAINS 8 /* x0..x7 below */

#if PG_FMA_WIDTH == 1
typedef float pg_fma_t;
#define PG_FMA_SUM(v) (v)
#elif PG_FMA_WIDTH == 8
typedef float8 pg_fma_t;
#define PG_FMA_SUM(v) (dot((v).lo.lo + (v).lo.hi + (v).hi.lo + (v).hi.hi, (float2)(1.0f)))
#elif PG_FMA_WIDTH == 16
typedef float16 pg_fma_t;
#define PG_FMA_SUM(v)                                                                            \
  (dot((v).lo.lo.lo + (v).lo.lo.hi + (v).lo.hi.lo + (v).lo.hi.hi + (v).hi.lo.lo + (v).hi.lo.hi + \
           (v).hi.hi.lo + (v).hi.hi.hi,                                                          \
       (float2)(1.0f)))
#endif

__kernel void fma_peak(__global float* out, uint rounds, float a, float b) {
  float base = (float)get_global_id(0) * 1e-9f;
  pg_fma_t x0 = (pg_fma_t)(base), x1 = (pg_fma_t)(base + 1.0f), x2 = (pg_fma_t)(base + 2.0f),
           x3 = (pg_fma_t)(base + 3.0f), x4 = (pg_fma_t)(base + 4.0f), x5 = (pg_fma_t)(base + 5.0f),
           x6 = (pg_fma_t)(base + 6.0f), x7 = (pg_fma_t)(base + 7.0f);
  pg_fma_t va = (pg_fma_t)(a), vb = (pg_fma_t)(b);
  for (uint r = 0; r < rounds; ++r) {
    x0 = fma(x0, va, vb);
    x1 = fma(x1, va, vb);
    x2 = fma(x2, va, vb);
    x3 = fma(x3, va, vb);
    x4 = fma(x4, va, vb);
    x5 = fma(x5, va, vb);
    x6 = fma(x6, va, vb);
    x7 = fma(x7, va, vb);
  }
  pg_fma_t s = ((x0 + x1) + (x2 + x3)) + ((x4 + x5) + (x6 + x7));
  out[get_global_id(0)] = PG_FMA_SUM(s);
}
