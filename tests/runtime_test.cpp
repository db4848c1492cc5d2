// Unit tests of the OpenCL runtime layer: error names and messages, device choice, device
// lookup, the program cache and the Runtime object.
#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <unistd.h>

#include <gtest/gtest.h>

#include "fogcl/fogcl.h"
#include "test_support.h"

namespace fogcl {
namespace {

#define EXPECT_MSG_HAS(msg, part) \
  EXPECT_NE((msg).find(part), std::string::npos) << "message: '" << (msg) << "' lacks '" << (part) << "'"

// Sets (or clears, for nullopt) FOGCL_DEVICE for its lifetime and restores the previous value.
class EnvGuard {
 public:
  explicit EnvGuard(const std::optional<std::string>& value) {
    if (const char* old = std::getenv("FOGCL_DEVICE")) old_ = std::string(old);
    if (value)
      setenv("FOGCL_DEVICE", value->c_str(), 1);
    else
      unsetenv("FOGCL_DEVICE");
  }
  ~EnvGuard() {
    if (old_)
      setenv("FOGCL_DEVICE", old_->c_str(), 1);
    else
      unsetenv("FOGCL_DEVICE");
  }
  EnvGuard(const EnvGuard&) = delete;
  EnvGuard& operator=(const EnvGuard&) = delete;

 private:
  std::optional<std::string> old_;
};

// ---------------------------------------------------------------------------------------------
// Error names and ClError

TEST(RuntimeTest, ClErrorNames) {
  EXPECT_STREQ(cl_error_name(0), "CL_SUCCESS");
  EXPECT_STREQ(cl_error_name(-30), "CL_INVALID_VALUE");
  EXPECT_STREQ(cl_error_name(-11), "CL_BUILD_PROGRAM_FAILURE");
  EXPECT_STREQ(cl_error_name(-5), "CL_OUT_OF_RESOURCES");
  EXPECT_STREQ(cl_error_name(-1), "CL_DEVICE_NOT_FOUND");
  EXPECT_STREQ(cl_error_name(-46), "CL_INVALID_KERNEL_NAME");
  EXPECT_STREQ(cl_error_name(-54), "CL_INVALID_WORK_GROUP_SIZE");
  EXPECT_STREQ(cl_error_name(-1001), "CL_PLATFORM_NOT_FOUND_KHR");
  EXPECT_STREQ(cl_error_name(-12345), "CL_UNKNOWN_ERROR");
  EXPECT_STREQ(cl_error_name(1), "CL_UNKNOWN_ERROR");
}

TEST(RuntimeTest, ClErrorMessage) {
  const ClError e("clBuildProgram", -11, "kernel.cl:3:5: error: expected ';'");
  const std::string what = e.what();
  EXPECT_MSG_HAS(what, "clBuildProgram");
  EXPECT_MSG_HAS(what, "CL_BUILD_PROGRAM_FAILURE");
  EXPECT_MSG_HAS(what, "(-11)");
  EXPECT_MSG_HAS(what, "kernel.cl:3:5: error: expected ';'");
  EXPECT_EQ(e.call(), "clBuildProgram");
  EXPECT_EQ(e.code(), -11);
  EXPECT_STREQ(e.code_name(), "CL_BUILD_PROGRAM_FAILURE");
  EXPECT_EQ(e.build_log(), "kernel.cl:3:5: error: expected ';'");
  // A ClError is a fogcl::Error.
  const Error& base = e;
  EXPECT_EQ(std::string(base.what()), what);

  const ClError plain("clEnqueueNDRangeKernel", -5);
  const std::string w2 = plain.what();
  EXPECT_MSG_HAS(w2, "clEnqueueNDRangeKernel");
  EXPECT_MSG_HAS(w2, "CL_OUT_OF_RESOURCES");
  EXPECT_MSG_HAS(w2, "(-5)");
  EXPECT_EQ(w2.find("build log"), std::string::npos) << w2;
  EXPECT_TRUE(plain.build_log().empty());

  const ClError unknown("clFoo", -12345);
  EXPECT_MSG_HAS(std::string(unknown.what()), "CL_UNKNOWN_ERROR (-12345)");
}

TEST(RuntimeTest, WithClErrorsTranslates) {
  try {
    with_cl_errors([]() -> int { throw cl::Error(CL_INVALID_VALUE, "clSomething"); });
    ADD_FAILURE() << "nothing thrown";
  } catch (const ClError& e) {
    EXPECT_EQ(e.code(), CL_INVALID_VALUE);
    EXPECT_EQ(e.call(), "clSomething");
    EXPECT_MSG_HAS(std::string(e.what()), "CL_INVALID_VALUE (-30)");
  }
  EXPECT_EQ(with_cl_errors([] { return 7; }), 7);
}

// ---------------------------------------------------------------------------------------------
// Device choice

TEST(RuntimeTest, ResolveDeviceChoiceExplicitWins) {
  {
    EnvGuard env(std::string("gpu"));
    EXPECT_EQ(resolve_device_choice("my-device"), "my-device");
    EXPECT_EQ(resolve_device_choice(), "gpu");
    EXPECT_EQ(resolve_device_choice(""), "gpu");
  }
  {
    EnvGuard env(std::nullopt);
    EXPECT_EQ(resolve_device_choice(), "cpu");
    EXPECT_EQ(resolve_device_choice("gpu"), "gpu");
  }
  {
    EnvGuard env(std::string(""));  // set but empty: as if unset
    EXPECT_EQ(resolve_device_choice(), "cpu");
  }
  {
    EnvGuard env(std::string("NVIDIA"));
    EXPECT_EQ(resolve_device_choice(), "NVIDIA");
  }
}

TEST(RuntimeTest, EnvGuardRestores) {
  const char* before = std::getenv("FOGCL_DEVICE");
  const std::optional<std::string> saved = before ? std::optional<std::string>(before) : std::nullopt;
  { EnvGuard env(std::string("something-else")); }
  const char* after = std::getenv("FOGCL_DEVICE");
  EXPECT_EQ(after != nullptr, saved.has_value());
  if (after && saved) {
    EXPECT_EQ(std::string(after), *saved);
  }
}

TEST(RuntimeTest, FindDeviceUnknownListsAvailable) {
  FOGCL_REQUIRE_DEVICE();
  const std::string name = device_name(test::runtime()->device());
  try {
    find_device("no-such-device-xyz");
    ADD_FAILURE() << "no exception for an unknown device";
  } catch (const ClError& e) {
    ADD_FAILURE() << "expected a plain fogcl::Error, got ClError " << e.what();
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_MSG_HAS(msg, "no-such-device-xyz");
    EXPECT_MSG_HAS(msg, "available");
    EXPECT_MSG_HAS(msg, name);
  }
}

TEST(RuntimeTest, FindDeviceByNameIsCaseInsensitive) {
  FOGCL_REQUIRE_DEVICE();
  const cl_device_id want = test::runtime()->device();
  std::string name = device_name(want);
  for (char& c : name) c = char(std::toupper(static_cast<unsigned char>(c)));
  const cl_device_id got = find_device(name);
  EXPECT_EQ(device_name(got), device_name(want));
}

TEST(RuntimeTest, FindDeviceCpu) {
  FOGCL_REQUIRE_DEVICE();
  if (!test::runtime()->is_cpu()) GTEST_SKIP() << "the test device is not a CPU device";
  const cl_device_id d = find_device("cpu");
  EXPECT_TRUE(device_is_cpu(d));
  EXPECT_TRUE(device_is_cpu(find_device("CPU")));
}

// ---------------------------------------------------------------------------------------------
// Runtime

TEST(RuntimeTest, DescriptionNamesTheDevice) {
  FOGCL_REQUIRE_DEVICE();
  const Runtime& rt = *test::runtime();
  const std::string name = device_name(rt.device());
  const std::string desc = rt.description();
  EXPECT_MSG_HAS(desc, name);
  const std::string platform = cl::Platform(wrap(rt.device()).getInfo<CL_DEVICE_PLATFORM>()).getInfo<CL_PLATFORM_NAME>();
  EXPECT_MSG_HAS(desc, platform);
  std::printf("[ info ] device: %s\n", desc.c_str());
  // The integration constructor describes the same device.
  const Runtime wrapped(rt.context(), rt.device(), rt.queue());
  EXPECT_EQ(wrapped.description(), desc);
  EXPECT_EQ(wrapped.is_cpu(), rt.is_cpu());
}

TEST(RuntimeTest, DefaultDeviceIsCpu) {
  FOGCL_REQUIRE_DEVICE();
  if (resolve_device_choice() != "cpu")
    GTEST_SKIP() << "FOGCL_DEVICE=" << resolve_device_choice() << " picks another device";
  EXPECT_TRUE(test::runtime()->is_cpu()) << test::runtime()->description();
  EXPECT_TRUE(device_is_cpu(test::runtime()->device()));
  const Runtime cpu("cpu");
  EXPECT_TRUE(cpu.is_cpu());
  EXPECT_EQ(device_name(cpu.device()), device_name(test::runtime()->device()));
}

TEST(RuntimeTest, UnknownDeviceRuntimeThrows) {
  FOGCL_REQUIRE_DEVICE();
  EXPECT_THROW(Runtime("no-such-device-xyz"), Error);
}

TEST(RuntimeTest, DeviceOpenClCVersion) {
  FOGCL_REQUIRE_DEVICE();
  const std::string v = device_opencl_c_version(test::runtime()->device());
  EXPECT_EQ(v.rfind("OpenCL C ", 0), 0u) << v;
}

// ---------------------------------------------------------------------------------------------
// ProgramCache

const char* kGoodSource = R"CL(
__kernel void scale(__global float* a, float s) { a[get_global_id(0)] *= s; }
)CL";

const char* kBadSource = R"CL(
__kernel void scale(__global float* a, float s) { a[get_global_id(0)] *= s }
)CL";

TEST(ProgramCacheTest, SyntaxErrorThrowsWithBuildLog) {
  FOGCL_REQUIRE_DEVICE();
  ProgramCache cache(test::runtime()->context());
  try {
    cache.get(test::runtime()->device(), "bad.cl", kBadSource, "-cl-std=CL1.2");
    ADD_FAILURE() << "a syntax error built";
  } catch (const ClError& e) {
    EXPECT_EQ(e.code(), CL_BUILD_PROGRAM_FAILURE);
    EXPECT_EQ(e.code(), -11);
    EXPECT_STREQ(e.code_name(), "CL_BUILD_PROGRAM_FAILURE");
    EXPECT_FALSE(e.build_log().empty());
    EXPECT_MSG_HAS(e.build_log(), "error");
    const std::string what = e.what();
    EXPECT_MSG_HAS(what, "CL_BUILD_PROGRAM_FAILURE");
    EXPECT_MSG_HAS(what, "bad.cl");
    EXPECT_MSG_HAS(what, e.build_log());
    std::printf("[ info ] build failure message:\n%s\n", what.c_str());
  }
  EXPECT_EQ(cache.builds(), 0u) << "a failed build is not a cached program";
  // A failed build is not cached: asking again fails again.
  EXPECT_THROW(cache.get(test::runtime()->device(), "bad.cl", kBadSource, "-cl-std=CL1.2"), ClError);
}

TEST(ProgramCacheTest, CachesByDeviceSourceNameAndOptions) {
  FOGCL_REQUIRE_DEVICE();
  const cl_device_id device = test::runtime()->device();
  ProgramCache cache(test::runtime()->context());
  EXPECT_EQ(cache.builds(), 0u);
  EXPECT_EQ(cache.context(), test::runtime()->context());
  EXPECT_EQ(cache.find(device, "good.cl", "-cl-std=CL1.2"), nullptr) << "find() before any build";

  const cl_program p1 = cache.get(device, "good.cl", kGoodSource, "-cl-std=CL1.2");
  EXPECT_EQ(cache.builds(), 1u);
  const cl_program p2 = cache.get(device, "good.cl", kGoodSource, "-cl-std=CL1.2");
  EXPECT_EQ(cache.builds(), 1u) << "the same key must not build again";
  EXPECT_EQ(p1, p2) << "the same key must return the cached program";

  const cl_program p3 = cache.get(device, "good.cl", kGoodSource, "-cl-std=CL1.2 -D UNUSED=1");
  EXPECT_EQ(cache.builds(), 2u) << "different options must build";
  EXPECT_NE(p3, p1);
  const cl_program p4 = cache.get(device, "other.cl", kGoodSource, "-cl-std=CL1.2");
  EXPECT_EQ(cache.builds(), 3u) << "a different source name must build";
  EXPECT_NE(p4, p1);
  EXPECT_EQ(cache.find(device, "good.cl", "-cl-std=CL1.2"), p1) << "find() returns the built program";
  EXPECT_EQ(cache.builds(), 3u) << "find() never builds";

  cache.get(device, "good.cl", kGoodSource, "-cl-std=CL1.2 -D UNUSED=1");
  cache.get(device, "other.cl", kGoodSource, "-cl-std=CL1.2");
  EXPECT_EQ(cache.builds(), 3u);

  // The cached program is usable.
  cl::Kernel kernel(wrap(p2), "scale");
  cl::Buffer buf(wrap(test::runtime()->context()), CL_MEM_READ_WRITE, 4 * sizeof(float));
  const float in[4] = {1, 2, 3, -4};
  const cl::CommandQueue q = wrap(test::runtime()->queue());
  q.enqueueWriteBuffer(buf, CL_TRUE, 0, sizeof in, in);
  kernel.setArg(0, buf);
  kernel.setArg(1, 2.5f);
  q.enqueueNDRangeKernel(kernel, cl::NullRange, cl::NDRange(4));
  float out[4] = {};
  q.enqueueReadBuffer(buf, CL_TRUE, 0, sizeof out, out);
  for (int i = 0; i < 4; ++i) EXPECT_EQ(out[i], in[i] * 2.5f) << i;
}

// FOGCL_PROGRAM_BINARIES=DIR writes each program built (the driver's binary) and its options to
// DIR; a program taken from the cache is not written again, and without the variable nothing is.
TEST(ProgramCacheTest, WritesBinariesWhereAsked) {
  FOGCL_REQUIRE_DEVICE();
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("fogcl-binaries-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const auto files = [&] {
    std::vector<fs::path> out;
    for (const auto& e : fs::directory_iterator(dir)) out.push_back(e.path());
    std::sort(out.begin(), out.end());
    return out;
  };
  const cl_device_id device = test::runtime()->device();
  ProgramCache cache(test::runtime()->context());
  cache.get(device, "unwritten.cl", kGoodSource, "-cl-std=CL1.2");
  setenv("FOGCL_PROGRAM_BINARIES", dir.c_str(), 1);
  cache.get(device, "unwritten.cl", kGoodSource, "-cl-std=CL1.2");  // cached: not built again
  EXPECT_TRUE(files().empty()) << "a cached program was written";
  cache.get(device, "good.cl", kGoodSource, "-cl-std=CL1.2 -D UNUSED=7");
  unsetenv("FOGCL_PROGRAM_BINARIES");
  cache.get(device, "good.cl", kGoodSource, "-cl-std=CL1.2 -D UNUSED=8");
  const std::vector<fs::path> written = files();
  ASSERT_EQ(written.size(), 2u) << "one .bin and one .options for the one program built with the variable set";
  EXPECT_EQ(written[0].extension(), ".bin");
  EXPECT_EQ(written[1].extension(), ".options");
  EXPECT_EQ(written[0].stem(), written[1].stem());
  EXPECT_EQ(written[0].filename().string().rfind("good.cl-", 0), 0u) << written[0];
  EXPECT_GT(fs::file_size(written[0]), 0u);
  std::ifstream options(written[1]);
  std::string line;
  std::getline(options, line);
  EXPECT_EQ(line, "-cl-std=CL1.2 -D UNUSED=7");
  fs::remove_all(dir);
}

TEST(ProgramCacheTest, InvalidOptionsThrowClError) {
  FOGCL_REQUIRE_DEVICE();
  ProgramCache cache(test::runtime()->context());
  try {
    cache.get(test::runtime()->device(), "good.cl", kGoodSource, "-cl-no-such-option-xyz");
    ADD_FAILURE() << "an invalid build option was accepted";
  } catch (const ClError& e) {
    EXPECT_TRUE(e.code() == CL_INVALID_BUILD_OPTIONS || e.code() == CL_BUILD_PROGRAM_FAILURE)
        << e.what();
    EXPECT_MSG_HAS(std::string(e.what()), "-cl-no-such-option-xyz");
  }
  EXPECT_EQ(cache.builds(), 0u);
}

}  // namespace
}  // namespace fogcl

namespace fogcl {
namespace {
// Several threads asking one cache for the same program at once: one build, one program; other
// keys asked meanwhile are built too (a build does not hold the cache's lock).
TEST(ProgramCacheTest, ThreadsShareOneBuildPerKey) {
  FOGCL_REQUIRE_DEVICE();
  const cl_device_id device = test::runtime()->device();
  auto cache = std::make_shared<ProgramCache>(test::runtime()->context());
  constexpr int kThreads = 6;
  std::vector<cl_program> got(kThreads, nullptr);
  std::vector<std::thread> threads;
  for (int i = 0; i < kThreads; ++i)
    threads.emplace_back([&, i] {
      // Threads 0..3 want the same program; 4 and 5 another one each.
      const std::string options = "-cl-std=CL1.2 -D THREAD_KEY=" + std::to_string(i < 4 ? 0 : i);
      got[i] = cache->get(device, "good.cl", kGoodSource, options);
    });
  for (auto& t : threads) t.join();
  std::printf("[ info ] %d threads, %zu builds\n", kThreads, cache->builds());
  EXPECT_EQ(cache->builds(), 3u);
  for (int i = 1; i < 4; ++i) EXPECT_EQ(got[i], got[0]) << "thread " << i;
  EXPECT_NE(got[4], got[0]);
  EXPECT_NE(got[5], got[4]);
}
}  // namespace
}  // namespace fogcl
