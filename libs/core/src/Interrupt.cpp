#include <devslam/core/Interrupt.h>

#include <pthread.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>
#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <iterator>

namespace devslam::core {
namespace {
// Read by other threads (the bench's render workers): an atomic, lock-free and so usable in
// a signal handler.
std::atomic<int> g_signal{0};
static_assert(std::atomic<int>::is_always_lock_free);
const char* g_program = "";
std::size_t g_program_len = 0;
constexpr int kStopSignals[] = {SIGINT, SIGTERM};
bool g_installed[std::size(kStopSignals)] = {};  // per kStopSignals: the handler was installed

/// Sets the signals the handler was installed for back to the default action (a signal
/// ignored at start stays ignored). Async-signal-safe.
void resetInstalled() {
    struct sigaction dfl {};
    dfl.sa_handler = SIG_DFL;
    sigemptyset(&dfl.sa_mask);
    for (std::size_t k = 0; k < std::size(kStopSignals); ++k)
        if (g_installed[k]) sigaction(kStopSignals[k], &dfl, nullptr);
}

extern "C" void onStopSignal(int sig) {
    // Only async-signal-safe calls here (sigaction, write), nothing that allocates or locks.
    // The next signal of either kind takes the default action: the program ends at once.
    resetInstalled();
    int none = 0;
    g_signal.compare_exchange_strong(none, sig);
    constexpr char msg[] =
        ": stopping after the current step, keeping what is done (again to quit at once)\n";
    ssize_t ignored = ::write(STDERR_FILENO, "\n", 1);
    ignored = ::write(STDERR_FILENO, g_program, g_program_len);
    ignored = ::write(STDERR_FILENO, msg, sizeof msg - 1);
    (void)ignored;
}
}  // namespace

void ignoreFileSizeSignal() {
    // Past a file-size limit (ulimit -f) a write fails with EFBIG, which every writer reports,
    // keeping the other outputs; SIGXFSZ's default action killed the program first, losing
    // the summary (devslam-run left a cut map.ply.part and printed nothing).
    std::signal(SIGXFSZ, SIG_IGN);
}

void installStopHandler(const char* program) {
    ignoreFileSizeSignal();
    g_program = program;
    g_program_len = std::strlen(program);
    struct sigaction sa {};
    sa.sa_handler = onStopSignal;
    sigemptyset(&sa.sa_mask);
    for (const int s : kStopSignals) sigaddset(&sa.sa_mask, s);
    // SA_RESTART: reads and writes in progress go on instead of failing with EINTR.
    sa.sa_flags = SA_RESTART;
    for (std::size_t k = 0; k < std::size(kStopSignals); ++k) {
        // A signal ignored at start stays ignored: a shell starts background jobs with SIGINT
        // ignored, so that Ctrl-C at the terminal is not theirs.
        struct sigaction old {};
        if (sigaction(kStopSignals[k], nullptr, &old) == 0 && old.sa_handler == SIG_IGN) continue;
        g_installed[k] = true;  // before the handler can run
        g_installed[k] = sigaction(kStopSignals[k], &sa, nullptr) == 0;
    }
}

int stopSignal() {
    return g_signal;
}

void clearStopSignal() {
    g_signal = 0;
}

std::string signalName(int sig) {
    switch (sig) {
        case SIGINT:
            return "SIGINT";
        case SIGTERM:
            return "SIGTERM";
        default:
            return "signal " + std::to_string(sig);
    }
}

void exitBySignal(int sig) {
    std::cout.flush();
    std::cerr.flush();
    std::fflush(nullptr);
    std::signal(sig, SIG_DFL);
    sigset_t set;
    sigemptyset(&set);
    sigaddset(&set, sig);
    pthread_sigmask(SIG_UNBLOCK, &set, nullptr);
    std::raise(sig);
    std::_Exit(128 + sig);  // not reached for SIGINT and SIGTERM
}

int stopSignalOf(int status) {
    if (status == -1) return 0;
    if (WIFSIGNALED(status))
        return WTERMSIG(status) == SIGINT || WTERMSIG(status) == SIGTERM ? WTERMSIG(status) : 0;
    if (!WIFEXITED(status)) return 0;
    const int code = WEXITSTATUS(status);
    return code == 128 + SIGINT || code == 128 + SIGTERM ? code - 128 : 0;
}

int runCommand(const std::string& cmd) {
    const std::string line = "exec " + cmd;
    // SIGINT and SIGTERM are blocked across the fork: one that comes in between must not run
    // this program's handler in the child (and be used up there); the parent gets it when
    // it unblocks them, the child (which starts with none pending) from the terminal.
    sigset_t stop, old;
    sigemptyset(&stop);
    for (const int s : kStopSignals) sigaddset(&stop, s);
    pthread_sigmask(SIG_BLOCK, &stop, &old);
    const pid_t parent = getpid();
    const pid_t pid = fork();
    if (pid == 0) {
        // Only async-signal-safe calls in the child of a threaded program until exec. It gets
        // the dispositions the program started with (the default, or ignored); and should
        // the program die without waiting for it (a second Ctrl-C), it dies too instead of
        // running on unseen beside a resumed command.
        resetInstalled();
        prctl(PR_SET_PDEATHSIG, SIGKILL);
        if (getppid() != parent) _exit(127);  // the program died before prctl
        pthread_sigmask(SIG_SETMASK, &old, nullptr);
        execl("/bin/sh", "sh", "-c", line.c_str(), static_cast<char*>(nullptr));
        _exit(127);
    }
    pthread_sigmask(SIG_SETMASK, &old, nullptr);
    if (pid < 0) return -1;
    int status = 0;
    while (waitpid(pid, &status, 0) < 0)
        if (errno != EINTR) return -1;
    return status;
}

}  // namespace devslam::core
