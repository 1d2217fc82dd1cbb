// Pinhole camera, static or keyframed along a named path.
#pragma once

#include <map>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace rtpg {

struct CameraView {
  glm::vec3 position{0.0f, 0.0f, 1.0f};
  glm::vec3 look_at{0.0f};
  glm::vec3 up{0.0f, 1.0f, 0.0f};
  float fov_y = 0.6981317f;  // vertical field of view in radians
};

// Keys sorted by time (seconds); views between keys are interpolated (positions and targets
// with Catmull-Rom, fov linearly), clamped at the ends.
struct CameraPath {
  std::vector<float> times;
  std::vector<CameraView> views;
  float fps = 30.0f;  // frame f of a render is at time f / fps
  CameraView at(float time) const;
};

struct CameraSetup {
  CameraView view;                          // the static camera
  std::map<std::string, CameraPath> paths;  // named camera paths
};

// The matrices a frame needs: world -> camera and camera -> image plane.
struct CameraFrame {
  // The defaults (a camera at the origin looking down -z) only keep a default-constructed frame
  // defined (GBuffer::camera before a renderer set it); make_camera_frame sets every field.
  glm::vec3 position{0.0f};
  glm::vec3 right{1.0f, 0.0f, 0.0f}, up{0.0f, 1.0f, 0.0f},
      forward{0.0f, 0.0f, -1.0f};  // orthonormal, right-handed, forward = view direction
  float tan_half_fov_y = 0.0f;
  float aspect = 1.0f;  // width / height
  // Ray direction through film point (sx, sy) in [0,1]^2, (0,0) = top-left corner. Inline:
  // the camera-ray loop (render/camera_rays.cpp) computes it in vector lanes.
  glm::vec3 ray_direction(float sx, float sy) const {
    // Film x grows to the right, film y grows downwards (image rows).
    const float x = (2.0f * sx - 1.0f) * tan_half_fov_y * aspect;
    const float y = (1.0f - 2.0f * sy) * tan_half_fov_y;
    return glm::normalize(forward + x * right + y * up);
  }
  // Film position in [0,1]^2 of a world point (for motion vectors); false if behind.
  bool project(const glm::vec3& p, float& sx, float& sy) const;
};

CameraFrame make_camera_frame(const CameraView& view, float aspect);

}  // namespace rtpg
