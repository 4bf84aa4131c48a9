#pragma once
// Runs one of the built apps (DEVSLAM_BIN_DIR) as a user would, for the apps' smoke tests.
//
//   const auto r = devslam::test::runApp("devslam-nav", "--map m.gridmap --to 1,0");
//   EXPECT_EQ(r.rc, 0) << r.out;   // r.out: stdout and stderr together
#include <array>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>

#include <sys/wait.h>
#include <unistd.h>

namespace devslam::test {

struct CommandResult {
    int rc = -1;      ///< exit status; -1 when it could not run or did not exit
    std::string out;  ///< stdout and stderr
    bool signalled = false;  ///< signalAppWhen: the signal was sent (it had not ended before)
};

/// The shell command `cmd`: what it writes on stdout, and how it exited.
inline CommandResult runShell(const std::string& cmd) {
    CommandResult r;
    FILE* p = popen(cmd.c_str(), "r");
    if (!p) return r;
    std::array<char, 4096> buf{};
    while (fgets(buf.data(), buf.size(), p)) r.out += buf.data();
    const int st = pclose(p);
    r.rc = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
    return r;
}

/// `<DEVSLAM_BIN_DIR>/<app> <args> <redirect>` through the shell (quote arguments with
/// spaces); its stderr, and its stdout where `redirect` does not send it elsewhere, are read.
inline CommandResult runAppRedirected(const std::string& app, const std::string& args,
                                      const std::string& redirect) {
    return runShell(std::string(DEVSLAM_BIN_DIR) + "/" + app + " " + args + " 2>&1 " + redirect);
}

/// `<DEVSLAM_BIN_DIR>/<app> <args>` through the shell (quote arguments with spaces).
inline CommandResult runApp(const std::string& app, const std::string& args) {
    return runAppRedirected(app, args, "");
}

/// `<app> <args>` with no file it writes allowed past `bytes` (RLIMIT_FSIZE, with SIGXFSZ
/// ignored, so the write past it fails with EFBIG, "File too large"): a disk that fills, where
/// CI cannot mount a small one. r.out: its stdout and stderr. `ignore_xfsz` false leaves the
/// signal's default action (the process is killed) to a program that ignores it itself
/// (core::installStopHandler does).
inline CommandResult runAppWithFileLimit(const std::string& app, const std::string& args,
                                         unsigned long bytes, bool ignore_xfsz = true) {
    return runShell(std::string(ignore_xfsz ? "trap '' XFSZ; " : "trap - XFSZ; ") +
                    "exec prlimit --fsize=" + std::to_string(bytes) + " " +
                    std::string(DEVSLAM_BIN_DIR) + "/" + app + " " + args + " 2>&1");
}

/// `<app> <args>` with its standard output on /dev/full, as behind a '>' on a full disk: r.out
/// is its stderr alone.
inline CommandResult runAppOntoFullDisk(const std::string& app, const std::string& args) {
    return runAppRedirected(app, args, "> /dev/full");
}

/// Ctrl-C at a terminal, simulated: runs `<app> <args>` in a process group of its own with
/// its output in `log`, and once the output holds `when` (or after `timeout_s`) sends `sig` to
/// the whole group (the app and the programs it runs), or with `group` false to the app
/// alone. Returns its output and its status as a shell gives it (128 + N when killed by
/// signal N) once it has ended.
inline CommandResult signalAppWhen(const std::string& app, const std::string& args,
                                   const std::string& when, int sig, const std::string& log,
                                   bool group = true, double timeout_s = 120) {
    const std::string cmd =
        "exec " + std::string(DEVSLAM_BIN_DIR) + "/" + app + " " + args + " > '" + log + "' 2>&1";
    const auto output = [&] {
        std::ifstream in(log);
        std::stringstream ss;
        ss << in.rdbuf();
        return ss.str();
    };
    CommandResult r;
    const pid_t pid = fork();
    if (pid < 0) return r;
    if (pid == 0) {
        setpgid(0, 0);
        execl("/bin/sh", "sh", "-c", cmd.c_str(), static_cast<char*>(nullptr));
        _exit(127);
    }
    setpgid(pid, pid);  // also here, so the group exists before the signal
    const auto t0 = std::chrono::steady_clock::now();
    int st = 0;
    bool ended = false;  // before the signal (then it is not sent)
    while (output().find(when) == std::string::npos &&
           std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() <
               timeout_s &&
           !(ended = waitpid(pid, &st, WNOHANG) == pid))
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
    if (!ended) {
        r.signalled = kill(group ? -pid : pid, sig) == 0;
        ended = waitpid(pid, &st, 0) == pid;
    }
    if (ended) r.rc = WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
    r.out = output();
    return r;
}

}  // namespace devslam::test
