// Camera parsing and validation: every view must define a usable camera frame.
#include "scene/camera_json.h"

namespace rtpg {

namespace {

float read_fov(const JsonNode& node) {
  const float degrees = node.number();
  if (!(degrees > 0.0f && degrees < 180.0f)) node.fail("fov must lie in (0, 180) degrees");
  return glm::radians(degrees);
}

// A view whose direction is undefined, or parallel to up, has no camera frame.
void check_view(const JsonNode& node, const CameraView& view) {
  const glm::vec3 forward = view.look_at - view.position;
  if (!(glm::dot(forward, forward) > 0.0f)) node.fail("position and look_at must differ");
  const glm::vec3 right = glm::cross(glm::normalize(forward), view.up);
  if (!(glm::dot(view.up, view.up) > 0.0f) ||
      !(glm::dot(right, right) > 1e-10f * glm::dot(view.up, view.up)))
    node.fail("up must not be zero or parallel to the view direction");
}

CameraPath read_path(const JsonNode& node, const CameraView& base) {
  node.check_object({"description", "fps", "keys"});
  if (node.has("description")) node.child("description").string();  // a comment
  CameraPath path;
  path.fps = node.number_or("fps", 30.0f);
  if (!(path.fps > 0.0f)) node.child("fps").fail("fps must be positive");
  const JsonNode keys = node.child("keys");
  if (keys.size() < 2) keys.fail("a camera path needs at least 2 keys");
  for (std::size_t i = 0; i < keys.size(); ++i) {
    const JsonNode key = keys[i];
    key.check_object({"time", "position", "look_at", "up", "fov"});
    const JsonNode time = key.child("time");
    const float t = time.number();
    if (!path.times.empty() && !(t > path.times.back()))
      time.fail("key times must be strictly increasing");
    CameraView view = base;
    view.position = key.child("position").vec3();
    view.look_at = key.child("look_at").vec3();
    if (key.has("up")) view.up = key.child("up").vec3();
    if (key.has("fov")) view.fov_y = read_fov(key.child("fov"));
    check_view(key, view);
    path.times.push_back(t);
    path.views.push_back(view);
  }
  return path;
}

}  // namespace

CameraView read_camera(const JsonNode& node) {
  node.check_object({"description", "position", "look_at", "up", "fov"});
  if (node.has("description")) node.child("description").string();  // a comment
  CameraView view;
  view.position = node.child("position").vec3();
  view.look_at = node.child("look_at").vec3();
  view.up = node.has("up") ? node.child("up").vec3() : glm::vec3(0.0f, 1.0f, 0.0f);
  view.fov_y = read_fov(node.child("fov"));
  check_view(node, view);
  return view;
}

void read_camera_paths(const JsonNode& node, const CameraView& base, CameraSetup& setup) {
  for (const std::string& name : node.keys()) setup.paths[name] = read_path(node.child(name), base);
}

}  // namespace rtpg
