#include "cl/kernel_source.h"

#include <cstdlib>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <utility>
#include <vector>

#include "rtpg/errors.h"

namespace rtpg {
namespace {

const char* kernel_dir_override() {
  const char* dir = std::getenv("RTPG_KERNEL_DIR");
  return (dir != nullptr && dir[0] != '\0') ? dir : nullptr;
}

// Updates in_comment across one line: enough C lexing to tell whether the next line starts
// inside a /* */ comment (string and character literals may hold "/*").
void scan_comments(const std::string& line, bool& in_comment) {
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    const char next = i + 1 < line.size() ? line[i + 1] : '\0';
    if (in_comment) {
      if (c == '*' && next == '/') {
        in_comment = false;
        ++i;
      }
    } else if (c == '/' && next == '/') {
      return;
    } else if (c == '/' && next == '*') {
      in_comment = true;
      ++i;
    } else if (c == '"' || c == '\'') {
      for (++i; i < line.size() && line[i] != c; ++i)
        if (line[i] == '\\') ++i;
    }
  }
}

// If line is `#include "path"` (any spacing), sets path and returns true.
bool quoted_include(const std::string& line, std::string& path) {
  std::size_t i = line.find_first_not_of(" \t");
  if (i == std::string::npos || line[i] != '#') return false;
  i = line.find_first_not_of(" \t", i + 1);
  if (i == std::string::npos || line.compare(i, 7, "include") != 0) return false;
  i = line.find_first_not_of(" \t", i + 7);
  if (i == std::string::npos || line[i] != '"') return false;
  const std::size_t end = line.find('"', i + 1);
  if (end == std::string::npos) return false;
  path = line.substr(i + 1, end - i - 1);
  if (path.compare(0, 2, "./") == 0) path.erase(0, 2);
  return true;
}

// Kernel files live under kernels/, except the public layout header the kernels share with
// host code: "rtpg/<h>" is include/rtpg/<h> (include/rtpg/guiding_layout.h).
bool is_public_header(const std::string& path) {
  return path.compare(0, 5, "rtpg/") == 0;
}

std::string source_path(const std::string& path) {
  return (is_public_header(path) ? "include/" : "kernels/") + path;
}

std::string line_directive(int line, const std::string& path) {
  return "#line " + std::to_string(line) + " \"" + source_path(path) + "\"\n";
}

class Resolver {
 public:
  explicit Resolver(const KernelFileLoader& load) : load_(load) {}

  void include(const std::string& path, const std::string& included_from) {
    const std::optional<std::string> text = load_(path);
    if (!text) {
      throw InputError(source_path(path),
                       "no such kernel file" +
                           (included_from.empty() ? "" : " (included from " + included_from + ")") +
                           " in " + kernel_file_origin() + " kernel sources");
    }
    included_.insert(path);
    out_ += line_directive(1, path);
    std::istringstream in(*text);
    std::string line, target;
    bool in_comment = false;
    for (int number = 1; std::getline(in, line); ++number) {
      if (!in_comment && quoted_include(line, target)) {
        if (included_.count(target) != 0) {
          out_ += "// #include \"" + target + "\": already included above\n";
        } else {
          include(target, source_path(path) + ":" + std::to_string(number));
          out_ += line_directive(number + 1, path);
        }
        continue;
      }
      scan_comments(line, in_comment);
      out_ += line;
      out_ += '\n';
    }
  }

  std::string take() { return std::move(out_); }

 private:
  const KernelFileLoader& load_;
  std::set<std::string> included_;
  std::string out_;
};

}  // namespace

std::optional<std::string> load_kernel_file(const std::string& path) {
  if (const char* dir = kernel_dir_override()) {
    // The public header sits beside the kernels folder: <dir>/../include/rtpg/<h>.
    const std::string file_path =
        std::string(dir) + (is_public_header(path) ? "/../include/" : "/") + path;
    std::ifstream file(file_path, std::ios::binary);
    if (!file) return std::nullopt;
    std::ostringstream text;
    text << file.rdbuf();
    return text.str();
  }
  const auto& files = embedded_kernel_files();
  const auto it = files.find(path);
  if (it == files.end()) return std::nullopt;
  return it->second;
}

std::string kernel_file_origin() {
  if (const char* dir = kernel_dir_override()) return std::string("RTPG_KERNEL_DIR=") + dir;
  return "embedded";
}

std::string resolve_kernel_source(const std::string& kernel_file, const KernelFileLoader& load) {
  Resolver resolver(load);
  resolver.include(kernel_file, "");
  return resolver.take();
}

std::string attribute_build_log(const std::string& log, const std::string& resolved_source) {
  // origin[r - 1]: the file and line of the submitted text's line r (the directives' own lines
  // keep an empty path).
  std::vector<std::pair<std::string, int>> origin;
  static const std::regex directive(R"re(^#line (\d+) "([^"]*)"$)re");
  std::istringstream in(resolved_source);
  std::string line, path;
  int next = 1;
  while (std::getline(in, line)) {
    std::smatch m;
    if (std::regex_match(line, m, directive)) {
      next = std::stoi(m[1].str());
      path = m[2].str();
      origin.emplace_back(std::string(), 0);
    } else {
      origin.emplace_back(path, next++);
    }
  }
  // At most 9 digits: a longer number is no line of ours, and stoul must not throw here.
  static const std::regex raw_position(R"((<kernel>|input\.cl):(\d{1,9})(:\d+)?)");
  std::string out;
  auto last = log.cbegin();
  for (std::sregex_iterator it(log.begin(), log.end(), raw_position), end; it != end; ++it) {
    const std::smatch& m = *it;
    out.append(last, m[0].second);
    last = m[0].second;
    const unsigned long raw = std::stoul(m[2].str());
    if (raw >= 1 && raw <= origin.size() && !origin[raw - 1].first.empty())
      out += " (" + origin[raw - 1].first + ":" + std::to_string(origin[raw - 1].second) + ")";
  }
  out.append(last, log.cend());
  return out;
}

}  // namespace rtpg
