// Files written by scene tests: a fresh folder per test, file writing and the check that a
// loader refuses bad input with an InputError naming what is wrong.
#pragma once

#include <gtest/gtest.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <functional>
#include <initializer_list>
#include <string>
#include <vector>

#include <unistd.h>

#include "rtpg/errors.h"

namespace rtpg::test {

namespace fs = std::filesystem;

// A fresh folder per test, removed afterwards.
class TempDir {
 public:
  TempDir() {
    static std::atomic<int> counter{0};
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ =
        fs::temp_directory_path() / ("rtpg_scene_" + std::string(info ? info->name() : "x") + "_" +
                                     std::to_string(::getpid()) + "_" + std::to_string(counter++));
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  std::string operator/(const std::string& name) const { return (path_ / name).string(); }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

inline void write_file(const std::string& path, const std::string& content) {
  fs::create_directories(fs::path(path).parent_path());
  std::ofstream out(path, std::ios::binary);
  out << content;
  ASSERT_TRUE(out.good()) << path;
}

// Runs `f`, expects an InputError whose message contains every one of `parts`; returns the
// message (empty when none was thrown), for checks of its form.
inline std::string expect_input_error(const std::function<void()>& f,
                                      const std::vector<std::string>& parts) {
  try {
    f();
    ADD_FAILURE() << "no InputError thrown";
  } catch (const InputError& e) {
    const std::string message = e.what();
    for (const std::string& part : parts)
      EXPECT_NE(message.find(part), std::string::npos)
          << "message \"" << message << "\" lacks \"" << part << "\"";
    return message;
  }
  return {};
}

inline std::string expect_input_error(const std::function<void()>& f,
                                      std::initializer_list<std::string> parts) {
  return expect_input_error(f, std::vector<std::string>(parts));
}

}  // namespace rtpg::test
