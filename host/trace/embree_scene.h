// The Embree 3 BVH of a Scene and batched ray queries over all cores (TBB).
// Knows nothing of guiding; alpha-masked materials are alpha-tested in intersection filters.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>

#include "scene/scene.h"
#include "trace/ray.h"

namespace rtpg {

class EmbreeError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class EmbreeScene {
 public:
  explicit EmbreeScene(const Scene& scene);  // builds the BVH; throws EmbreeError
  ~EmbreeScene();
  EmbreeScene(const EmbreeScene&) = delete;
  EmbreeScene& operator=(const EmbreeScene&) = delete;

  // Closest hits of rays[0..count) into hits[0..count).
  void intersect(const Ray* rays, Hit* hits, std::size_t count,
                 RayMode mode = RayMode::Single) const;
  // occluded[i] = 1 if anything lies on rays[i] within (tmin, tmax), else 0. A ray with an
  // empty segment (not tmin <= tmax: the path tracer's slot without a shadow ray) gets 0 without
  // a query. Returns the number of rays queried.
  std::size_t occluded(const Ray* rays, std::uint8_t* occluded, std::size_t count,
                       RayMode mode = RayMode::Single) const;

  double build_seconds() const { return build_seconds_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  double build_seconds_ = 0.0;
};

}  // namespace rtpg
