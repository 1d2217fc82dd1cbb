// Multiple importance sampling weights (Veach's power heuristic, exponent 2), shared by
// next-event estimation and BSDF sampling in the path tracer.
#pragma once

namespace rtpg {

// Weight of the strategy with density a against one with density b: a^2 / (a^2 + b^2), written
// with the ratio of the smaller to the larger density so that no square overflows (a density
// above about 1.8e19, e.g. a small light seen edge-on, made a^2 infinite and the weight NaN).
// An infinite a gets 1; a = b = 0 gets 0.
inline float power_heuristic(float a, float b) {
  if (!(a > 0.0f)) return 0.0f;
  if (a >= b) {
    const float r = b / a;
    return 1.0f / (1.0f + r * r);
  }
  const float r = a / b;
  return r * r / (1.0f + r * r);
}

}  // namespace rtpg
