// The scene file format (scenes/README.md, "Scene file format"): parsing, asset lookup,
// assembly of the Scene and the checks that make a scene renderable.
#include "scene/scene_loader.h"

#include <fstream>
#include <functional>
#include <cmath>
#include <map>
#include <set>
#include <filesystem>
#include <sstream>
#include <system_error>

#include <nlohmann/json.hpp>

#include "scene/asset_paths.h"
#include "scene/camera_json.h"
#include "scene/json_reader.h"
#include "scene/material_json.h"
#include "scene/mesh_check.h"
#include "scene/mesh_loader.h"
#include "scene/mesh_transform.h"
#include "scene/shapes.h"
#include "scene/texture_cache.h"
#include "scene/transform_json.h"
#include "rtpg/errors.h"

namespace rtpg {

namespace {

// nlohmann::json keeps the last of two equal keys without a word; in a scene file that
// silently drops a whole "materials" block. This parser callback rejects duplicates and names
// the key path.
class DuplicateKeyCheck {
 public:
  explicit DuplicateKeyCheck(const std::string& file) : file_(file) {}

  bool operator()(int, nlohmann::json::parse_event_t event, nlohmann::json& parsed) {
    using Event = nlohmann::json::parse_event_t;
    switch (event) {
      case Event::object_start:
      case Event::array_start:
        frames_.push_back({event == Event::array_start, 0, "", {}, child_path()});
        break;
      case Event::key: {
        Frame& top = frames_.back();
        top.key = parsed.get<std::string>();
        if (!top.keys.insert(top.key).second)
          throw InputError(file_, child_path() + ": duplicate key");
        break;
      }
      case Event::value:
        next_element();
        break;
      case Event::object_end:
      case Event::array_end:
        frames_.pop_back();
        next_element();
        break;
    }
    return true;
  }

 private:
  struct Frame {
    bool array;
    std::size_t index;
    std::string key;
    std::set<std::string> keys;
    std::string path;
  };

  // Path of the value about to be read in the innermost object or array.
  std::string child_path() const {
    if (frames_.empty()) return "";
    const Frame& top = frames_.back();
    if (top.array) return top.path + "[" + std::to_string(top.index) + "]";
    return top.path.empty() ? top.key : top.path + "." + top.key;
  }

  void next_element() {
    if (!frames_.empty() && frames_.back().array) ++frames_.back().index;
  }

  const std::string& file_;
  std::vector<Frame> frames_;
};

nlohmann::json parse_file(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw InputError(path, "file not found");
  if (std::filesystem::is_directory(path, ec)) throw InputError(path, "is a directory");
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  if (!in) throw InputError(path, "cannot be read");
  try {
    DuplicateKeyCheck check(path);
    return nlohmann::json::parse(text.str(), std::ref(check));
  } catch (const nlohmann::json::exception& e) {
    // e.what() is "[json.exception.parse_error.101] parse error at line 3, column 7: ...":
    // keep the part a user needs. Not only parse errors: a number beyond the double range is
    // out_of_range.406 (found by fuzzing, tests/fuzz/corpus/scene_json/number-overflow.json).
    std::string message = e.what();
    const std::size_t bracket = message.find("] ");
    if (message.rfind("[json.exception", 0) == 0 && bracket != std::string::npos)
      message.erase(0, bracket + 2);
    throw InputError(path, "invalid JSON: " + message);
  }
}

// Everything one load needs; lives for the duration of load_scene.
class SceneBuilder {
 public:
  SceneBuilder(const std::string& path, const SceneLoadSettings& settings, Scene& scene)
      : path_(path),
        scene_(scene),
        assets_(path, resolve_asset_root(path, settings)),
        cache_(scene.textures) {}

  void build(const JsonNode& root) {
    root.check_object({"description", "camera", "camera_paths", "meshes", "shapes", "materials",
                       "material_overrides", "sun", "environment", "integrator", "exposure"});
    read_description(root);
    scene_.camera.view = read_camera(root.child("camera"));
    if (root.has("camera_paths"))
      read_camera_paths(root.child("camera_paths"), scene_.camera.view, scene_.camera);
    if (root.has("materials")) read_materials(root.child("materials"));
    if (root.has("meshes")) {
      const JsonNode meshes = root.child("meshes");
      for (std::size_t i = 0; i < meshes.size(); ++i) read_mesh(meshes[i]);
    }
    if (root.has("shapes")) {
      const JsonNode shapes = root.child("shapes");
      for (std::size_t i = 0; i < shapes.size(); ++i) read_shape(shapes[i]);
    }
    if (root.has("material_overrides")) {
      const JsonNode overrides = root.child("material_overrides");
      for (std::size_t i = 0; i < overrides.size(); ++i) apply_override(overrides[i]);
    }
    if (root.has("sun")) read_sun(root.child("sun"));
    if (root.has("environment")) read_environment(root.child("environment"));
    if (root.has("integrator")) read_integrator(root.child("integrator"));
    if (root.has("exposure")) read_exposure(root.child("exposure"));
    if (scene_.meshes.empty())
      throw InputError(path_, "the scene has no geometry (meshes, shapes)");
    if (!has_light())
      throw InputError(path_, "no light sources (an emissive material, sun or environment)");
  }

 private:
  // The file a path value names, or a failure listing every place searched.
  std::string asset(const JsonNode& value) {
    const std::string written = value.string();
    if (written.empty()) value.fail("empty path");
    std::vector<std::string> searched;
    if (auto found = assets_.find(written, searched)) return *found;
    std::string where;
    for (const std::string& s : searched) where += (where.empty() ? "" : ", ") + s;
    std::string hint;
    if (assets_.asset_root().empty())
      hint = " (no asset root: set RTPG_ASSET_ROOT or SceneLoadSettings::asset_root)";
    value.fail("file '" + written + "' not found; looked in: " + where + hint);
  }

  // A free-text comment on an entry: must be a string, otherwise ignored.
  static void read_description(const JsonNode& entry) {
    if (entry.has("description")) entry.child("description").string();
  }

  // Render defaults the scene asks for (as pbrt's Integrator directive); flags override them.
  void read_integrator(const JsonNode& node) {
    node.check_object({"max_bounces"});
    if (node.has("max_bounces")) {
      const JsonNode value = node.child("max_bounces");
      const int bounces = value.integer();
      if (bounces < 1 || bounces > kMaxPathBounces)
        value.fail("expected an integer in [1, " + std::to_string(kMaxPathBounces) + "]");
      scene_.max_bounces = bounces;
    }
  }

  void read_exposure(const JsonNode& value) {
    const float exposure = value.number();
    if (!std::isfinite(exposure) || exposure <= 0.0f || exposure > 1e6f)
      value.fail("expected a number in (0, 1e6]");
    scene_.exposure = exposure;
  }

  std::string context(const JsonNode& value) const { return value.path() + " in " + path_; }

  int texture(const JsonNode& value, ImageDecode decode) {
    return cache_.file(asset(value), decode, context(value));
  }

  void read_materials(const JsonNode& node) {
    const TextureResolver resolve = [this](const JsonNode& v, ImageDecode d) {
      return texture(v, d);
    };
    for (const std::string& name : node.keys()) {
      Material m;
      m.name = name;
      apply_material_fields(node.child(name), m, resolve);
      named_[name] = static_cast<std::uint32_t>(scene_.materials.size());
      scene_.materials.push_back(m);
    }
  }

  std::uint32_t named_material(const JsonNode& value) {
    const std::string name = value.string();
    const auto found = named_.find(name);
    if (found == named_.end()) value.fail("no material named '" + name + "' in \"materials\"");
    return found->second;
  }

  void add_mesh(Mesh mesh, const JsonNode& entry) {
    if (entry.has("transform")) {
      const JsonNode transform = entry.child("transform");
      transform_mesh(mesh, read_transform(transform));
      // A large scale can carry finite coordinates past the float range.
      for (const glm::vec3& p : mesh.positions)
        if (!all_finite(p))
          transform.fail("moves a vertex of mesh '" + mesh.name + "' outside the float range");
    }
    scene_.meshes.push_back(std::move(mesh));
  }

  void read_mesh(const JsonNode& entry) {
    entry.check_object({"description", "file", "transform", "material"});
    read_description(entry);
    const JsonNode file = entry.child("file");
    const std::string mesh_path = asset(file);
    const bool replace = entry.has("material");
    const std::uint32_t replacement = replace ? named_material(entry.child("material")) : 0;
    MeshFile loaded = load_mesh_file(mesh_path, replace ? nullptr : &cache_, context(file));
    if (loaded.degenerate_triangles > 0) {
      scene_.degenerate_triangles += loaded.degenerate_triangles;
      scene_.warnings.push_back(mesh_path + ": dropped " +
                                std::to_string(loaded.degenerate_triangles) +
                                " triangles of zero area (" + context(file) + ")");
    }
    const auto offset = static_cast<std::uint32_t>(scene_.materials.size());
    if (!replace)
      scene_.materials.insert(scene_.materials.end(), loaded.materials.begin(),
                              loaded.materials.end());
    for (Mesh& mesh : loaded.meshes) {
      mesh.material = replace ? replacement : mesh.material + offset;
      add_mesh(std::move(mesh), entry);
    }
  }

  void read_shape(const JsonNode& entry) {
    const JsonNode type_node = entry.child("type");
    const std::string type = type_node.string();
    Mesh mesh;
    if (type == "quad") {
      entry.check_object(
          {"description", "type", "corner", "edge1", "edge2", "material", "transform"});
      const glm::vec3 e1 = entry.child("edge1").vec3(), e2 = entry.child("edge2").vec3();
      const glm::vec3 n = glm::cross(e1, e2);
      if (!(glm::dot(n, n) > 0.0f)) entry.fail("edge1 and edge2 must span a parallelogram");
      mesh = make_quad(entry.child("corner").vec3(), e1, e2);
    } else if (type == "box") {
      entry.check_object({"description", "type", "min", "max", "material", "transform"});
      const glm::vec3 lo = entry.child("min").vec3(), hi = entry.child("max").vec3();
      if (!(lo.x < hi.x && lo.y < hi.y && lo.z < hi.z))
        entry.child("max").fail("max must exceed min in every component");
      mesh = make_box(lo, hi);
    } else if (type == "sphere") {
      entry.check_object({"description", "type", "center", "radius", "subdivisions", "inward",
                          "material", "transform"});
      const JsonNode radius = entry.child("radius");
      const float r = radius.number();
      if (!(r > 0.0f)) radius.fail("radius must be positive");
      int subdivisions = 4;
      if (entry.has("subdivisions")) {
        const JsonNode s = entry.child("subdivisions");
        subdivisions = s.integer();
        if (subdivisions < 0 || subdivisions > 8) s.fail("subdivisions must lie in [0, 8]");
      }
      mesh = make_sphere(entry.child("center").vec3(), r, subdivisions,
                         entry.boolean_or("inward", false));
    } else {
      type_node.fail("unknown shape type '" + type + "' (expected quad, box or sphere)");
    }
    read_description(entry);
    mesh.name = type + "#" + std::to_string(shape_count_++);
    mesh.material = named_material(entry.child("material"));
    add_mesh(std::move(mesh), entry);
  }

  void apply_override(const JsonNode& entry) {
    entry.check_object({"description", "match", "set"});
    read_description(entry);
    const JsonNode match = entry.child("match");
    const std::string pattern = match.string();
    const TextureResolver resolve = [this](const JsonNode& v, ImageDecode d) {
      return texture(v, d);
    };
    const JsonNode set = entry.child("set");
    bool matched = false;
    for (Material& m : scene_.materials) {
      if (pattern != "*" && m.name != pattern) continue;
      apply_material_fields(set, m, resolve);
      matched = true;
    }
    // A misspelt name would silently change nothing.
    if (!matched) match.fail("no material is named '" + pattern + "'");
  }

  void read_sun(const JsonNode& node) {
    node.check_object({"direction", "irradiance", "angular_radius_deg"});
    const JsonNode direction = node.child("direction");
    // Normalised in double: a float's squared length overflows from components of about 2e19,
    // and glm::normalize then returned the zero vector (a sun that lit nothing).
    const glm::dvec3 d(direction.vec3());
    const double length = glm::length(d);
    if (!(length > 0.0)) direction.fail("direction must not be zero");
    scene_.sun.enabled = true;
    scene_.sun.direction = glm::vec3(d / length);
    const JsonNode irradiance = node.child("irradiance");
    scene_.sun.irradiance = irradiance.vec3();
    for (int i = 0; i < 3; ++i)
      if (!(scene_.sun.irradiance[i] >= 0.0f)) irradiance.fail("components must not be negative");
    const float radius = node.number_or("angular_radius_deg", 0.27f);
    if (!(radius >= 0.0f && radius < 90.0f))
      node.child("angular_radius_deg").fail("must lie in [0, 90) degrees");
    scene_.sun.angular_radius = glm::radians(radius);
  }

  void read_environment(const JsonNode& node) {
    Environment& env = scene_.environment;
    if (node.has("color")) {
      node.check_object({"color"});
      const JsonNode color = node.child("color");
      env.kind = Environment::Kind::Constant;
      env.color = color.vec3();
      for (int i = 0; i < 3; ++i)
        if (!(env.color[i] >= 0.0f)) color.fail("components must not be negative");
      return;
    }
    node.check_object({"file", "intensity", "rotation_deg"});
    const JsonNode file = node.child("file");
    env.kind = Environment::Kind::Map;
    // Float maps (hdr, exr) are linear; an 8-bit map is an sRGB photograph.
    env.map_texture = texture(file, ImageDecode{true, false, false});
    const float intensity = node.number_or("intensity", 1.0f);
    if (!(intensity >= 0.0f)) node.child("intensity").fail("intensity must not be negative");
    env.color = glm::vec3(intensity);
    // One turn at most before radians: the float of a large angle's radians resolves the azimuth
    // poorly (3.6e6 degrees: 0.004 rad steps); below 360 fmod changes nothing.
    const double degrees = node.number_or("rotation_deg", 0.0f);
    env.rotation = glm::radians(static_cast<float>(std::fmod(degrees, 360.0)));
  }

  bool has_light() const {
    for (const Mesh& mesh : scene_.meshes)
      if (!mesh.triangles.empty() && scene_.materials.at(mesh.material).is_emissive()) return true;
    const glm::vec3 sun = scene_.sun.irradiance;
    if (scene_.sun.enabled && (sun.x > 0.0f || sun.y > 0.0f || sun.z > 0.0f)) return true;
    const Environment& environment = scene_.environment;
    const glm::vec3 env = environment.color;
    if (environment.kind == Environment::Kind::None ||
        !(env.x > 0.0f || env.y > 0.0f || env.z > 0.0f))
      return false;
    if (environment.kind != Environment::Kind::Map) return true;
    // A map lights only where it is not black in a channel its colour keeps.
    const Texture& map = scene_.textures.at(static_cast<std::size_t>(environment.map_texture));
    for (int y = 0; y < map.height; ++y)
      for (int x = 0; x < map.width; ++x) {
        const glm::vec4 t = map.fetch(x, y);
        if (t.x * env.x > 0.0f || t.y * env.y > 0.0f || t.z * env.z > 0.0f) return true;
      }
    return false;
  }

  const std::string& path_;
  Scene& scene_;
  AssetPaths assets_;
  TextureCache cache_;
  std::map<std::string, std::uint32_t> named_;  // "materials" name -> Scene::materials index
  int shape_count_ = 0;
};

}  // namespace

Scene load_scene(const std::string& json_path, const SceneLoadSettings& settings) {
  const nlohmann::json document = parse_file(json_path);
  Scene scene;
  scene.source_path = json_path;
  SceneBuilder builder(json_path, settings, scene);
  builder.build(JsonNode(document, json_path, ""));
  for (const Material& m : scene.materials)
    if (m.bump_texture >= 0) prepare_bump_slopes(scene.textures[m.bump_texture]);
  return scene;
}

}  // namespace rtpg
