// Text checks of OBJ and MTL files (obj_check.h). One pass over each file, a line at a time;
// only statements whose numbers assimp would take are checked, everything else is assimp's.
#include "scene/obj_check.h"

#include <cfloat>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <cstdio>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "rtpg/errors.h"

namespace rtpg {
namespace {

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> tokens;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
    std::size_t j = i;
    while (j < line.size() && line[j] != ' ' && line[j] != '\t' && line[j] != '\r') ++j;
    if (j > i && line[i] == '#') break;  // a comment to the end of the line
    if (j > i) tokens.push_back(line.substr(i, j - i));
    i = j;
  }
  return tokens;
}

// Where a problem is, for the error message: "line 12" or "line 12, material 'red'".
struct Place {
  const std::string& file;
  const std::string& context;
  std::size_t line = 0;
  std::string material;

  [[noreturn]] void fail(const std::string& problem) const {
    std::string where = "line " + std::to_string(line);
    if (!material.empty()) where += ", material '" + material + "'";
    throw InputError(file, where + ": " + problem + " (" + context + ")");
  }
};

// The value of a numeric token that must be a finite float.
float parse_number(const std::string& token, const std::string& statement, const Place& at) {
  const std::string shown = token.size() > 24 ? token.substr(0, 24) + "..." : token;
  if (token.size() > kMaxNumberLength)
    at.fail(statement + ": a number of " + std::to_string(token.size()) + " characters (at most " +
            std::to_string(kMaxNumberLength) + ")");
  const char* first = token.data();
  const char* last = token.data() + token.size();
  if (first != last && *first == '+') ++first;  // from_chars takes no '+'; OBJ writers do
  double value = 0.0;
  const auto [end, error] = std::from_chars(first, last, value);
  if (error == std::errc::result_out_of_range)
    at.fail(statement + ": '" + shown + "' is outside the float range");
  if (error != std::errc() || end != last) at.fail(statement + ": '" + shown + "' is not a number");
  if (!std::isfinite(value)) at.fail(statement + ": '" + shown + "' is not a finite number");
  if (std::fabs(value) > FLT_MAX)
    at.fail(statement + ": '" + shown + "' is outside the float range");
  return static_cast<float>(value);
}

void check_vertex_statement(const std::vector<std::string>& t, const Place& at) {
  const std::string& s = t[0];
  const std::size_t count = t.size() - 1;
  const bool count_ok = s == "v"    ? (count == 3 || count == 4 || count == 6 || count == 7)
                        : s == "vn" ? count == 3
                                    : (count >= 1 && count <= 3);  // vt, vp
  if (!count_ok) at.fail(s + ": " + std::to_string(count) + " numbers");
  for (std::size_t i = 1; i < t.size(); ++i) parse_number(t[i], s, at);
}

// The range of each numeric MTL statement (docs/robustness.md): colours and factors.
struct MtlRange {
  float lo, hi;
  bool lo_open;  // lo itself excluded (Ni > 0)
  std::size_t min_count, max_count;
};

const std::map<std::string, MtlRange>& mtl_ranges() {
  static const std::map<std::string, MtlRange> ranges = {
      {"Ka", {0.0f, FLT_MAX, false, 1, 3}},  {"Kd", {0.0f, 1.0f, false, 1, 3}},
      {"Ks", {0.0f, 1.0f, false, 1, 3}},     {"Ke", {0.0f, FLT_MAX, false, 1, 3}},
      {"Tf", {0.0f, 1.0f, false, 1, 3}},     {"Ns", {0.0f, FLT_MAX, false, 1, 1}},
      {"Ni", {0.0f, FLT_MAX, true, 1, 1}},   {"d", {0.0f, 1.0f, false, 1, 1}},
      {"Tr", {0.0f, 1.0f, false, 1, 1}},     {"Pr", {0.0f, 1.0f, false, 1, 1}},
      {"Pm", {0.0f, 1.0f, false, 1, 1}},     {"Ps", {0.0f, 1.0f, false, 1, 1}},
      {"Pc", {0.0f, 1.0f, false, 1, 1}},     {"Pcr", {0.0f, 1.0f, false, 1, 1}},
      {"aniso", {0.0f, 1.0f, false, 1, 1}},  {"anisor", {0.0f, 1.0f, false, 1, 1}},
      {"illum", {0.0f, 10.0f, false, 1, 1}}, {"sharpness", {0.0f, FLT_MAX, false, 1, 1}}};
  return ranges;
}

std::string range_text(const MtlRange& r) {
  if (r.hi == FLT_MAX) return r.lo_open ? "must be above 0" : "must not be negative";
  return "must lie in [0, " + std::to_string(static_cast<int>(r.hi)) + "]";
}

void check_mtl_statement(const std::vector<std::string>& t, const Place& at) {
  const std::string& s = t[0];
  if (s.rfind("map_", 0) == 0 || s == "bump" || s == "norm" || s == "disp" || s == "decal" ||
      s == "refl") {
    // Texture statements: only the bump multiplier reaches a material value (bump_scale).
    for (std::size_t i = 1; i + 1 < t.size(); ++i)
      if (t[i] == "-bm") parse_number(t[i + 1], s + " -bm", at);
    return;
  }
  const auto found = mtl_ranges().find(s);
  if (found == mtl_ranges().end()) return;
  const MtlRange& r = found->second;
  std::size_t first = 1;
  // "Kd xyz x y z" and "d -halo f" carry a word first; "Kd spectral file.rfl" has no numbers.
  if (t.size() > 1 && (t[1] == "xyz" || t[1] == "-halo")) first = 2;
  if (t.size() > 1 && t[1] == "spectral") return;
  const std::size_t count = t.size() - first;
  if (count < r.min_count || count > r.max_count)
    at.fail(s + ": " + std::to_string(count) + " numbers");
  for (std::size_t i = first; i < t.size(); ++i) {
    const float v = parse_number(t[i], s, at);
    if (!(r.lo_open ? v > r.lo : v >= r.lo) || v > r.hi)
      at.fail(s + ": " + t[i] + " " + range_text(r));
  }
}

// Calls `statement` for every non-empty, non-comment line of `path`.
template <class Visit>
void for_each_statement(const std::string& path, const std::string& context, Visit visit) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, "cannot be read (" + context + ")");
  std::string line;
  std::size_t number = 0;
  while (std::getline(in, line)) {
    ++number;
    // OBJ and MTL are text. assimp 5.2.5 reads a NUL as the end of its buffer and then reads
    // past the MTL's end (a crash, found by fuzzing), even inside a comment.
    for (const char c : line)
      if (static_cast<unsigned char>(c) < 0x20 && c != '\t' && c != '\r') {
        char code[8];
        std::snprintf(code, sizeof code, "0x%02x", static_cast<unsigned>(c));
        throw InputError(path, "line " + std::to_string(number) + ": a control byte (" + code +
                                   ") in a text file (" + context + ")");
      }
    const std::size_t start = line.find_first_not_of(" \t\r");
    if (start == std::string::npos || line[start] == '#') continue;
    visit(number, line);
  }
}

void check_mtl(const std::string& path, const std::string& context) {
  std::string material;
  bool in_material = false;
  for_each_statement(path, context, [&](std::size_t line, const std::string& text) {
    const std::vector<std::string> t = split(text);
    if (t.empty()) return;  // whitespace before a comment
    if (t[0] == "newmtl") {
      material = t.size() > 1 ? t[1] : "";
      in_material = true;
      return;
    }
    Place at{path, context, line, material};
    // assimp 5.2.5 writes through a null material for a texture statement before the first
    // newmtl (a crash found by fuzzing: tests/fuzz/corpus/mtl/texture-before-newmtl.mtl), and
    // a statement that belongs to no material means nothing anyway.
    if (!in_material) at.fail("'" + t[0].substr(0, 24) + "' before the first newmtl");
    check_mtl_statement(t, at);
  });
}

}  // namespace

void check_obj(const std::string& path, const std::string& context, bool with_materials) {
  std::vector<std::string> libraries;
  for_each_statement(path, context, [&](std::size_t line, const std::string& text) {
    // Only the first token decides; a long line is split only when it is a statement we check.
    const std::size_t start = text.find_first_not_of(" \t");
    const std::size_t end = text.find_first_of(" \t\r", start);
    const std::string keyword = text.substr(start, end == std::string::npos ? end : end - start);
    const Place at{path, context, line, ""};
    if (keyword == "v" || keyword == "vn" || keyword == "vt" || keyword == "vp") {
      check_vertex_statement(split(text), at);
    } else if (keyword == "mtllib") {
      // assimp ignores a missing .mtl and gives every surface its default grey.
      std::string name = text.substr(end == std::string::npos ? text.size() : end);
      name.erase(0, name.find_first_not_of(" \t"));
      while (!name.empty() && (name.back() == ' ' || name.back() == '\t' || name.back() == '\r'))
        name.pop_back();
      if (!name.empty()) libraries.push_back(name);
    }
  });
  for (const std::string& name : libraries) {
    const std::filesystem::path mtl = std::filesystem::path(path).parent_path() / name;
    const std::string mtl_context = "mtllib of " + path + ", " + context;
    std::error_code ec;
    if (!std::filesystem::is_regular_file(mtl, ec)) {
      // Without materials from the file (the scene overrides them) a missing library costs
      // nothing: assimp skips it.
      if (!with_materials) continue;
      throw InputError(mtl.lexically_normal().string(), "file not found (" + mtl_context + ")");
    }
    // Checked also where the scene overrides the materials: assimp parses the library anyway,
    // and its reader crashes on some malformed ones (docs/robustness.md, "Fuzzing").
    check_mtl(mtl.string(), mtl_context);
  }
}

}  // namespace rtpg
