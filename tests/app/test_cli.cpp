// The rtpg program as a user meets it. Bad input of every kind must end with exit code 2 and
// a one-line message on stderr naming the file or flag at fault, and must leave the output
// folder exactly as it was: no new file, no temporary left behind, an existing output file
// byte for byte unchanged. Good input must write valid images and statistics.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <sys/wait.h>

#include <OpenImageIO/imageio.h>
#include <nlohmann/json.hpp>

#include "support/test_env.h"

namespace fs = std::filesystem;

namespace rtpg {
namespace {

std::string rtpg_binary() {
  const char* env = std::getenv("RTPG_BINARY");
  return env ? env : RTPG_BINARY_PATH;
}

std::string source_dir() {
  const char* env = std::getenv("RTPG_SOURCE_DIR");
  return env ? env : RTPG_SOURCE_DIR;
}

std::string shell_quote(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

std::string read_file(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void write_file(const fs::path& path, const std::string& content) {
  std::ofstream(path, std::ios::binary) << content;
}

std::string random_bytes(std::size_t n, unsigned seed) {
  std::mt19937 rng(seed);
  std::string out(n, '\0');
  for (char& c : out) c = static_cast<char>(rng() & 0xff);
  return out;
}

struct RunResult {
  bool exited = false;  // false: killed by a signal (a crash)
  int exit_code = -1;
  int signal = 0;
  std::string out, err;
};

// Runs `rtpg ARGS` with `cwd` as working directory. stdout and stderr go to files in a
// separate folder, so that the working directory holds only what rtpg itself writes.
// `env` (optional): arguments of env(1) put before rtpg, e.g. "-u NAME NAME2=value".
RunResult run_rtpg(const fs::path& cwd, const std::string& args, const std::string& env = "") {
  test::TempDir capture;
  const fs::path out = capture.path() / "stdout", err = capture.path() / "stderr";
  // exec: the shell becomes rtpg, so a crash shows as a signal rather than as exit code 128+n.
  const std::string command = "cd " + shell_quote(cwd.string()) + " && exec " +
                              (env.empty() ? "" : "env " + env + " ") + shell_quote(rtpg_binary()) +
                              " " + args + " >" + shell_quote(out.string()) + " 2>" +
                              shell_quote(err.string());
  const int status = std::system(command.c_str());
  RunResult r;
  r.exited = WIFEXITED(status);
  r.exit_code = r.exited ? WEXITSTATUS(status) : -1;
  r.signal = WIFSIGNALED(status) ? WTERMSIG(status) : 0;
  r.out = read_file(out);
  r.err = read_file(err);
  return r;
}

// Every file under `dir` (relative path -> bytes), hidden temporaries included.
std::map<std::string, std::string> snapshot(const fs::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& entry : fs::recursive_directory_iterator(dir))
    if (entry.is_regular_file())
      files[fs::relative(entry.path(), dir).string()] = read_file(entry.path());
    else if (!entry.is_directory())
      files[fs::relative(entry.path(), dir).string()] = "<not a regular file>";
  return files;
}

std::string describe(const RunResult& r) {
  return "exit " + (r.exited ? std::to_string(r.exit_code) : "signal " + std::to_string(r.signal)) +
         "\n--- stderr ---\n" + r.err + "--- stdout ---\n" + r.out;
}

constexpr const char* kCamera =
    R"("camera": {"position": [0, 1, 3], "look_at": [0, 1, 0], "fov": 40})";

// A valid scene: an emissive quad and a second quad of material `material` (defined by
// `material_json`), plus `extra` top-level keys (with their leading comma).
std::string scene_with(const std::string& material_json, const std::string& extra = "") {
  return std::string("{") + kCamera + R"(,
  "materials": {"lamp": {"emission": [1, 1, 1]}, "surface": )" +
         material_json + R"(},
  "shapes": [
    {"type": "quad", "corner": [-1, 2, -1], "edge1": [2, 0, 0], "edge2": [0, 0, 2], "material": "lamp"},
    {"type": "quad", "corner": [-1, 0, -1], "edge1": [2, 0, 0], "edge2": [0, 2, 0], "material": "surface"}])" +
         extra + "}";
}

class Cli : public ::testing::Test {
 protected:
  const fs::path& dir() const { return dir_.path(); }
  void write(const std::string& name, const std::string& content) const {
    write_file(dir() / name, content);
  }

  // Runs rtpg with `args` twice: with the `outputs` absent, then with each present holding
  // sentinel bytes. Both runs must exit with 2 and print one line naming `subject`, and
  // leave the folder exactly as it was.
  void expect_rejected(const std::string& args, const std::string& subject,
                       const std::vector<std::string>& outputs = {"out.exr", "stats.json"}) {
    for (const bool outputs_exist : {false, true}) {
      SCOPED_TRACE(std::string("rtpg ") + args +
                   (outputs_exist ? " (outputs exist)" : " (no outputs yet)"));
      for (const auto& name : outputs) {
        fs::remove(dir() / name);
        if (outputs_exist) write(name, "precious bytes of " + name + " that must survive\n");
      }
      const auto before = snapshot(dir());
      const RunResult r = run_rtpg(dir(), args);
      ASSERT_TRUE(r.exited) << describe(r);
      EXPECT_EQ(r.exit_code, 2) << describe(r);
      EXPECT_FALSE(r.err.empty());
      EXPECT_EQ(r.err.rfind("rtpg: ", 0), 0u) << r.err;
      EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << "not one line:\n" << r.err;
      EXPECT_EQ(r.err.back(), '\n');
      EXPECT_NE(r.err.find(subject), std::string::npos)
          << "message does not name '" << subject << "': " << r.err;
      const auto after = snapshot(dir());
      EXPECT_EQ(after, before) << "the folder changed";
      for (const auto& [name, bytes] : after)
        EXPECT_EQ(before.count(name), 1u) << "new file " << name;
    }
  }

  // The render flags of a bad-input run: tiny and fast where it gets that far.
  static std::string render(const std::string& args) {
    return "render " + args + " --spp 1 --guiding off -o out.exr --stats-json stats.json";
  }

 private:
  test::TempDir dir_;
};

// ---- bad scenes and assets ----------------------------------------------------------------

TEST_F(Cli, RejectsMissingSceneFile) {
  expect_rejected(render("missing.json --res 16x16"), "missing.json");
}

TEST_F(Cli, RejectsMalformedJsonScene) {
  write("broken.json", std::string("{") + kCamera + R"(, "materials": {"lamp": )");
  expect_rejected(render("broken.json --res 16x16"), "broken.json");
}

TEST_F(Cli, RejectsSceneWithWrongKey) {
  write("typo.json", scene_with(R"({"base_colour": [1, 0, 0]})"));
  expect_rejected(render("typo.json --res 16x16"), "typo.json");
}

TEST_F(Cli, RejectsMissingMesh) {
  write("scene.json",
        scene_with("{}", R"(, "meshes": [{"file": "gone.ply", "material": "surface"}])"));
  expect_rejected(render("scene.json --res 16x16"), "gone.ply");
}

TEST_F(Cli, RejectsGarbageMesh) {
  write("garbage.ply", random_bytes(4096, 1));
  write("scene.json",
        scene_with("{}", R"(, "meshes": [{"file": "garbage.ply", "material": "surface"}])"));
  expect_rejected(render("scene.json --res 16x16"), "garbage.ply");
}

TEST_F(Cli, RejectsTruncatedMesh) {
  // A valid header that promises more vertices and faces than the file holds.
  write("short.ply",
        "ply\nformat ascii 1.0\nelement vertex 1000\nproperty float x\nproperty float y\n"
        "property float z\nelement face 10\nproperty list uchar int vertex_indices\n"
        "end_header\n0 0 0\n1 0 0\n");
  write("scene.json",
        scene_with("{}", R"(, "meshes": [{"file": "short.ply", "material": "surface"}])"));
  expect_rejected(render("scene.json --res 16x16"), "short.ply");
}

TEST_F(Cli, RejectsMissingTexture) {
  write("scene.json", scene_with(R"({"base_color_texture": "gone.png"})"));
  expect_rejected(render("scene.json --res 16x16"), "gone.png");
}

TEST_F(Cli, RejectsGarbageTexture) {
  write("noise.png", random_bytes(4096, 2));
  write("scene.json", scene_with(R"({"base_color_texture": "noise.png"})"));
  expect_rejected(render("scene.json --res 16x16"), "noise.png");
}

TEST_F(Cli, RejectsTextureWithPngSignatureAndGarbage) {
  // Gets past the signature check into libpng's chunk reader, which reports on stderr itself.
  write("fake.png", std::string("\x89PNG\r\n\x1a\n", 8) + random_bytes(4096, 3));
  write("scene.json", scene_with(R"({"base_color_texture": "fake.png"})"));
  expect_rejected(render("scene.json --res 16x16"), "fake.png");
}

TEST_F(Cli, RejectsMissingEnvironmentMap) {
  write("scene.json", scene_with("{}", R"(, "environment": {"file": "gone.hdr"})"));
  expect_rejected(render("scene.json --res 16x16"), "gone.hdr");
}

TEST_F(Cli, RejectsGarbageEnvironmentMap) {
  write("noise.hdr", random_bytes(4096, 4));
  write("scene.json", scene_with("{}", R"(, "environment": {"file": "noise.hdr"})"));
  expect_rejected(render("scene.json --res 16x16"), "noise.hdr");
}

// ---- bad flags -----------------------------------------------------------------------------

TEST_F(Cli, RejectsUnknownFlag) {
  expect_rejected(render("--res 16x16 --bogus"), "--bogus");
}

TEST_F(Cli, RejectsZeroResolution) {
  expect_rejected(render("--res 0x0"), "--res");
}

// A side beyond 65536 pixels, even where the whole image is small (rtpg/image_size.h), and more
// than 8192^2 pixels in all.
TEST_F(Cli, RejectsResolutionsTooLarge) {
  expect_rejected(render("--res 70000x8"), "--res");
  expect_rejected(render("--res 8x70000"), "--res");
  expect_rejected(render("--res 16384x8193"), "--res");
}

TEST_F(Cli, RejectsNonNumericResolution) {
  expect_rejected(render("--res abc"), "--res");
}

TEST_F(Cli, RejectsResolutionWithTrailingGarbage) {
  expect_rejected(render("--res 16x16x"), "--res");
}

TEST_F(Cli, RejectsZeroSamplesPerPixel) {
  expect_rejected("render --res 16x16 --spp 0 --guiding off -o out.exr --stats-json stats.json",
                  "--spp");
}

TEST_F(Cli, RejectsZeroFrames) {
  expect_rejected(render("--res 16x16 --frames 0"), "--frames");
}

TEST_F(Cli, RejectsSavedFrameOutsideTheRender) {
  expect_rejected(render("--res 16x16 --frames 3 --save-frames 0,3"), "--save-frames",
                  {"out.exr", "out-f0000.exr", "out-f0003.exr", "stats.json"});
}

TEST_F(Cli, RejectsSavedFramesWithoutOutput) {
  expect_rejected("render --res 16x16 --spp 1 --guiding off --frames 2 --save-frames 1",
                  "--save-frames", {"out-f0001.exr"});
}

TEST_F(Cli, RejectsMaxBouncesOutOfRange) {
  expect_rejected(render("--res 16x16 --max-bounces -1"), "--max-bounces");
  // At most 64, as a scene's integrator.max_bounces: a path's depth is recorded in a byte.
  expect_rejected(render("--res 16x16 --max-bounces 65"), "--max-bounces");
}

TEST_F(Cli, RejectsUnknownGuidingMode) {
  expect_rejected("render --res 16x16 --spp 1 --guiding magic -o out.exr", "--guiding",
                  {"out.exr"});
}

TEST_F(Cli, RejectsUnknownGuideVertices) {
  expect_rejected("render --res 16x16 --spp 1 --guide-vertices some -o out.exr", "--guide-vertices",
                  {"out.exr"});
}

TEST_F(Cli, RejectsUnknownSharedRandoms) {
  expect_rejected("render --res 16x16 --spp 2 --share-randoms everything -o out.exr",
                  "--share-randoms", {"out.exr"});
}

TEST_F(Cli, RejectsUnknownDevice) {
  expect_rejected(render("--res 16x16 --device nosuch"), "nosuch");
}

TEST_F(Cli, RejectsResolutionTooLargeForMemory) {
  expect_rejected(render("--res 100000x100000"), "--res");
}

// ---- bad outputs and references -------------------------------------------------------------

TEST_F(Cli, RejectsOutputExtensionOtherThanExrOrPng) {
  expect_rejected("render --res 16x16 --spp 1 --guiding off -o out.jpg", "out.jpg", {"out.jpg"});
}

TEST_F(Cli, RejectsOutputInMissingFolder) {
  expect_rejected("render --res 16x16 --spp 1 --guiding off -o nowhere/out.exr", "nowhere");
}

TEST_F(Cli, RejectsStatsJsonInMissingFolderBeforeWritingTheImage) {
  expect_rejected(
      "render --res 16x16 --spp 1 --guiding off -o out.exr --stats-json nowhere/stats.json",
      "nowhere");
}

// A folder that exists and refuses new files (/proc, even to root): found before the render,
// not after the image was written.
TEST_F(Cli, RejectsStatsJsonInAFolderThatTakesNoFilesBeforeWritingTheImage) {
  expect_rejected(
      "render --res 16x16 --spp 1 --guiding off -o out.exr --stats-json /proc/rtpg-stats.json",
      "/proc/rtpg-stats.json");
  expect_rejected(
      "render --res 16x16 --spp 1 --guiding off -o out.exr --denoise svgf "
      "--noisy-output /proc/rtpg-noisy.exr",
      "/proc/rtpg-noisy.exr");
}

// Options that would be parsed and do nothing: a camera path's frame without the path, later
// vertices borrowing the mixtures of a render that has none.
TEST_F(Cli, RejectsOptionsThatWouldDoNothing) {
  expect_rejected("reference " + source_dir() +
                      "/scenes/cornell-box.json --res 8x8 --spp 1 "
                      "-o ref.exr --frame 3",
                  "--frame", {"ref.exr"});
  expect_rejected("render --res 8x8 --guiding off --guide-vertices all -o out.exr",
                  "--guide-vertices", {"out.exr"});
}

// --accumulate averages frames of one view; along a camera path it would blur the path.
TEST_F(Cli, RejectsAccumulatingAlongACameraPath) {
  expect_rejected(render("--res 16x16 --frames 2 --accumulate --camera-path pan"), "--accumulate");
}

// CLI11's ranges let NaN through: the world guide's two mixing-weight bounds check it.
TEST_F(Cli, RejectsANanWorldGuideMixingWeight) {
  expect_rejected(render("--res 16x16 --guide-vertices world --world-guide-min-pi nan"),
                  "--world-guide-min-pi");
  expect_rejected(render("--res 16x16 --guide-vertices world --world-guide-pi-max nan"),
                  "--world-guide-pi-max");
}

// Options a subcommand would ignore are not offered: reference and info open no OpenCL device,
// info runs no parallel loops.
TEST_F(Cli, ReferenceAndInfoOfferNoDevice) {
  expect_rejected("reference " + source_dir() +
                      "/scenes/cornell-box.json --res 8x8 --spp 1 "
                      "-o ref.exr --device cpu",
                  "--device");
  expect_rejected("info " + source_dir() + "/scenes/cornell-box.json --threads 1", "--threads");
}

TEST_F(Cli, RejectsReferenceOfWrongSize) {
  const RunResult made =
      run_rtpg(dir(), "render --res 16x8 --spp 1 --guiding off -q -o reference.exr");
  ASSERT_EQ(made.exit_code, 0) << describe(made);
  expect_rejected(render("--res 32x32 --reference reference.exr"), "reference.exr");
}

// The outputs of a run are distinct files, none of them an input: -o onto the reference would
// replace what the run reads, -o and --stats-json in one file would leave an "EXR" of JSON.
// Spellings of one path count as one ("./"). Refused before any work, the reference unchanged.
TEST_F(Cli, RejectsOutputsThatAreOneFileOrAnInput) {
  const RunResult made =
      run_rtpg(dir(), "render --res 16x16 --spp 1 --guiding off -q -o reference.exr");
  ASSERT_EQ(made.exit_code, 0) << describe(made);
  expect_rejected(
      "render --res 16x16 --spp 1 --guiding off --reference reference.exr -o "
      "./reference.exr",
      "reference.exr", {});
  expect_rejected("render --res 16x16 --spp 1 --guiding off -o same.exr --stats-json same.exr",
                  "--stats-json", {"same.exr"});
  expect_rejected(
      "render --res 16x16 --spp 1 --frames 2 --guiding off -o out.exr --denoise svgf "
      "--noisy-output out.exr",
      "--noisy-output", {"out.exr"});
  expect_rejected("reference " + shell_quote(source_dir() + "/scenes/cornell-box.json") +
                      " --res 16x16 --spp 1 -o ref.exr --stats-json ref.exr",
                  "--stats-json", {"ref.exr"});
}

// An output that is an existing folder is refused before the render: the rename into place
// would fail only after the frames saved beside it were written.
TEST_F(Cli, RejectsAnOutputThatIsAFolder) {
  fs::create_directory(dir() / "folder.exr");
  expect_rejected(
      "render --res 16x16 --spp 1 --frames 2 --save-frames 0 --guiding off -o "
      "folder.exr",
      "folder.exr", {});
  expect_rejected("render --res 16x16 --spp 1 --guiding off -o out.exr --stats-json folder.exr",
                  "folder.exr", {"out.exr"});
}

// A float EXR of any channel count, written by OpenImageIO (references the program must refuse).
void write_float_exr(const fs::path& path, int width, int height, int channels,
                     const std::vector<float>& pixels) {
  auto out = OIIO::ImageOutput::create(path.string());
  ASSERT_TRUE(out);
  const OIIO::ImageSpec spec(width, height, channels, OIIO::TypeDesc::FLOAT);
  ASSERT_TRUE(out->open(path.string(), spec));
  ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, pixels.data()));
  ASSERT_TRUE(out->close());
}

// A reference whose header claims another size is refused before its pixels are allocated (a
// 55-byte HDR file claiming 100000x100000 pixels used to end in std::bad_alloc), and one with a
// NaN pixel is refused instead of making every relMSE NaN.
TEST_F(Cli, RejectsAHugeOrNonFiniteReference) {
  write("huge.hdr", "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 100000 +X 100000\n");
  expect_rejected(render("--res 16x16 --reference huge.hdr"), "huge.hdr");
  std::vector<float> pixels(16 * 16 * 3, 0.5f);
  pixels[3 * 37 + 1] = std::nanf("");
  write_float_exr(dir() / "nan.exr", 16, 16, 3, pixels);
  expect_rejected(render("--res 16x16 --reference nan.exr"), "pixel (5, 2) is not finite");
}

// A reference is radiance: a tonemapped 8-bit PNG (relMSE against it would mean nothing) and a
// header claiming more channels than RGBA are refused before any pixel is read.
TEST_F(Cli, RejectsAReferenceThatIsNoRadianceImage) {
  const RunResult made = run_rtpg(dir(), "render --res 16x16 --spp 1 --guiding off -q -o ref.png");
  ASSERT_EQ(made.exit_code, 0) << describe(made);
  expect_rejected(render("--res 16x16 --reference ref.png"), "ref.png");
  write_float_exr(dir() / "five.exr", 16, 16, 5, std::vector<float>(16 * 16 * 5, 0.5f));
  expect_rejected(render("--res 16x16 --reference five.exr"), "5 channels");
}

TEST_F(Cli, RejectsMissingReference) {
  expect_rejected(render("--res 16x16 --reference gone.exr"), "gone.exr");
}

TEST_F(Cli, RejectsCorruptReference) {
  write("noise.exr", std::string("\x76\x2f\x31\x01", 4) + random_bytes(4096, 5));
  expect_rejected(render("--res 16x16 --reference noise.exr"), "noise.exr");
}

TEST_F(Cli, ReferenceCommandRejectsPngOutput) {
  expect_rejected("reference " + shell_quote(source_dir() + "/scenes/cornell-box.json") +
                      " --res 16x16 --spp 4 -o ref.png",
                  "ref.png", {"ref.png"});
}

TEST_F(Cli, ReferenceCommandRejectsZeroSamples) {
  expect_rejected("reference " + shell_quote(source_dir() + "/scenes/cornell-box.json") +
                      " --res 16x16 --spp 0 -o ref.exr",
                  "--spp", {"ref.exr"});
}

// ---- good input ------------------------------------------------------------------------------

struct ExrImage {
  int width = 0, height = 0, channels = 0;
  std::vector<float> pixels;
  std::map<std::string, std::string> metadata;
};

ExrImage read_exr(const fs::path& path) {
  ExrImage image;
  auto in = OIIO::ImageInput::open(path.string());
  if (!in) return image;
  const OIIO::ImageSpec& spec = in->spec();
  image.width = spec.width;
  image.height = spec.height;
  image.channels = spec.nchannels;
  image.pixels.resize(static_cast<std::size_t>(spec.width) * spec.height * spec.nchannels);
  if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, image.pixels.data()))
    image.pixels.clear();
  for (const auto& attribute : spec.extra_attribs)
    if (attribute.type() == OIIO::TypeDesc::STRING)
      image.metadata[attribute.name().string()] = attribute.get_string();
  return image;
}

TEST_F(Cli, RenderOfDefaultSceneWritesExrAndStatistics) {
  const RunResult r = run_rtpg(
      dir(), "render --res 32x32 --spp 2 --frames 2 --seed 7 -o out.exr --stats-json stats.json");
  ASSERT_TRUE(r.exited && r.exit_code == 0) << describe(r);
  EXPECT_TRUE(r.err.empty()) << r.err;

  const ExrImage image = read_exr(dir() / "out.exr");
  ASSERT_EQ(image.width, 32);
  ASSERT_EQ(image.height, 32);
  ASSERT_GE(image.channels, 3);
  ASSERT_EQ(image.pixels.size(), 32u * 32u * image.channels);
  double sum = 0.0;
  for (float v : image.pixels) {
    ASSERT_TRUE(std::isfinite(v) && v >= 0.0f) << v;
    sum += v;
  }
  EXPECT_GT(sum, 0.0) << "a black image";
  EXPECT_EQ(image.metadata.count("rtpg:spp") ? image.metadata.at("rtpg:spp") : "", "2");

  const nlohmann::json stats = nlohmann::json::parse(read_file(dir() / "stats.json"));
  for (const char* key : {"scene", "width", "height", "spp", "seed", "device", "frames"})
    EXPECT_TRUE(stats.contains(key)) << "stats.json lacks '" << key << "'";
  EXPECT_NE(stats.value("scene", std::string()).find("cornell-box.json"), std::string::npos);
  EXPECT_EQ(stats.value("width", 0), 32);
  EXPECT_EQ(stats.value("height", 0), 32);
  EXPECT_EQ(stats.value("spp", 0), 2);
  EXPECT_EQ(stats.value("seed", 0), 7);
  EXPECT_FALSE(stats.value("device", std::string()).empty());
  ASSERT_TRUE(stats["frames"].is_array());
  ASSERT_EQ(stats["frames"].size(), 2u);
  for (std::size_t f = 0; f < 2; ++f) {
    const nlohmann::json& frame = stats["frames"][f];
    EXPECT_EQ(frame.value("index", -1), static_cast<int>(f));
    ASSERT_TRUE(frame.contains("time_ms") && frame["time_ms"].is_object());
    for (const char* stage :
         {"total", "primary", "gbuffer", "first_bounce", "trace", "shade", "compact"}) {
      ASSERT_TRUE(frame["time_ms"].contains(stage)) << "frame " << f << " lacks time_ms." << stage;
      EXPECT_TRUE(frame["time_ms"][stage].is_number());
      EXPECT_GE(frame["time_ms"][stage].get<double>(), 0.0);
    }
    // The host's stages are disjoint parts of the frame: together no longer than it.
    double stages = 0.0;
    for (const char* stage : {"primary", "gbuffer", "first_bounce", "trace", "shade", "compact"})
      stages += frame["time_ms"][stage].get<double>();
    EXPECT_LE(stages, frame["time_ms"]["total"].get<double>()) << "frame " << f;
    // The frame's wall time runs from its start to the next frame's: it holds the frame.
    ASSERT_TRUE(frame.contains("wall_ms")) << "frame " << f;
    EXPECT_GE(frame["wall_ms"].get<double>(), frame["time_ms"]["total"].get<double>());
    ASSERT_TRUE(frame.contains("nonfinite_samples"));
    EXPECT_EQ(frame["nonfinite_samples"].get<long long>(), 0);
    EXPECT_FALSE(frame.contains("relmse")) << "relmse without a reference";
  }
  EXPECT_EQ(snapshot(dir()).size(), 2u) << "only out.exr and stats.json";
}

TEST_F(Cli, RenderWritesTonemappedPng) {
  const RunResult r = run_rtpg(dir(), "render --res 32x32 --spp 2 --guiding off -q -o out.png");
  ASSERT_TRUE(r.exited && r.exit_code == 0) << describe(r);
  auto in = OIIO::ImageInput::open((dir() / "out.png").string());
  ASSERT_TRUE(in) << OIIO::geterror();
  EXPECT_EQ(in->format_name(), std::string("png"));
  const OIIO::ImageSpec spec = in->spec();
  ASSERT_EQ(spec.width, 32);
  ASSERT_EQ(spec.height, 32);
  ASSERT_GE(spec.nchannels, 3);
  std::vector<std::uint8_t> pixels(32 * 32 * spec.nchannels);
  ASSERT_TRUE(in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::UINT8, pixels.data()));
  const auto [lo, hi] = std::minmax_element(pixels.begin(), pixels.end());
  EXPECT_LT(*lo, *hi) << "a flat image";
}

// The scene file's exposure scales radiance before the PNG's tonemap and leaves the EXR linear:
// the same render at exposure 1 and 4 gives the same EXR, and a PNG at least as bright at every
// channel (brighter wherever the exposure-1 PNG is neither black nor white).
TEST_F(Cli, PngUsesTheScenesExposureAndExrStaysLinear) {
  const std::string surface = R"({"base_color": [0.5, 0.5, 0.5]})";
  write("dim.json", scene_with(surface));
  write("bright.json", scene_with(surface, R"(, "exposure": 4)"));
  for (const char* scene : {"dim", "bright"}) {
    for (const char* ext : {".png", ".exr"}) {
      const RunResult r = run_rtpg(dir(), std::string("render ") + scene +
                                              ".json --res 24x16 --spp 4 --seed 2 --guiding off "
                                              "-q -o " +
                                              scene + ext);
      ASSERT_TRUE(r.exited && r.exit_code == 0) << describe(r);
    }
  }
  const ExrImage dim = read_exr(dir() / "dim.exr"), bright = read_exr(dir() / "bright.exr");
  ASSERT_FALSE(dim.pixels.empty());
  EXPECT_EQ(dim.pixels, bright.pixels) << "EXR is linear radiance, not exposed";
  std::vector<std::uint8_t> png[2];
  for (int k = 0; k < 2; ++k) {
    auto in = OIIO::ImageInput::open((dir() / (k == 0 ? "dim.png" : "bright.png")).string());
    ASSERT_TRUE(in) << OIIO::geterror();
    png[k].resize(24 * 16 * 3);
    ASSERT_TRUE(in->read_image(0, 0, 0, 3, OIIO::TypeDesc::UINT8, png[k].data()));
  }
  int brighter = 0, between = 0;
  for (std::size_t i = 0; i < png[0].size(); ++i) {
    EXPECT_GE(png[1][i], png[0][i]) << "channel " << i;
    if (png[0][i] > 0 && png[0][i] < 255) {
      ++between;
      brighter += png[1][i] > png[0][i];
    }
  }
  EXPECT_GT(between, 0);
  EXPECT_EQ(brighter, between);
}

TEST_F(Cli, StatisticsCarryRelMseAgainstReference) {
  const std::string common = "render --res 32x32 --spp 2 --seed 3 --guiding off -q";
  RunResult r = run_rtpg(dir(), common + " -o reference.exr");
  ASSERT_EQ(r.exit_code, 0) << describe(r);

  // The same settings and seed reproduce the image exactly (the EXR holds 32-bit floats).
  r = run_rtpg(dir(), common + " --reference reference.exr --stats-json same.json");
  ASSERT_EQ(r.exit_code, 0) << describe(r);
  const nlohmann::json same = nlohmann::json::parse(read_file(dir() / "same.json"));
  ASSERT_EQ(same["frames"].size(), 1u);
  ASSERT_TRUE(same["frames"][0].contains("relmse"));
  EXPECT_EQ(same["frames"][0]["relmse"].get<double>(), 0.0);

  // Another seed: new noise, a positive and finite error in every frame.
  r = run_rtpg(dir(),
               "render --res 32x32 --spp 2 --seed 4 --guiding off -q --frames 2 "
               "--reference reference.exr --stats-json other.json -o other.exr");
  ASSERT_EQ(r.exit_code, 0) << describe(r);
  const nlohmann::json other = nlohmann::json::parse(read_file(dir() / "other.json"));
  ASSERT_EQ(other["frames"].size(), 2u);
  for (const auto& frame : other["frames"]) {
    ASSERT_TRUE(frame.contains("relmse"));
    const double relmse = frame["relmse"].get<double>();
    EXPECT_TRUE(std::isfinite(relmse) && relmse > 0.0) << relmse;
  }
  // The last frame's figure is README's definition, worked out here from the two images: the
  // mean over pixels and channels of (I - R)^2 / (R^2 + 0.01).
  const ExrImage image = read_exr(dir() / "other.exr"), ref = read_exr(dir() / "reference.exr");
  ASSERT_EQ(image.pixels.size(), ref.pixels.size());
  double sum = 0.0;
  for (std::size_t k = 0; k < image.pixels.size(); ++k) {
    const double d = image.pixels[k] - ref.pixels[k], r2 = double(ref.pixels[k]) * ref.pixels[k];
    sum += d * d / (r2 + 0.01);
  }
  const double expected = sum / static_cast<double>(image.pixels.size());
  EXPECT_NEAR(other["frames"][1]["relmse"].get<double>(), expected, 1e-9 + 1e-6 * expected);
}

// A scene file whose name is not UTF-8 (Latin-1 bytes): the statistics' JSON replaces the bad
// byte instead of failing the run after its image was written.
TEST_F(Cli, StatisticsOfASceneNamedInLatin1) {
  const std::string name = "sc\xe8ne.json";
  fs::copy_file(source_dir() + "/scenes/cornell-box.json", dir() / name);
  const RunResult r = run_rtpg(
      dir(), "render " + shell_quote(name) + " --res 8x8 -q -o out.exr --stats-json s.json");
  ASSERT_EQ(r.exit_code, 0) << describe(r);
  const nlohmann::json stats = nlohmann::json::parse(read_file(dir() / "s.json"));
  EXPECT_EQ(stats["frames"].size(), 1u);
}

TEST_F(Cli, ThreadsChangeNothingButTheThreadCount) {
  // Every parallel loop of the frame sums in an order that does not depend on the threads
  // (docs/design.md), so one host thread renders the same images, guided and along a camera
  // path, as every core does; the statistics say how many there were. The image is large enough
  // that every loop splits (128x96: six of the path tracer's 2048-pixel blocks, several chunks of
  // every other pixel loop); the bounce rays go grouped, and the second pair trains and samples
  // the world guide; every frame is compared.
  for (const std::string variant : {"", " --guide-vertices world"}) {
    const std::string common =
        "render --res 128x96 --frames 3 --spp 2 --seed 9 --camera-path pan -q "
        "--bounce-ray-order grouped --save-frames 0,1" +
        variant + " --stats-json ";
    RunResult r = run_rtpg(dir(), common + "all.json -o all.exr");
    ASSERT_EQ(r.exit_code, 0) << describe(r);
    r = run_rtpg(dir(), common + "one.json -o one.exr --threads 1");
    ASSERT_EQ(r.exit_code, 0) << describe(r);
    for (const char* image : {"-f0000.exr", "-f0001.exr", ".exr"})
      EXPECT_EQ(read_exr(dir() / (std::string("one") + image)).pixels,
                read_exr(dir() / (std::string("all") + image)).pixels)
          << image << variant;
  }
  const nlohmann::json one = nlohmann::json::parse(read_file(dir() / "one.json"));
  EXPECT_EQ(one["threads"].get<int>(), 1);
  // A limit above the cores is a limit, not the threads that ran.
  RunResult r = run_rtpg(dir(), "render --res 8x8 -q --threads 4096 --stats-json many.json");
  ASSERT_EQ(r.exit_code, 0) << describe(r);
  const nlohmann::json many = nlohmann::json::parse(read_file(dir() / "many.json"));
  EXPECT_LE(many["threads"].get<unsigned>(), std::max(1u, std::thread::hardware_concurrency()));
  r = run_rtpg(dir(), "render --res 8x8 -q --threads -2");
  EXPECT_EQ(r.exit_code, 2) << describe(r);
  EXPECT_NE(r.err.find("--threads"), std::string::npos) << describe(r);
}

// Every feature at once, at sizes where a work-group, a row of lanes or a 5x5 filter tap has
// nothing beside it (one pixel; one row or column; prime widths; a row shorter than a work-group
// and one longer than the 16 lanes by one), with the camera moving and several samples a pixel:
// each run exits 0, every frame's samples are finite and the image is finite and non-negative.
// Twice: in place with the mixture's MIS density, and with every host transfer packed and both
// of the device's overlaps on (what a device with memory of its own can run; the sampling's
// overlap needs the BSDF's MIS density, so that run keeps the default).
TEST_F(Cli, EveryFeatureAtOddSizesStaysFinite) {
  const std::string features =
      "render --spp 3 --frames 4 --camera-path pan --denoise svgf --guide-vertices world -q "
      "-o out.exr --stats-json stats.json ";
  struct Way {
    const char* args;
    double sample_overlap;
  };
  const Way ways[] = {
      {"--host-transfer in-place --first-bounce-mis mixture", 0.0},
      {"--host-transfer packed --train-overlap on --sample-overlap on", 1.0},
  };
  const std::pair<int, int> sizes[] = {{1, 1},   {1, 7},   {7, 1},   {17, 3},
                                       {333, 1}, {1, 190}, {129, 65}};
  for (const Way& way : ways) {
    for (const auto& [w, h] : sizes) {
      const std::string res = std::to_string(w) + "x" + std::to_string(h);
      SCOPED_TRACE(res + " " + way.args);
      const RunResult r = run_rtpg(dir(), features + "--res " + res + " " + way.args);
      ASSERT_TRUE(r.exited && r.exit_code == 0) << describe(r);
      const nlohmann::json stats = nlohmann::json::parse(read_file(dir() / "stats.json"));
      ASSERT_EQ(stats["frames"].size(), 4u);
      for (const nlohmann::json& frame : stats["frames"]) {
        EXPECT_EQ(frame["nonfinite_samples"].get<long long>(), 0);
        EXPECT_EQ(frame["sample_overlap"].get<double>(), way.sample_overlap);
      }
      const ExrImage image = read_exr(dir() / "out.exr");
      ASSERT_EQ(image.width, w);
      ASSERT_EQ(image.height, h);
      for (float v : image.pixels) ASSERT_TRUE(std::isfinite(v) && v >= 0.0f) << v;
    }
  }
}

TEST_F(Cli, SavesTheRequestedFramesBesideTheOutput) {
  const RunResult r =
      run_rtpg(dir(), "render --res 16x16 --frames 3 --seed 5 -q --save-frames 2,0 -o out.exr");
  ASSERT_EQ(r.exit_code, 0) << describe(r);
  const auto files = snapshot(dir());
  EXPECT_EQ(files.size(), 3u) << "out.exr, out-f0000.exr and out-f0002.exr only";
  const ExrImage last = read_exr(dir() / "out.exr");
  const ExrImage first = read_exr(dir() / "out-f0000.exr");
  const ExrImage saved_last = read_exr(dir() / "out-f0002.exr");
  ASSERT_EQ(first.pixels.size(), 16u * 16u * first.channels);
  EXPECT_EQ(saved_last.pixels, last.pixels) << "frame 2 is the last frame";
  EXPECT_NE(first.pixels, last.pixels) << "frame 0 has its own noise";
  EXPECT_EQ(first.metadata.at("rtpg:frame"), "0");
  EXPECT_EQ(saved_last.metadata.at("rtpg:frame"), "2");

  // Frame 0 of a longer run is the image of a one-frame run with the same seed.
  const RunResult one = run_rtpg(dir(), "render --res 16x16 --frames 1 --seed 5 -q -o one.exr");
  ASSERT_EQ(one.exit_code, 0) << describe(one);
  EXPECT_EQ(read_exr(dir() / "one.exr").pixels, first.pixels);
}

TEST_F(Cli, InfoCountsMatchTheSceneFile) {
  const std::string scene_path = source_dir() + "/scenes/cornell-box.json";
  const nlohmann::json scene = nlohmann::json::parse(read_file(scene_path));
  // Triangles per shape as scenes/README.md defines them.
  std::size_t triangles = 0, emissive_triangles = 0;
  for (const auto& shape : scene["shapes"]) {
    const std::string type = shape["type"];
    const std::size_t n = type == "quad"  ? 2
                          : type == "box" ? 12
                                          : 20u << (2 * shape.value("subdivisions", 4));
    triangles += n;
    const auto& material = scene["materials"][shape["material"].get<std::string>()];
    bool emissive = false;
    if (material.contains("emission"))
      for (const auto& c : material["emission"]) emissive = emissive || c.get<double>() > 0.0;
    if (emissive) emissive_triangles += n;
  }
  ASSERT_FALSE(scene.contains("meshes")) << "the counts above cover shapes only";

  const RunResult r = run_rtpg(dir(), "info " + shell_quote(scene_path));
  ASSERT_TRUE(r.exited && r.exit_code == 0) << describe(r);
  std::map<std::string, std::string> lines;
  std::istringstream text(r.out);
  for (std::string line; std::getline(text, line);) {
    const auto colon = line.find(": ");
    if (colon != std::string::npos) lines[line.substr(0, colon)] = line.substr(colon + 2);
  }
  EXPECT_EQ(lines["triangles"], std::to_string(triangles)) << r.out;
  EXPECT_EQ(lines["materials"], std::to_string(scene["materials"].size())) << r.out;
  EXPECT_EQ(lines["lights"].rfind(std::to_string(emissive_triangles) + " emissive triangles", 0),
            0u)
      << r.out;
}

TEST_F(Cli, DevicesListsAtLeastOneDevice) {
  const RunResult r = run_rtpg(dir(), "devices");
  ASSERT_TRUE(r.exited) << describe(r);
  EXPECT_EQ(r.exit_code, 0) << describe(r);
  EXPECT_FALSE(r.out.empty());
}

// rtpg reference reports what it cost: samples per second = width * height * spp / seconds, in
// its line, in --stats-json and in the EXR metadata (rtpg:samples_per_second).
TEST_F(Cli, ReferenceReportsSamplesPerSecond) {
  const RunResult r =
      run_rtpg(dir(), "reference " + shell_quote(source_dir() + "/scenes/cornell-box.json") +
                          " --res 24x16 --spp 8 -o ref.exr --stats-json ref.json");
  ASSERT_TRUE(r.exited) << describe(r);
  ASSERT_EQ(r.exit_code, 0) << describe(r);
  EXPECT_NE(r.out.find("M samples/s"), std::string::npos) << r.out;
  const nlohmann::json stats = nlohmann::json::parse(read_file(dir() / "ref.json"));
  const double seconds = stats.at("seconds"), rate = stats.at("samples_per_second");
  EXPECT_EQ(stats.at("spp"), 8);
  ASSERT_GT(seconds, 0.0);
  EXPECT_NEAR(rate, 24.0 * 16.0 * 8.0 / seconds, 1e-6 * rate);
  auto in = OIIO::ImageInput::open((dir() / "ref.exr").string());
  ASSERT_TRUE(in);
  EXPECT_NEAR(std::stod(in->spec().get_string_attribute("rtpg:samples_per_second")), rate,
              0.5 + 1e-6 * rate);
}

// `rtpg reference` and `rtpg render --accumulate` both average frames of the same random streams:
// a reference of 8 spp (two passes of 4) equals two accumulated 4-spp frames of the same seed, to
// float rounding, and the accumulated image's relMSE against it is that rounding while each
// frame's own relMSE is not. A reference that averaged its passes wrongly (a sum, the last pass
// alone, divided by the sample count), or ignored --max-bounces or the seed, and an accumulation
// that wrote or measured the last frame instead of the running mean, all fail here
// (bench/suite/equal_time.py reads relmse_accumulated; the references are every error's yardstick).
TEST_F(Cli, ReferenceEqualsTheAccumulatedFramesOfTheSameSeed) {
  const std::string scene = shell_quote(source_dir() + "/scenes/cornell-box.json");
  for (const std::string& args :
       {"reference " + scene + " --res 20x12 --spp 8 --seed 3 --max-bounces 2 -q -o ref.exr",
        "reference " + scene + " --res 20x12 --spp 8 --seed 3 --max-bounces 3 -q -o deeper.exr",
        "reference " + scene + " --res 20x12 --spp 8 --seed 4 --max-bounces 2 -q -o seed4.exr",
        "render " + scene + " --res 20x12 --spp 4 --frames 2 --seed 3 --max-bounces 2 --guiding " +
            "off --accumulate -q -o accumulated.exr --reference ref.exr --stats-json stats.json"}) {
    const RunResult r = run_rtpg(dir(), args);
    ASSERT_TRUE(r.exited) << describe(r);
    ASSERT_EQ(r.exit_code, 0) << describe(r);
  }
  const ExrImage reference = read_exr(dir() / "ref.exr"),
                 accumulated = read_exr(dir() / "accumulated.exr");
  ASSERT_EQ(reference.pixels.size(), 20u * 12u * 3u);
  ASSERT_EQ(accumulated.pixels.size(), reference.pixels.size());
  double sum = 0.0;
  for (std::size_t i = 0; i < reference.pixels.size(); ++i) {
    const float want = reference.pixels[i], got = accumulated.pixels[i];
    EXPECT_NEAR(got, want, 1e-5f * std::max(1.0f, std::fabs(want))) << "value " << i;
    sum += want;
  }
  EXPECT_GT(sum, 0.0);
  // The deeper reference and the other seed's differ from it (so the comparison above can fail).
  for (const char* other : {"deeper.exr", "seed4.exr"}) {
    const ExrImage o = read_exr(dir() / other);
    ASSERT_EQ(o.pixels.size(), reference.pixels.size()) << other;
    std::size_t differing = 0;
    for (std::size_t i = 0; i < o.pixels.size(); ++i)
      differing += std::fabs(o.pixels[i] - reference.pixels[i]) >
                   1e-4f * std::max(1.0f, std::fabs(reference.pixels[i]));
    EXPECT_GT(differing, o.pixels.size() / 20) << other;
  }
  const nlohmann::json stats = nlohmann::json::parse(read_file(dir() / "stats.json"));
  EXPECT_EQ(stats.at("max_bounces"), 2);
  const nlohmann::json& frames = stats.at("frames");
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_GT(frames[0].at("relmse").get<double>(), 1e-4);
  EXPECT_GT(frames[1].at("relmse").get<double>(), 1e-4);
  EXPECT_LT(frames[1].at("relmse_accumulated").get<double>(), 1e-9);
  EXPECT_GT(frames[0].at("relmse_accumulated").get<double>(), 1e-4);
}

// No OpenCL platform at all (the ICD loader finds no vendor file): exit code 3, the OpenCL
// failure's one line, and nothing written, for every command that needs a device.
TEST_F(Cli, NoOpenClPlatformIsExitThree) {
  write("scene.json", scene_with(R"({"base_color": [0.5, 0.5, 0.5]})"));
  test::TempDir no_vendors;
  const std::string env = "OCL_ICD_VENDORS=" + shell_quote(no_vendors.path().string());
  for (const std::string& args :
       {std::string("devices"), render("scene.json --res 16x16"),
        std::string("render scene.json --res 16x16 --spp 1 --guiding pmm -o out.exr")}) {
    SCOPED_TRACE(args);
    const auto before = snapshot(dir());
    const RunResult r = run_rtpg(dir(), args, env);
    ASSERT_TRUE(r.exited) << describe(r);
    EXPECT_EQ(r.exit_code, 3) << describe(r);
    EXPECT_EQ(r.err.rfind("rtpg: OpenCL: ", 0), 0u) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << "not one line:\n" << r.err;
    EXPECT_EQ(snapshot(dir()), before) << "files written without a device";
  }
}

// A cache folder that cannot be created only costs the caches: rendering works, with and
// without guiding, and writes its image (docs/design.md: the program cache).
TEST_F(Cli, UnwritableCacheFolderStillRenders) {
  write("scene.json", scene_with(R"({"base_color": [0.5, 0.5, 0.5]})"));
  const std::string env = "-u POCL_CACHE_DIR -u XDG_CACHE_HOME RTPG_CACHE_DIR=/proc/rtpg-cache";
  for (const char* guiding : {"off", "pmm"}) {
    SCOPED_TRACE(guiding);
    fs::remove(dir() / "out.exr");
    const RunResult r =
        run_rtpg(dir(),
                 std::string("render scene.json --res 16x16 --spp 1 --frames 2 --guiding ") +
                     guiding + " -o out.exr",
                 env);
    ASSERT_TRUE(r.exited) << describe(r);
    EXPECT_EQ(r.exit_code, 0) << describe(r);
    EXPECT_TRUE(fs::exists(dir() / "out.exr")) << describe(r);
  }
  EXPECT_FALSE(fs::exists("/proc/rtpg-cache"));
}

// ---- the denoiser ------------------------------------------------------------------------

TEST_F(Cli, DenoiseWritesTheFilteredAndTheNoisyFrameWithTheirStatistics) {
  const RunResult r = run_rtpg(dir(),
                               "render --res 40x24 --frames 3 --denoise svgf -o out.exr "
                               "--noisy-output noisy.exr --save-frames 1 --stats-json stats.json");
  ASSERT_TRUE(r.exited && r.exit_code == 0) << describe(r);
  const ExrImage out = read_exr(dir() / "out.exr");
  const ExrImage noisy = read_exr(dir() / "noisy.exr");
  ASSERT_EQ(out.pixels.size(), noisy.pixels.size());
  ASSERT_FALSE(out.pixels.empty());
  EXPECT_EQ(out.metadata.at("rtpg:denoise"), "svgf");
  EXPECT_EQ(noisy.metadata.at("rtpg:denoise"), "off");
  EXPECT_TRUE(fs::exists(dir() / "out-f0001.exr"));
  EXPECT_TRUE(fs::exists(dir() / "noisy-f0001.exr"));
  // The filter changes the image; both stay finite.
  double differ = 0.0;
  for (std::size_t i = 0; i < out.pixels.size(); ++i) {
    ASSERT_TRUE(std::isfinite(out.pixels[i]));
    differ += std::fabs(out.pixels[i] - noisy.pixels[i]);
  }
  EXPECT_GT(differ, 0.0);
  // The noisy images, the last frame's and the saved one's, are the frames the same render
  // writes without the denoiser, to the bit.
  const RunResult plain =
      run_rtpg(dir(), "render --res 40x24 --frames 3 -o plain.exr --save-frames 1");
  ASSERT_TRUE(plain.exited && plain.exit_code == 0) << describe(plain);
  EXPECT_EQ(read_exr(dir() / "plain.exr").pixels, noisy.pixels);
  const ExrImage saved = read_exr(dir() / "noisy-f0001.exr");
  ASSERT_EQ(saved.pixels.size(), noisy.pixels.size());
  EXPECT_EQ(read_exr(dir() / "plain-f0001.exr").pixels, saved.pixels);
  EXPECT_NE(saved.pixels, noisy.pixels);
  const nlohmann::json stats = nlohmann::json::parse(read_file(dir() / "stats.json"));
  EXPECT_EQ(stats.value("denoise", std::string()), "svgf");
  EXPECT_EQ(stats["svgf_settings"].value("iterations", 0), 5);
  const nlohmann::json& last = stats["frames"][2];
  for (const char* key :
       {"svgf_temporal", "svgf_variance", "svgf_atrous", "svgf_remodulate", "svgf_total"})
    EXPECT_TRUE(last["time_ms"].contains(key)) << key;
  EXPECT_TRUE(last.contains("flicker_mse_noisy"));
  // Nothing crosses where the guided frame reads in place (zero_copy, PoCL's CPU device);
  // elsewhere (RTPG_HOST_TRANSFER=packed, the tests' second run) SVGF reads the guider's copy of
  // the G-buffer and moves the colour (12 bytes) and emission (16) up and the denoised colour
  // (12) down: 40 bytes.
  ASSERT_TRUE(last.contains("zero_copy"));
  EXPECT_EQ(last.value("svgf_host_device_bytes_per_pixel", -1.0),
            last.value("zero_copy", 0.0) == 1.0 ? 0.0 : 40.0);
}

// The world guide's cells' mixing weight must stay below 1, as the pixels' (--pg-pi-max): at 1 a
// guided vertex would never sample its BSDF.
TEST_F(Cli, RejectsAWorldGuideMixingWeightOfOne) {
  expect_rejected(render("--res 16x16 --guide-vertices world --world-guide-pi-max 1"),
                  "--world-guide-pi-max");
}

TEST_F(Cli, RejectsBadDenoiserSettings) {
  expect_rejected(render("--res 16x16 --denoise svgf --svgf-iterations 0"), "iterations");
  expect_rejected(render("--res 16x16 --denoise svgf --svgf-history-iteration 5"),
                  "history_iteration");
  expect_rejected(render("--res 16x16 --noisy-output noisy.exr"), "--noisy-output",
                  {"out.exr", "stats.json", "noisy.exr"});
}

}  // namespace
}  // namespace rtpg
