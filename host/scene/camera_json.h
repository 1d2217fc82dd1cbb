// Reads "camera" and "camera_paths" of a scene file (format: scenes/README.md).
#pragma once

#include "scene/camera.h"
#include "scene/json_reader.h"

namespace rtpg {

// The static camera: position, look_at, up (default +y), fov (vertical, degrees).
CameraView read_camera(const JsonNode& node);

// {"NAME": {"fps": 30, "keys": [...]}}: keys default up and fov to `base`'s.
void read_camera_paths(const JsonNode& node, const CameraView& base, CameraSetup& setup);

}  // namespace rtpg
