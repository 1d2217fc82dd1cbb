// Device selection, the program cache (memory and disk), and how OpenCL failures read.
#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "rtpg/cl_error.h"
#include "rtpg/cl_runtime.h"
#include "rtpg/guider.h"
#include "cl/device.h"
#include "render/image_kernels.h"
#include "support/test_env.h"
#include "rtpg/errors.h"

namespace rtpg {
namespace {

namespace fs = std::filesystem;
using test::ScopedEnv;
using test::TempDir;

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

std::vector<fs::path> cache_files(const std::string& cache_dir) {
  std::vector<fs::path> out;
  const fs::path dir = fs::path(cache_dir) / "programs";
  if (!fs::exists(dir)) return out;
  for (const auto& entry : fs::directory_iterator(dir))
    if (entry.path().extension() == ".clbin") out.push_back(entry.path());
  return out;
}

void write_file(const fs::path& path, const std::string& text) {
  fs::create_directories(path.parent_path());
  std::ofstream(path, std::ios::binary) << text;
}

TEST(ClError, NamesEveryCodeAndFormatsTheMessage) {
  EXPECT_EQ(cl_error_name(CL_SUCCESS), "CL_SUCCESS");
  EXPECT_EQ(cl_error_name(-54), "CL_INVALID_WORK_GROUP_SIZE");
  EXPECT_EQ(cl_error_name(-68), "CL_INVALID_DEVICE_PARTITION_COUNT");
  EXPECT_EQ(cl_error_name(-1001), "CL_PLATFORM_NOT_FOUND_KHR");
  EXPECT_EQ(cl_error_name(-12345), "CL_UNKNOWN_ERROR");
  for (cl_int code = -1; code >= -68; --code) {
    if (code < -19 && code > -30) continue;  // unassigned in OpenCL 1.2
    EXPECT_NE(cl_error_name(code), "CL_UNKNOWN_ERROR") << code;
  }
  const ClError e("clFoo", CL_INVALID_VALUE);
  EXPECT_STREQ(e.what(), "clFoo: CL_INVALID_VALUE (-30)");
  EXPECT_EQ(e.code(), CL_INVALID_VALUE);
  try {
    rethrow_cl_error(cl::Error(CL_OUT_OF_RESOURCES, "clBar"));
    FAIL() << "rethrow_cl_error returned";
  } catch (const ClError& converted) {
    EXPECT_STREQ(converted.what(), "clBar: CL_OUT_OF_RESOURCES (-5)");
  }
}

TEST(ClBuildErrorMessage, KeepsTheFirstFortyLines) {
  std::string log;
  for (int i = 1; i <= 100; ++i) log += "line " + std::to_string(i) + "\n";
  const ClBuildError e("k.cl", "Some Device", log);
  const std::string what = e.what();
  EXPECT_EQ(what.rfind("building k.cl for Some Device: line 1\n", 0), 0u) << what;
  EXPECT_TRUE(contains(what, "line 40\n"));
  EXPECT_FALSE(contains(what, "line 41\n"));
  EXPECT_TRUE(contains(what, "60 more lines"));
  EXPECT_EQ(e.log(), log);
  EXPECT_EQ(e.code(), CL_BUILD_PROGRAM_FAILURE);
}

TEST(Devices, ListsAtLeastOne) {
  const auto devices = list_devices();
  ASSERT_FALSE(devices.empty());
  for (const auto& d : devices) {
    EXPECT_FALSE(d.device_name.empty());
    EXPECT_GT(d.compute_units, 0u);
    EXPECT_GT(d.max_work_group_size, 0u);
    EXPECT_TRUE(d.type == "gpu" || d.type == "cpu" || d.type == "accelerator" || d.type == "other");
  }
}

TEST(Devices, SelectsByTypeIndexAndName) {
  ScopedEnv no_env("RTPG_DEVICE", std::nullopt);
  const auto devices = list_devices();
  ASSERT_FALSE(devices.empty());
  EXPECT_FALSE(select_device("").info.device_name.empty());  // the default always finds one

  const bool has_cpu =
      std::any_of(devices.begin(), devices.end(), [](const auto& d) { return d.type == "cpu"; });
  if (has_cpu) {
    EXPECT_EQ(select_device("cpu").info.type, "cpu");
    EXPECT_EQ(select_device(" CPU ").info.type, "cpu");
  }

  const DeviceInfo& last = devices.back();
  EXPECT_EQ(select_device(last.spec()).info.device_name, last.device_name);

  // A case-flipped piece of the name finds the first device with that piece.
  std::string piece = last.device_name.substr(0, std::min<std::size_t>(6, last.device_name.size()));
  for (char& c : piece)
    c = static_cast<char>(std::isupper(static_cast<unsigned char>(c))
                              ? std::tolower(static_cast<unsigned char>(c))
                              : std::toupper(static_cast<unsigned char>(c)));
  const SelectedDevice by_name = select_device(piece);
  EXPECT_TRUE(contains(by_name.info.device_name, last.device_name.substr(0, piece.size())));
}

TEST(Devices, UnknownSpecListsWhatThereIs) {
  ScopedEnv no_env("RTPG_DEVICE", std::nullopt);
  try {
    select_device("no-such-device-xyz");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.rfind("--device: no OpenCL device matches 'no-such-device-xyz'; available: ", 0),
              0u)
        << what;
    EXPECT_TRUE(contains(what, list_devices().front().device_name)) << what;
  }
  EXPECT_THROW(select_device("7:9"), InputError);
  {
    ScopedEnv bad_env("RTPG_DEVICE", std::string("also-no-such-device"));
    try {
      select_device("");
      FAIL() << "expected InputError";
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()).rfind("RTPG_DEVICE: no OpenCL device matches", 0), 0u);
    }
  }
}

TEST(ProgramCache, SameKeySameProgramOtherOptionsOtherProgram) {
  ClRuntime rt;
  cl::Program& a = rt.program("tonemap.cl");
  cl::Program& b = rt.program("tonemap.cl");
  cl::Program& c = rt.program("tonemap.cl", "-DPG_TEST_UNUSED_OPTION=1");
  EXPECT_EQ(&a, &b);
  EXPECT_EQ(a(), b());
  EXPECT_NE(a(), c());
  EXPECT_EQ(rt.cache_stats().memory_hits, 1);
  EXPECT_EQ(rt.cache_stats().disk_hits + rt.cache_stats().source_builds, 2);
  EXPECT_NE(rt.kernel("tonemap.cl", "tonemap")(), nullptr);
}

TEST(ProgramCache, DiskRoundTripAndCorruptEntry) {
  TempDir dir;
  ScopedEnv cache_env("RTPG_CACHE_DIR", dir.str());
  {
    ClRuntime first;
    EXPECT_EQ(first.cache_dir(), dir.str());
    first.program("accumulate.cl");
    EXPECT_EQ(first.cache_stats().source_builds, 1);
  }
  const auto files = cache_files(dir.str());
  ASSERT_EQ(files.size(), 1u);
  EXPECT_GT(fs::file_size(files.front()), 0u);

  // A fresh runtime loads the binary, and the kernel from it computes.
  {
    ClRuntime second;
    Accumulator acc(second, 3, 1);
    acc.add(std::vector<glm::vec4>(3, glm::vec4(1.0f, 2.0f, 3.0f, 4.0f)));
    acc.add(std::vector<glm::vec4>(3, glm::vec4(3.0f, 4.0f, 5.0f, 6.0f)));
    EXPECT_EQ(second.cache_stats().disk_hits, 1);
    EXPECT_EQ(second.cache_stats().source_builds, 0);
    EXPECT_EQ(acc.read()[2], glm::vec4(2.0f, 3.0f, 4.0f, 5.0f));
  }

  // A damaged entry is rebuilt silently and replaced by a good one.
  write_file(files.front(), "RTPGCLB1 but then garbage");
  {
    ClRuntime third;
    EXPECT_NO_THROW(third.program("accumulate.cl"));
    EXPECT_EQ(third.cache_stats().disk_hits, 0);
    EXPECT_EQ(third.cache_stats().source_builds, 1);
  }
  {
    ClRuntime fourth;
    fourth.program("accumulate.cl");
    EXPECT_EQ(fourth.cache_stats().disk_hits, 1);
  }
  EXPECT_EQ(cache_files(dir.str()).size(), 1u);  // no temporary files left behind
  EXPECT_EQ(std::distance(fs::directory_iterator(dir.path() / "programs"), {}), 1);
}

TEST(ProgramBuild, SyntaxErrorNamesRealFilesAndLines) {
  TempDir kernels;
  write_file(kernels.path() / "shared" / "bad_helper.h",
             "/* line 1 */\n"
             "static inline float pg_helper(float x) {\n"
             "  return x * undeclared_in_header;\n"  // line 3
             "}\n");
  write_file(kernels.path() / "bad.cl",
             "/* line 1 */\n"
             "#include \"shared/bad_helper.h\"\n"
             "\n"
             "__kernel void bad(__global float* out) {\n"
             "  out[0] = pg_helper(1.0f);\n"
             "  out[1] = undeclared_in_kernel;\n"  // line 6
             "}\n");
  ScopedEnv dir_env("RTPG_KERNEL_DIR", kernels.str());
  ClRuntime rt;
  try {
    rt.program("bad.cl");
    FAIL() << "expected ClBuildError";
  } catch (const ClBuildError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.rfind("building bad.cl for " + rt.info().device_name + ": ", 0), 0u) << what;
    // PoCL honours the #line directives; NVIDIA's compiler and Oclgrind 21.10 print raw
    // positions, which attribute_build_log maps back: every device names the real lines.
    EXPECT_TRUE(contains(what, "kernels/shared/bad_helper.h:3")) << what;
    EXPECT_TRUE(contains(what, "kernels/bad.cl:6")) << what;
    EXPECT_TRUE(contains(what, "undeclared_in_header")) << what;
    EXPECT_TRUE(contains(e.log(), "undeclared_in_kernel")) << e.log();
    EXPECT_EQ(e.code(), CL_BUILD_PROGRAM_FAILURE);
  }
  EXPECT_THROW(rt.program("not_there.cl"), InputError);
}

TEST(ClErrors, InvalidCallsNameTheCallAndTheCode) {
  ClRuntime rt;
  try {
    translate_cl_errors([&] { cl::Buffer empty(rt.context(), CL_MEM_READ_WRITE, 0); });
    FAIL() << "expected ClError";
  } catch (const ClError& e) {
    EXPECT_STREQ(e.what(), "clCreateBuffer: CL_INVALID_BUFFER_SIZE (-61)");
  }

  cl::Kernel kernel = rt.kernel("accumulate.cl", "accumulate");
  cl::Buffer buffer(rt.context(), CL_MEM_READ_WRITE, 16 * sizeof(cl_float4));
  kernel.setArg(0, buffer);
  kernel.setArg(1, buffer);
  kernel.setArg(2, cl_uint(10));
  kernel.setArg(3, cl_uint(1));
  kernel.setArg(4, 1.0f);
  try {
    // OpenCL 1.2: the local size must divide the global size.
    translate_cl_errors([&] {
      rt.queue().enqueueNDRangeKernel(kernel, cl::NullRange, cl::NDRange(10), cl::NDRange(3));
    });
    FAIL() << "expected ClError";
  } catch (const ClError& e) {
    EXPECT_STREQ(e.what(), "clEnqueueNDRangeKernel: CL_INVALID_WORK_GROUP_SIZE (-54)");
    EXPECT_EQ(e.code(), CL_INVALID_WORK_GROUP_SIZE);
  }

  try {
    rt.kernel("accumulate.cl", "no_such_kernel");
    FAIL() << "expected ClError";
  } catch (const ClError& e) {
    EXPECT_TRUE(contains(e.what(), "clCreateKernel(no_such_kernel in accumulate.cl)")) << e.what();
    EXPECT_TRUE(contains(e.what(), "CL_INVALID_KERNEL_NAME")) << e.what();
  }
}

TEST(ClRuntimeTiming, EventTimesAreNonNegative) {
  ClRuntime rt;
  Accumulator acc(rt, 32, 32);
  cl::Event event = acc.add(std::vector<glm::vec4>(32 * 32, glm::vec4(1.0f)));
  event.wait();
  const double ms = ClRuntime::event_ms(event);
  // A kernel that ran took some time: a timer that returns 0 (profiling off, or start and end
  // read from the same counter) fails here.
  EXPECT_GT(ms, 0.0);
  EXPECT_LT(ms, 10000.0);
}

// A runtime destroyed before an object that keeps a reference to it stops the program with a
// message (ClRuntime::Use). Without it a test that did so ran on silently on PoCL and crashed on
// NVIDIA's OpenCL, whose released queue the guided sampler's destructor then used
// (docs/guiding.md, "The renderer on a GPU").
TEST(ClRuntimeDeathTest, DestroyedBeforeItsUsersStopsWithAMessage) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  EXPECT_DEATH(
      {
        auto runtime = std::make_unique<ClRuntime>();
        Guider guider(*runtime, 8, 4);
        runtime.reset();
      },
      "still use it");
  auto runtime = std::make_unique<ClRuntime>();
  {
    Guider guider(*runtime, 8, 4);
    EXPECT_EQ(runtime->users(), 1);
  }
  EXPECT_EQ(runtime->users(), 0);
}

// The CPU device's worker threads are asked to stay one per core, unless the user's environment
// already decides (docs/design.md, "CPU devices' worker threads pinned"). Only the variable is
// checked here: PoCL reads it once per process, and what it changes is time, which the
// benchmarks measure.
TEST(CpuDeviceThreads, PinnedUnlessTheEnvironmentSaysOtherwise) {
  {
    test::ScopedEnv unset("POCL_AFFINITY", std::nullopt);
    EXPECT_TRUE(request_pinned_cpu_device_threads());
    ASSERT_NE(std::getenv("POCL_AFFINITY"), nullptr);
    EXPECT_STREQ(std::getenv("POCL_AFFINITY"), "1");
    EXPECT_FALSE(request_pinned_cpu_device_threads());  // set now: left as it is
  }
  for (const char* users : {"0", "1"}) {
    test::ScopedEnv set("POCL_AFFINITY", std::string(users));
    EXPECT_FALSE(request_pinned_cpu_device_threads());
    EXPECT_STREQ(std::getenv("POCL_AFFINITY"), users);
  }
}

}  // namespace
}  // namespace rtpg
