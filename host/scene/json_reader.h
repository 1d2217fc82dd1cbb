// Checked access to a parsed JSON document: every value knows its file and key path, so each
// error can say exactly what is wrong where ("scene.json: meshes[0].transform.scale: ...").
#pragma once

#include <cstddef>
#include <initializer_list>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

namespace rtpg {

class JsonNode {
 public:
  // `file` is the error subject; `path` the key path of `value` ("" for the root).
  JsonNode(const nlohmann::json& value, const std::string& file, std::string path)
      : value_(&value), file_(&file), path_(std::move(path)) {}

  const std::string& path() const { return path_; }
  const std::string& file() const { return *file_; }
  const nlohmann::json& raw() const { return *value_; }
  bool is_null() const { return value_->is_null(); }
  bool is_array() const { return value_->is_array(); }
  bool is_object() const { return value_->is_object(); }
  bool is_number() const { return value_->is_number(); }
  bool is_string() const { return value_->is_string(); }

  // Throws InputError(file, "<path>: <problem>").
  [[noreturn]] void fail(const std::string& problem) const;
  // fail("expected <what>, got <type>").
  [[noreturn]] void fail_type(const std::string& what) const;

  // Objects. check_object fails unless this is an object whose keys are all in `allowed`.
  void check_object(std::initializer_list<const char*> allowed) const;
  bool has(const char* key) const;
  JsonNode child(const char* key) const;  // fails when the key is missing
  std::vector<std::string> keys() const;  // sorted (nlohmann::json objects are std::maps)
  JsonNode child(const std::string& key) const { return child(key.c_str()); }

  // Arrays.
  std::size_t size() const;  // fails unless an array
  JsonNode operator[](std::size_t i) const;

  // Scalars; each fails on the wrong type. Numbers must be finite.
  float number() const;
  int integer() const;
  bool boolean() const;
  std::string string() const;
  glm::vec3 vec3() const;  // an array of 3 numbers

  // Optional keys with defaults.
  float number_or(const char* key, float fallback) const;
  bool boolean_or(const char* key, bool fallback) const;

 private:
  const nlohmann::json* value_;
  const std::string* file_;
  std::string path_;
};

}  // namespace rtpg
