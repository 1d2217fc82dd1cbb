// Include resolution and #line bookkeeping of host/cl/kernel_source.cpp (no device needed).
#include <map>
#include <optional>
#include <string>

#include <gtest/gtest.h>

#include "cl/kernel_source.h"
#include "rtpg/errors.h"

namespace rtpg {
namespace {

KernelFileLoader loader(const std::map<std::string, std::string>& files) {
  return [files](const std::string& path) -> std::optional<std::string> {
    const auto it = files.find(path);
    if (it == files.end()) return std::nullopt;
    return it->second;
  };
}

int count(const std::string& text, const std::string& what) {
  int n = 0;
  for (auto pos = text.find(what); pos != std::string::npos; pos = text.find(what, pos + 1)) ++n;
  return n;
}

TEST(KernelSource, InlinesIncludesWithLineDirectives) {
  const std::map<std::string, std::string> files = {
      {"k.cl", "// kernel\n#include \"shared/a.h\"\nint k;\n"},
      {"shared/a.h", "#include \"shared/b.h\"\nint a;\n"},
      {"shared/b.h", "int b;\n"},
  };
  const std::string expected =
      "#line 1 \"kernels/k.cl\"\n"
      "// kernel\n"
      "#line 1 \"kernels/shared/a.h\"\n"
      "#line 1 \"kernels/shared/b.h\"\n"
      "int b;\n"
      "#line 2 \"kernels/shared/a.h\"\n"
      "int a;\n"
      "#line 3 \"kernels/k.cl\"\n"
      "int k;\n";
  EXPECT_EQ(resolve_kernel_source("k.cl", loader(files)), expected);
}

TEST(KernelSource, IncludesEachFileOnceAndKeepsLineNumbers) {
  const std::map<std::string, std::string> files = {
      {"k.cl",
       "#include \"shared/a.h\"\n#include \"shared/b.h\"\n  #  include \"shared/a.h\"\nx\n"},
      {"shared/a.h", "#include \"shared/b.h\"\nA\n"},
      {"shared/b.h", "B\n"},
  };
  const std::string source = resolve_kernel_source("k.cl", loader(files));
  EXPECT_EQ(count(source, "\nB\n"), 1);
  EXPECT_EQ(count(source, "\nA\n"), 1);
  // The skipped includes still occupy their lines, so "x" is on line 4 without a new #line.
  EXPECT_NE(source.find("#line 2 \"kernels/k.cl\"\n// #include \"shared/b.h\": already "
                        "included above\n// #include \"shared/a.h\": already included above\nx\n"),
            std::string::npos)
      << source;
}

// Compilers that ignore #line print positions in the submitted text (NVIDIA's OpenCL:
// "<kernel>:N:C", Oclgrind: "input.cl:N:C"); the log names the real file and line beside each.
TEST(KernelSource, BuildLogPositionsInTheSubmittedTextNameTheRealLines) {
  const std::map<std::string, std::string> files = {
      {"k.cl", "// kernel\n#include \"shared/a.h\"\nint k = oops;\n"},
      {"shared/a.h", "int a;\nint b = bad;\n"},
  };
  const std::string source = resolve_kernel_source("k.cl", loader(files));
  // Submitted lines: 1 #line, 2 "// kernel", 3 #line, 4 "int a;", 5 "int b = bad;",
  // 6 #line, 7 "int k = oops;".
  EXPECT_EQ(attribute_build_log("<kernel>:5:9: error: bad\n<kernel>:7:9: error: oops\n", source),
            "<kernel>:5:9 (kernels/shared/a.h:2): error: bad\n"
            "<kernel>:7:9 (kernels/k.cl:3): error: oops\n");
  EXPECT_EQ(attribute_build_log("input.cl:4: warning", source),
            "input.cl:4 (kernels/shared/a.h:1): warning");
  // Already attributed positions, lines past the end, and directive lines stay as they are.
  const std::string untouched =
      "kernels/k.cl:3:9: error\n<kernel>:99:1: x\n<kernel>:6:1: y\n<kernel>:123456789012345678901: "
      "z\n";
  EXPECT_EQ(attribute_build_log(untouched, source), untouched);
}

TEST(KernelSource, LeavesCommentedAndAngleIncludesAlone) {
  const std::map<std::string, std::string> files = {
      {"k.cl",
       "/* a comment\n#include \"shared/missing.h\"\n*/\n#include <stdio.h>\n"
       "// #include \"shared/missing.h\"\n"},
  };
  const std::string source = resolve_kernel_source("k.cl", loader(files));
  EXPECT_NE(source.find("#include \"shared/missing.h\"\n*/"), std::string::npos);
  EXPECT_NE(source.find("#include <stdio.h>"), std::string::npos);
}

TEST(KernelSource, MissingFileNamesTheIncludeSite) {
  const std::map<std::string, std::string> files = {
      {"k.cl", "\n\n#include \"shared/nope.h\"\n"},
  };
  try {
    resolve_kernel_source("k.cl", loader(files));
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("kernels/shared/nope.h: no such kernel file"), std::string::npos) << what;
    EXPECT_NE(what.find("included from kernels/k.cl:3"), std::string::npos) << what;
  }
  EXPECT_THROW(resolve_kernel_source("other.cl", loader(files)), InputError);
}

TEST(KernelSource, EmbeddedTreeHoldsTheKernelsAndHeaders) {
  const auto& files = embedded_kernel_files();
  EXPECT_EQ(files.count("tonemap.cl"), 1u);
  EXPECT_EQ(files.count("accumulate.cl"), 1u);
  EXPECT_EQ(files.count("shared/compat.h"), 1u);
  EXPECT_EQ(files.count("shared/tonemap.h"), 1u);
  const std::string source = resolve_kernel_source("tonemap.cl", [&](const std::string& p) {
    const auto it = files.find(p);
    return it == files.end() ? std::nullopt : std::optional<std::string>(it->second);
  });
  EXPECT_NE(source.find("#line 1 \"kernels/shared/compat.h\""), std::string::npos);
  EXPECT_EQ(source.find("#include \"shared/"), std::string::npos);
}

}  // namespace
}  // namespace rtpg
