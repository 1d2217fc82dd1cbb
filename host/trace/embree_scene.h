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
  // intersect() for `lists` lists of rays laid out `stride` apart, as occluded_lists() below
  // (the path tracer's bounce rays, each block of its paths' rays written from the block's start).
  void intersect_lists(const Ray* rays, Hit* hits, std::size_t stride, const std::uint32_t* counts,
                       std::size_t lists, RayMode mode = RayMode::Single) const;
  // occluded[i] = 1 if anything lies on rays[i] within (tmin, tmax), else 0. A ray with an
  // empty segment (not tmin <= tmax, a NaN bound included) gets 0 without a query. Returns the
  // number of rays queried.
  std::size_t occluded(const Ray* rays, std::uint8_t* occluded, std::size_t count,
                       RayMode mode = RayMode::Single) const;
  // occluded() for `lists` lists of rays laid out `stride` apart: list l is
  // rays[l * stride .. l * stride + counts[l]) (at most stride long), answered into the same
  // places of `occluded`; what lies between the lists is neither read nor written. The path
  // tracer's shadow rays, each block of its paths' rays written from the block's start
  // (docs/host-path-tracer.md, "Shadow rays listed where they are made").
  std::size_t occluded_lists(const Ray* rays, std::uint8_t* occluded, std::size_t stride,
                             const std::uint32_t* counts, std::size_t lists,
                             RayMode mode = RayMode::Single) const;

  // Closest hits of an image's camera rays, rays[y * width + x] into hits[y * width + x],
  // traced in packets of neighbouring pixels: tiles of 4x4 (16 rays) where this CPU and Embree
  // trace 16-wide packets natively, else of 4x2 (8 rays) (docs/host-path-tracer.md, "Camera
  // rays in vector lanes"). `tiles` names one shape instead; 4x4 throws EmbreeError where
  // 16-wide packets are not native.
  enum class ImageTiles { automatic, tiles_4x2, tiles_4x4 };
  void intersect_image(const Ray* rays, Hit* hits, int width, int height,
                       ImageTiles tiles = ImageTiles::automatic) const;
  bool native_packets_of_16() const;

  double build_seconds() const { return build_seconds_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  double build_seconds_ = 0.0;
};

}  // namespace rtpg
