#pragma once
// Scratch paths for tests. Each carries the process id: two test runs on one machine (a CI
// run beside a local ctest) must never share, or delete, each other's files.
//
//   const auto dir = devslam::test::scratchPath("devslam_eval_report");  // /tmp/..._<pid>
//   devslam::test::TempDir d("devslam_io_");  // per GoogleTest test, removed afterwards
//   std::ofstream(d.str("a.ini")) << "...";
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>

#include <unistd.h>

namespace devslam::test {

/// `<system temp folder>/<name>_<pid>` (nothing is created).
inline std::filesystem::path scratchPath(const std::string& name) {
    return std::filesystem::temp_directory_path() / (name + "_" + std::to_string(::getpid()));
}

/// A fresh scratch folder for the running test (`<prefix><suite>_<test>_<pid>`), removed
/// when it goes out of scope.
class TempDir {
  public:
    explicit TempDir(const std::string& prefix) {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        std::string name = prefix + info->test_suite_name() + "_" + info->name();
        std::replace(name.begin(), name.end(), '/', '_');  // parameterised: "Layouts/Rawlog..."
        path_ = scratchPath(name);
        std::filesystem::remove_all(path_);
        std::filesystem::create_directories(path_);
    }
    ~TempDir() { std::filesystem::remove_all(path_); }
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;
    [[nodiscard]] std::string str(const std::string& sub = {}) const {
        return sub.empty() ? path_.string() : (path_ / sub).string();
    }

  private:
    std::filesystem::path path_;
};

}  // namespace devslam::test
