#pragma once
// Runs one of the built apps (DEVSLAM_BIN_DIR) as a user would, for the apps' smoke tests.
//
//   const auto r = devslam::test::runApp("devslam-nav", "--map m.gridmap --to 1,0");
//   EXPECT_EQ(r.rc, 0) << r.out;   // r.out: stdout and stderr together
#include <array>
#include <cstdio>
#include <string>

#include <sys/wait.h>

namespace devslam::test {

struct CommandResult {
    int rc = -1;      ///< exit status; -1 when it could not run or did not exit
    std::string out;  ///< stdout and stderr
};

/// `<DEVSLAM_BIN_DIR>/<app> <args>` through the shell (quote arguments with spaces).
inline CommandResult runApp(const std::string& app, const std::string& args) {
    const std::string cmd = std::string(DEVSLAM_BIN_DIR) + "/" + app + " " + args + " 2>&1";
    CommandResult r;
    FILE* p = popen(cmd.c_str(), "r");
    if (!p) return r;
    std::array<char, 4096> buf{};
    while (fgets(buf.data(), buf.size(), p)) r.out += buf.data();
    const int st = pclose(p);
    r.rc = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
    return r;
}

}  // namespace devslam::test
