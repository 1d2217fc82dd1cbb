// A minimal PLY reader that only walks the file's structure.
#include "scene/ply_check.h"

#include <cfloat>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <sstream>
#include <vector>

#include "rtpg/errors.h"

namespace rtpg {

namespace {

enum class Format { Ascii, BinaryLittle, BinaryBig };

struct Property {
  std::string name;
  int size = 0;                              // bytes of the value (list: of each item)
  int count_size = 0;                        // bytes of the list length; 0 for scalar properties
  bool is_signed = false, is_float = false;  // of the value (list: of each item)
};

struct Element {
  std::string name;
  std::uint64_t count = 0;
  std::vector<Property> properties;
};

int type_size(const std::string& type) {
  if (type == "char" || type == "uchar" || type == "int8" || type == "uint8") return 1;
  if (type == "short" || type == "ushort" || type == "int16" || type == "uint16") return 2;
  if (type == "int" || type == "uint" || type == "int32" || type == "uint32" || type == "float" ||
      type == "float32")
    return 4;
  if (type == "double" || type == "float64") return 8;
  return 0;
}

bool is_float_type(const std::string& t) {
  return t == "float" || t == "float32" || t == "double" || t == "float64";
}

bool is_signed_type(const std::string& t) {
  return t == "char" || t == "int8" || t == "short" || t == "int16" || t == "int" || t == "int32";
}

bool is_face_index(const Element& e, const Property& p) {
  return e.name == "face" && p.count_size > 0 &&
         (p.name == "vertex_indices" || p.name == "vertex_index");
}

class PlyChecker {
 public:
  PlyChecker(const std::string& path, const std::string& context)
      : path_(path), context_(context) {}

  void run() {
    std::ifstream in(path_, std::ios::binary);
    if (!in) fail("cannot be read");
    data_.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    read_header();
    if (format_ == Format::Ascii)
      walk_ascii();
    else
      walk_binary();
  }

 private:
  [[noreturn]] void fail(const std::string& problem) const {
    throw InputError(path_, "corrupt PLY file: " + problem + " (" + context_ + ")");
  }

  // The next header line without its line ending; fails at the end of the data.
  std::string header_line() {
    const std::size_t end = data_.find('\n', pos_);
    if (end == std::string::npos) fail("the header has no end_header line");
    std::string line = data_.substr(pos_, end - pos_);
    pos_ = end + 1;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    // The header is printable ASCII. We split words at any whitespace, assimp at spaces and
    // tabs only: a vertical tab before "property" hid the property from assimp, which then
    // read a misaligned body and aborted (found by fuzzing).
    for (const char c : line)
      if ((c < 0x20 || c > 0x7e) && c != '\t') fail("a control or non-ASCII byte in the header");
    return line;
  }

  void read_header() {
    if (header_line() != "ply") fail("it does not start with 'ply'");
    bool have_format = false;
    for (;;) {
      std::istringstream words(header_line());
      std::string keyword;
      words >> keyword;
      if (keyword == "end_header") break;
      if (keyword == "comment" || keyword == "obj_info" || keyword.empty()) continue;
      if (keyword == "format") {
        // Two format lines make assimp 5.2.5 read the body in one format and triangulate it as
        // the other, ending in an assert (found by fuzzing); the PLY header has exactly one.
        if (have_format) fail("a second format line");
        std::string format, version;
        words >> format >> version;
        if (version != "1.0") fail("format version '" + version + "' (only 1.0 exists)");
        if (format == "ascii")
          format_ = Format::Ascii;
        else if (format == "binary_little_endian")
          format_ = Format::BinaryLittle;
        else if (format == "binary_big_endian")
          format_ = Format::BinaryBig;
        else
          fail("unknown format '" + format + "'");
        have_format = true;
      } else if (keyword == "element") {
        Element e;
        std::string extra;
        if (!(words >> e.name >> e.count) || (words >> extra)) fail("bad element line");
        // assimp 5.2.5 matches element names without regard to case, reads a repeated element
        // again and skips unknown ones, and writes out of bounds on such headers (found by
        // fuzzing; valgrind shows the invalid write). rtpg accepts the canonical layout only:
        // 'vertex', then 'face', each at most once, in lower case.
        if (e.name != "vertex" && e.name != "face")
          fail("element '" + e.name + "' (rtpg reads PLY elements 'vertex' and 'face' only)");
        for (const Element& other : elements_)
          if (other.name == e.name) fail("a second element '" + e.name + "'");
        if (e.name == "vertex" && !elements_.empty()) fail("element 'vertex' after 'face'");
        elements_.push_back(e);
      } else if (keyword == "property") {
        if (elements_.empty()) fail("a property before any element");
        Property p;
        std::string type;
        words >> type;
        if (type == "list") {
          std::string count_type, item_type;
          words >> count_type >> item_type >> p.name;
          p.count_size = type_size(count_type);
          p.size = type_size(item_type);
          p.is_signed = is_signed_type(item_type);
          p.is_float = is_float_type(item_type);
          if (p.count_size == 0 || p.size == 0) fail("bad list property '" + p.name + "'");
          // A length typed float or double could exceed every integer (found by fuzzing).
          if (is_float_type(count_type) || p.count_size > 4)
            fail("list property '" + p.name + "' has a length of type " + count_type);
        } else {
          words >> p.name;
          p.size = type_size(type);
          p.is_float = is_float_type(type);
          if (p.size == 0) fail("unknown property type '" + type + "'");
        }
        // assimp 5.2.5 misreads a body whose properties have no name and then aborts in its
        // triangulation (an assert; found by fuzzing).
        if (p.name.empty()) fail("a property without a name");
        std::string extra;
        if (words >> extra) fail("property '" + p.name + "' has extra words ('" + extra + "')");
        for (const Property& other : elements_.back().properties)
          if (other.name == p.name) fail("a second property '" + p.name + "'");
        elements_.back().properties.push_back(p);
      } else {
        fail("unknown header keyword '" + keyword + "'");
      }
    }
    if (!have_format) fail("the header has no format line");
    // assimp 5.2.5 builds faces without indices from a face element whose list has another
    // name, and then aborts in its triangulation (an assert; found by fuzzing): faces need
    // their index list, vertices their position.
    for (const Element& e : elements_) {
      if (e.name == "face" && e.count > 0) {
        bool indexed = false;
        for (const Property& p : e.properties) indexed = indexed || is_face_index(e, p);
        if (!indexed) fail("element 'face' has no vertex_indices list");
      }
      if (e.name == "vertex" && e.count > 0)
        for (const char* axis : {"x", "y", "z"}) {
          bool found = false;
          for (const Property& p : e.properties) found = found || p.name == axis;
          if (!found) fail(std::string("element 'vertex' has no property '") + axis + "'");
        }
    }
  }

  std::uint64_t vertex_count() const {
    for (const Element& e : elements_)
      if (e.name == "vertex") return e.count;
    return 0;
  }

  void check_index(double index, std::uint64_t vertices) const {
    if (!(index >= 0.0) || index >= static_cast<double>(vertices))
      fail("a face index is outside the vertex range");
  }

  // assimp takes NaN, infinities and doubles beyond the float range as they are (and its
  // vertex joining then merges a NaN vertex into another one, without a word).
  void check_value(double v, const Element& e, std::uint64_t index, const Property& p) const {
    if (!std::isfinite(v) || std::fabs(v) > FLT_MAX) {
      std::ostringstream text;
      text << "element '" << e.name << "' " << index << ", property '" << p.name << "': " << v
           << " is not a finite float";
      throw InputError(path_, text.str() + " (" + context_ + ")");
    }
  }

  // A float or double at pos_, in the file's byte order.
  double read_float(int size) {
    const std::uint64_t bits = read_bits(size);
    if (size == 4) {
      float f;
      const auto b32 = static_cast<std::uint32_t>(bits);
      std::memcpy(&f, &b32, sizeof(f));
      return f;
    }
    double d;
    std::memcpy(&d, &bits, sizeof(d));
    return d;
  }

  // assimp's triangulation aborts the process (an assert) on faces of 0 to 2 vertices.
  void check_face_size(double n) const {
    if (n < 3.0) fail("a face with fewer than 3 vertices");
  }

  // ASCII bodies hold one element per line (assimp reads them line by line: an element split
  // over two lines shifted every later one, and a face read from a vertex line had no
  // indices, which aborts assimp's triangulation; found by fuzzing).
  void walk_ascii() {
    std::istringstream body(data_.substr(pos_));
    const std::uint64_t vertices = vertex_count();
    std::string line_text;
    std::istringstream line;
    std::string token;
    for (const Element& e : elements_)
      for (std::uint64_t i = 0; i < e.count; ++i) {
        do {
          if (!std::getline(body, line_text)) fail("the file ends inside element '" + e.name + "'");
        } while (line_text.find_first_not_of(" \t\r") == std::string::npos);
        // assimp reads the line as a C string: a NUL ends it early, and the rest of the element
        // shifts into the next one (a triangulation assert; found by fuzzing). Text only.
        for (const char c : line_text)
          if ((c < 0x20 || c > 0x7e) && c != '\t' && c != '\r')
            fail("a control or non-ASCII byte in element '" + e.name + "' " + std::to_string(i));
        line.clear();
        line.str(line_text);
        auto next = [&]() {
          if (!(line >> token))
            fail("element '" + e.name + "' " + std::to_string(i) + " has too few values");
          char* end = nullptr;
          const double v = std::strtod(token.c_str(), &end);
          if (end != token.c_str() + token.size() || token.empty())
            fail("'" + token + "' is not a number");
          return v;
        };
        for (const Property& p : e.properties) {
          if (p.count_size == 0) {
            const double v = next();
            if (p.is_float) check_value(v, e, i, p);
            continue;
          }
          const double n = next();
          if (!(n >= 0.0 && n < 4294967296.0) || n != std::floor(n))
            fail("a bad list length in element '" + e.name + "'");
          if (is_face_index(e, p)) check_face_size(n);
          for (std::uint64_t k = 0; k < static_cast<std::uint64_t>(n); ++k) {
            const double v = next();
            if (is_face_index(e, p)) check_index(v, vertices);
            if (p.is_float) check_value(v, e, i, p);
          }
        }
        if (line >> token)
          fail("element '" + e.name + "' " + std::to_string(i) + " has too many values");
      }
  }

  // The `size` bytes at pos_ as an unsigned integer, in the file's byte order.
  std::uint64_t read_bits(int size) {
    std::uint64_t bits = 0;
    for (int b = 0; b < size; ++b) {
      const auto byte = static_cast<unsigned char>(data_[pos_ + static_cast<std::size_t>(b)]);
      const int shift = format_ == Format::BinaryLittle ? 8 * b : 8 * (size - 1 - b);
      bits |= static_cast<std::uint64_t>(byte) << shift;
    }
    pos_ += static_cast<std::size_t>(size);
    return bits;
  }

  double read_integer(int size, bool is_signed) {
    const std::uint64_t bits = read_bits(size);
    if (is_signed && size < 8 && (bits >> (8 * size - 1)) & 1u)
      return static_cast<double>(static_cast<std::int64_t>(bits) - (std::int64_t{1} << (8 * size)));
    return static_cast<double>(bits);
  }

  void need(std::uint64_t bytes, const Element& e) const {
    if (bytes > data_.size() - pos_) fail("the file ends inside element '" + e.name + "'");
  }

  void walk_binary() {
    const std::uint64_t vertices = vertex_count();
    for (const Element& e : elements_) {
      // Elements of fixed-size properties are skipped in one step.
      std::uint64_t fixed = 0;
      bool has_list = false;
      for (const Property& p : e.properties) {
        fixed += static_cast<std::uint64_t>(p.size);
        has_list = has_list || p.count_size > 0;
      }
      bool has_float = false;
      for (const Property& p : e.properties) has_float = has_float || p.is_float;
      if (!has_list) {
        if (fixed != 0 && e.count > (data_.size() - pos_) / fixed)
          fail("the file ends inside element '" + e.name + "'");
        if (!has_float) {
          pos_ += static_cast<std::size_t>(fixed * e.count);
          continue;
        }
      }
      for (std::uint64_t i = 0; i < e.count; ++i)
        for (const Property& p : e.properties) {
          if (p.count_size == 0) {
            need(static_cast<std::uint64_t>(p.size), e);
            if (p.is_float)
              check_value(read_float(p.size), e, i, p);
            else
              pos_ += static_cast<std::size_t>(p.size);
            continue;
          }
          need(static_cast<std::uint64_t>(p.count_size), e);
          // Length types are unsigned in practice (uchar); a signed negative one is corrupt.
          const double n = read_integer(p.count_size, false);
          if (is_face_index(e, p)) check_face_size(n);
          need(static_cast<std::uint64_t>(n) * static_cast<std::uint64_t>(p.size), e);
          if (p.is_float) {
            for (std::uint64_t k = 0; k < static_cast<std::uint64_t>(n); ++k)
              check_value(read_float(p.size), e, i, p);
            continue;
          }
          if (!is_face_index(e, p)) {
            pos_ += static_cast<std::size_t>(n) * static_cast<std::size_t>(p.size);
            continue;
          }
          for (std::uint64_t k = 0; k < static_cast<std::uint64_t>(n); ++k)
            check_index(read_integer(p.size, p.is_signed), vertices);
        }
    }
  }

  const std::string& path_;
  const std::string& context_;
  std::string data_;
  std::size_t pos_ = 0;
  Format format_ = Format::Ascii;
  std::vector<Element> elements_;
};

}  // namespace

void check_ply(const std::string& path, const std::string& context) {
  PlyChecker(path, context).run();
}

}  // namespace rtpg
