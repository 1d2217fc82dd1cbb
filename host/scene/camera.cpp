// Camera paths (keyframe interpolation) and the pinhole projection used for primary rays and
// motion vectors.
#include "scene/camera.h"

#include <algorithm>
#include <cmath>

namespace rtpg {

namespace {

// Cubic Hermite segment between p0 (s = 0) and p1 (s = 1); m0, m1 are tangents already scaled
// to the segment's duration.
glm::vec3 hermite(const glm::vec3& p0, const glm::vec3& m0, const glm::vec3& p1,
                  const glm::vec3& m1, float s) {
  const float s2 = s * s, s3 = s2 * s;
  return (2.0f * s3 - 3.0f * s2 + 1.0f) * p0 + (s3 - 2.0f * s2 + s) * m0 +
         (-2.0f * s3 + 3.0f * s2) * p1 + (s3 - s2) * m1;
}

// Catmull-Rom tangent (per second) at key i for uneven key times: the central difference,
// one-sided at the ends, so the curve passes through every key and keys may be spaced freely.
template <typename Get>
glm::vec3 tangent(const std::vector<float>& times, std::size_t i, Get get) {
  const std::size_t last = times.size() - 1;
  const std::size_t a = i == 0 ? 0 : i - 1;
  const std::size_t b = i == last ? last : i + 1;
  return (get(b) - get(a)) / (times[b] - times[a]);
}

}  // namespace

CameraView CameraPath::at(float time) const {
  if (views.empty()) return CameraView{};
  if (views.size() == 1 || times.size() != views.size() || !(time > times.front()))
    return views.front();
  if (time >= times.back()) return views.back();

  // Segment [i, i + 1] holding time; times are strictly increasing (checked by the loader).
  const std::size_t i =
      static_cast<std::size_t>(std::upper_bound(times.begin(), times.end(), time) - times.begin()) -
      1;
  const float dt = times[i + 1] - times[i];
  const float s = (time - times[i]) / dt;

  auto position = [&](std::size_t k) { return views[k].position; };
  auto look_at = [&](std::size_t k) { return views[k].look_at; };
  CameraView out;
  out.position = hermite(views[i].position, tangent(times, i, position) * dt, views[i + 1].position,
                         tangent(times, i + 1, position) * dt, s);
  out.look_at = hermite(views[i].look_at, tangent(times, i, look_at) * dt, views[i + 1].look_at,
                        tangent(times, i + 1, look_at) * dt, s);
  // Up and fov change slowly and must not overshoot (fov outside (0, pi) breaks the camera).
  out.up = glm::mix(views[i].up, views[i + 1].up, s);
  out.fov_y = views[i].fov_y + (views[i + 1].fov_y - views[i].fov_y) * s;
  return out;
}

CameraFrame make_camera_frame(const CameraView& view, float aspect) {
  CameraFrame frame;
  frame.position = view.position;
  glm::vec3 forward = view.look_at - view.position;
  frame.forward =
      glm::dot(forward, forward) > 0.0f ? glm::normalize(forward) : glm::vec3(0.0f, 0.0f, -1.0f);
  // An up vector parallel to the view direction (possible mid-path) would leave right
  // undefined: fall back to the world axis least aligned with forward.
  glm::vec3 right = glm::cross(frame.forward, view.up);
  if (glm::dot(right, right) < 1e-12f) {
    const glm::vec3 f = glm::abs(frame.forward);
    const glm::vec3 axis = f.x <= f.y && f.x <= f.z ? glm::vec3(1, 0, 0)
                           : f.y <= f.z             ? glm::vec3(0, 1, 0)
                                                    : glm::vec3(0, 0, 1);
    right = glm::cross(frame.forward, axis);
  }
  frame.right = glm::normalize(right);
  frame.up = glm::cross(frame.right, frame.forward);
  frame.tan_half_fov_y = std::tan(0.5f * view.fov_y);
  frame.aspect = aspect;
  return frame;
}

bool CameraFrame::project(const glm::vec3& p, float& sx, float& sy) const {
  const glm::vec3 d = p - position;
  const float z = glm::dot(d, forward);
  if (!(z > 0.0f)) return false;
  const float x = glm::dot(d, right) / z;
  const float y = glm::dot(d, up) / z;
  // Values outside [0,1] are points off screen; the caller decides what that means.
  sx = 0.5f * (x / (tan_half_fov_y * aspect) + 1.0f);
  sy = 0.5f * (1.0f - y / tan_half_fov_y);
  return true;
}

}  // namespace rtpg
