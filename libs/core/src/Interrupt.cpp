#include <devslam/core/Interrupt.h>

#include <sys/wait.h>
#include <unistd.h>
#include <csignal>
#include <cstring>

namespace devslam::core {
namespace {
volatile std::sig_atomic_t g_signal = 0;
const char* g_program = "";
std::size_t g_program_len = 0;

extern "C" void onStopSignal(int sig) {
    g_signal = sig;
    // Only async-signal-safe calls here: write(2), nothing that allocates or locks.
    constexpr char msg[] =
        ": stopping after the current step, keeping what is done (again to quit at once)\n";
    ssize_t ignored = ::write(STDERR_FILENO, "\n", 1);
    ignored = ::write(STDERR_FILENO, g_program, g_program_len);
    ignored = ::write(STDERR_FILENO, msg, sizeof msg - 1);
    (void)ignored;
}
}  // namespace

void installStopHandler(const char* program) {
    g_program = program;
    g_program_len = std::strlen(program);
    struct sigaction sa {};
    sa.sa_handler = onStopSignal;
    sigemptyset(&sa.sa_mask);
    // SA_RESETHAND: the second signal takes the default action (the program ends at once);
    // SA_RESTART: reads and writes in progress go on instead of failing with EINTR.
    sa.sa_flags = SA_RESETHAND | SA_RESTART;
    for (const int sig : {SIGINT, SIGTERM}) {
        // A signal ignored at start stays ignored: a shell starts background jobs with SIGINT
        // ignored, so that Ctrl-C at the terminal is not theirs.
        struct sigaction old {};
        if (sigaction(sig, nullptr, &old) == 0 && old.sa_handler == SIG_IGN) continue;
        sigaction(sig, &sa, nullptr);
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

bool endedByStopSignal(int status) {
    if (status == -1) return false;
    if (WIFSIGNALED(status)) return WTERMSIG(status) == SIGINT || WTERMSIG(status) == SIGTERM;
    return WIFEXITED(status) && (WEXITSTATUS(status) == stopExitCode(SIGINT) ||
                                 WEXITSTATUS(status) == stopExitCode(SIGTERM));
}

}  // namespace devslam::core
