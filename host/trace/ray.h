// Rays and hits as the host tracer takes and returns them, in batches (structure of arrays
// would save little here: Embree reads one ray at a time or 8-wide packets it gathers).
#pragma once

#include <cstdint>

#include <glm/glm.hpp>

namespace rtpg {

struct Ray {
  glm::vec3 origin;
  float tmin = 0.0f;
  glm::vec3 direction;  // need not be normalised; t is in units of its length
  float tmax = 1e30f;
};

// Writes a ray's fields in place. Building a Ray on the stack and copying it into a batch makes
// the compiler store its fields one by one and reload them as 16-byte vectors, a store-forwarding
// stall per copy in the path tracer's loops (docs/host-path-tracer.md, "Rays written in place").
inline void set_ray(Ray& r, const glm::vec3& origin, const glm::vec3& direction, float tmin,
                    float tmax) {
  r.origin = origin;
  r.tmin = tmin;
  r.direction = direction;
  r.tmax = tmax;
}

constexpr std::uint32_t kNoHit = 0xffffffffu;

struct Hit {
  float t = 0.0f;
  std::uint32_t mesh = kNoHit;  // index into Scene::meshes; kNoHit on a miss
  std::uint32_t triangle = 0;   // index into Mesh::triangles
  float u = 0.0f, v = 0.0f;     // barycentrics of vertices 1 and 2
  bool valid() const { return mesh != kNoHit; }
};

// How a batch is handed to Embree. Packets of 8 pay off only for coherent rays (camera and
// shadow rays towards one light); incoherent bounces are as fast one by one (docs/design.md,
// "PoCL and OpenCL facts"). Stream: rtcIntersect1M / rtcOccluded1M over chunks of rays
// (docs/host-path-tracer.md, "Embree's stream API").
enum class RayMode { Single, Packet8, Stream };

}  // namespace rtpg
