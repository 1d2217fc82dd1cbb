#include "render/gbuffer_packer.h"

#include <stdexcept>

#include "shared/gbuffer_packing.h"

#if RTPG_HAS_AVX2_VARIANT
#include <immintrin.h>
#endif

namespace rtpg {
namespace {

bool fits(const GBuffer& g, std::size_t i) {
  return g.material[i] <= PG_PACKED_MATERIAL_MAX && g.flags[i] <= 0xffu;
}

bool pack_baseline(const GBuffer& g, std::size_t first, std::size_t last,
                   const PackedGBufferView& out) {
  bool all_fit = true;
  for (std::size_t i = first; i < last; ++i) {
    out.surface[i] = shared::pg_pack_gbuffer_surface(g.position_depth[i], g.shading_normal[i],
                                                     g.base_color_roughness[i]);
    out.shading[i] =
        shared::pg_pack_gbuffer_shading(g.metallic_specular[i], g.flags[i], g.material[i]);
    all_fit &= fits(g, i);
  }
  return all_fit;
}

#if RTPG_HAS_AVX2_VARIANT
#define RTPG_LANES_VARIANT __attribute__((target("avx2,f16c")))

// The x, y and z of eight float4, lane k holding element kLaneOrder[k] (a 4x4 transpose within
// each 128-bit half of the registers).
constexpr int kLaneOrder[8] = {0, 2, 4, 6, 1, 3, 5, 7};
RTPG_LANES_VARIANT inline void load_xyz8(const shared::float4* v, __m256& x, __m256& y, __m256& z) {
  const float* f = &v[0].x;
  const __m256 r0 = _mm256_loadu_ps(f), r1 = _mm256_loadu_ps(f + 8), r2 = _mm256_loadu_ps(f + 16),
               r3 = _mm256_loadu_ps(f + 24);
  const __m256 t0 = _mm256_unpacklo_ps(r0, r1), t1 = _mm256_unpackhi_ps(r0, r1);
  const __m256 t2 = _mm256_unpacklo_ps(r2, r3), t3 = _mm256_unpackhi_ps(r2, r3);
  x = _mm256_shuffle_ps(t0, t2, _MM_SHUFFLE(1, 0, 1, 0));
  y = _mm256_shuffle_ps(t0, t2, _MM_SHUFFLE(3, 2, 3, 2));
  z = _mm256_shuffle_ps(t1, t3, _MM_SHUFFLE(1, 0, 1, 0));
}

// pg_snorm16_bits in lanes: the same clamp, product, sum and floor, so the same bits.
RTPG_LANES_VARIANT inline __m256i snorm16_bits8(__m256 v) {
  const __m256 c = _mm256_min_ps(_mm256_max_ps(v, _mm256_set1_ps(-1.0f)), _mm256_set1_ps(1.0f));
  const __m256 scaled =
      _mm256_add_ps(_mm256_mul_ps(c, _mm256_set1_ps(32767.0f)), _mm256_set1_ps(0.5f));
  return _mm256_and_si256(_mm256_cvttps_epi32(_mm256_floor_ps(scaled)), _mm256_set1_epi32(0xffff));
}

// pg_pack_unit_vector in lanes: the same operations in the same order (the fold selected
// instead of branched to; multiplying by +-1 is exact either way).
RTPG_LANES_VARIANT inline __m256i pack_unit_vector8(__m256 x, __m256 y, __m256 z) {
  const __m256 sign_bit = _mm256_set1_ps(-0.0f), zero = _mm256_setzero_ps(),
               one = _mm256_set1_ps(1.0f);
  const __m256 ax = _mm256_andnot_ps(sign_bit, x), ay = _mm256_andnot_ps(sign_bit, y),
               az = _mm256_andnot_ps(sign_bit, z);
  const __m256 l1 = _mm256_add_ps(_mm256_add_ps(ax, ay), az);
  const __m256 inv = _mm256_and_ps(_mm256_cmp_ps(l1, zero, _CMP_GT_OQ), _mm256_div_ps(one, l1));
  __m256 px = _mm256_mul_ps(x, inv), py = _mm256_mul_ps(y, inv);
  const __m256 sx =
      _mm256_blendv_ps(_mm256_set1_ps(-1.0f), one, _mm256_cmp_ps(px, zero, _CMP_GE_OQ));
  const __m256 sy =
      _mm256_blendv_ps(_mm256_set1_ps(-1.0f), one, _mm256_cmp_ps(py, zero, _CMP_GE_OQ));
  const __m256 fx = _mm256_mul_ps(_mm256_sub_ps(one, _mm256_andnot_ps(sign_bit, py)), sx);
  const __m256 fy = _mm256_mul_ps(_mm256_sub_ps(one, _mm256_andnot_ps(sign_bit, px)), sy);
  const __m256 lower = _mm256_cmp_ps(z, zero, _CMP_LT_OQ);
  px = _mm256_blendv_ps(px, fx, lower);
  py = _mm256_blendv_ps(py, fy, lower);
  return _mm256_or_si256(snorm16_bits8(px), _mm256_slli_epi32(snorm16_bits8(py), 16));
}

// Four floats as halves (pg_half_bits: ties to even, saturated at 65504), in the low 64 bits.
RTPG_LANES_VARIANT inline __m128i halves4(const shared::float4& v) {
  const __m128 c =
      _mm_min_ps(_mm_max_ps(_mm_loadu_ps(&v.x), _mm_set1_ps(-65504.0f)), _mm_set1_ps(65504.0f));
  return _mm_cvtps_ph(c, _MM_FROUND_TO_NEAREST_INT);
}

RTPG_LANES_VARIANT bool pack_lanes(const GBuffer& g, std::size_t first, std::size_t last,
                                   const PackedGBufferView& out) {
  bool all_fit = true;
  std::size_t i = first;
  alignas(32) std::uint32_t normal[8];
  for (; i + 8 <= last; i += 8) {
    __m256 x, y, z;
    load_xyz8(&g.shading_normal[i], x, y, z);
    _mm256_store_si256(reinterpret_cast<__m256i*>(normal), pack_unit_vector8(x, y, z));
    for (int k = 0; k < 8; ++k) {
      const std::size_t p = i + static_cast<std::size_t>(kLaneOrder[k]);
      const __m128i colour = halves4(g.base_color_roughness[p]);
      out.surface[p] = shared::uint4(shared::as_uint(g.position_depth[p].w), normal[k],
                                     static_cast<std::uint32_t>(_mm_extract_epi32(colour, 0)),
                                     static_cast<std::uint32_t>(_mm_extract_epi32(colour, 1)));
      out.shading[p] = shared::uint2(
          static_cast<std::uint32_t>(_mm_cvtsi128_si32(halves4(g.metallic_specular[p]))),
          (g.flags[p] & 0xffu) | (g.material[p] << 8));
      all_fit &= fits(g, p);
    }
  }
  return pack_baseline(g, i, last, out) && all_fit;
}
#endif

}  // namespace

bool cpu_runs_gbuffer_packer_lanes() {
#if RTPG_HAS_AVX2_VARIANT
  return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("f16c");
#else
  return false;
#endif
}

bool pack_gbuffer(const GBuffer& g, std::size_t first, std::size_t last,
                  const PackedGBufferView& out, CpuCode code) {
  if (code == CpuCode::automatic)
    code = cpu_runs_gbuffer_packer_lanes() ? CpuCode::avx2 : CpuCode::baseline;
  if (code == CpuCode::avx2) {
    if (!cpu_runs_gbuffer_packer_lanes())
      throw std::invalid_argument("this CPU does not run AVX2 and F16C code");
#if RTPG_HAS_AVX2_VARIANT
    return pack_lanes(g, first, last, out);
#endif
  }
  return pack_baseline(g, first, last, out);
}

}  // namespace rtpg
