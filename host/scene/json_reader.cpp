// Type checks and error messages for scene files.
#include "scene/json_reader.h"

#include <cmath>
#include <limits>

#include "rtpg/errors.h"

namespace rtpg {

namespace {

std::string type_name(const nlohmann::json& v) {
  if (v.is_number()) return "a number";
  if (v.is_string()) return "a string \"" + v.get<std::string>() + "\"";
  if (v.is_boolean()) return v.get<bool>() ? "true" : "false";
  if (v.is_null()) return "null";
  if (v.is_array()) return "an array of " + std::to_string(v.size());
  return "an object";
}

}  // namespace

void JsonNode::fail(const std::string& problem) const {
  throw InputError(*file_, path_.empty() ? problem : path_ + ": " + problem);
}

void JsonNode::fail_type(const std::string& what) const {
  fail("expected " + what + ", got " + type_name(*value_));
}

void JsonNode::check_object(std::initializer_list<const char*> allowed) const {
  if (!value_->is_object()) fail_type("an object");
  for (auto it = value_->begin(); it != value_->end(); ++it) {
    bool known = false;
    for (const char* key : allowed) known = known || it.key() == key;
    if (known) continue;
    std::string list;
    for (const char* key : allowed) list += (list.empty() ? "" : ", ") + std::string(key);
    child(it.key()).fail("unknown key (allowed here: " + list + ")");
  }
}

bool JsonNode::has(const char* key) const {
  return value_->is_object() && value_->contains(key);
}

JsonNode JsonNode::child(const char* key) const {
  const std::string path = path_.empty() ? key : path_ + "." + key;
  if (!value_->is_object()) fail_type("an object");
  const auto it = value_->find(key);
  if (it == value_->end()) JsonNode(*value_, *file_, path).fail("missing required key");
  return JsonNode(*it, *file_, path);
}

std::vector<std::string> JsonNode::keys() const {
  if (!value_->is_object()) fail_type("an object");
  std::vector<std::string> out;
  for (auto it = value_->begin(); it != value_->end(); ++it) out.push_back(it.key());
  return out;
}

std::size_t JsonNode::size() const {
  if (!value_->is_array()) fail_type("an array");
  return value_->size();
}

JsonNode JsonNode::operator[](std::size_t i) const {
  if (!value_->is_array()) fail_type("an array");
  return JsonNode((*value_)[i], *file_, path_ + "[" + std::to_string(i) + "]");
}

float JsonNode::number() const {
  if (!value_->is_number()) fail_type("a number");
  const double v = value_->get<double>();
  if (!std::isfinite(v) || std::abs(v) > std::numeric_limits<float>::max())
    fail("number out of range");
  return static_cast<float>(v);
}

int JsonNode::integer() const {
  if (!value_->is_number_integer()) fail_type("an integer");
  const auto v = value_->get<long long>();
  if (v < std::numeric_limits<int>::min() || v > std::numeric_limits<int>::max())
    fail("integer out of range");
  return static_cast<int>(v);
}

bool JsonNode::boolean() const {
  if (!value_->is_boolean()) fail_type("true or false");
  return value_->get<bool>();
}

std::string JsonNode::string() const {
  if (!value_->is_string()) fail_type("a string");
  return value_->get<std::string>();
}

glm::vec3 JsonNode::vec3() const {
  if (!value_->is_array() || value_->size() != 3) fail_type("an array of 3 numbers");
  glm::vec3 v;
  for (int i = 0; i < 3; ++i) v[i] = (*this)[static_cast<std::size_t>(i)].number();
  return v;
}

float JsonNode::number_or(const char* key, float fallback) const {
  return has(key) ? child(key).number() : fallback;
}

bool JsonNode::boolean_or(const char* key, bool fallback) const {
  return has(key) ? child(key).boolean() : fallback;
}

}  // namespace rtpg
