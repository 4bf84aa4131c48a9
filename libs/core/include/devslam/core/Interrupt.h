#pragma once
/// Ctrl-C for long jobs: stop after the current step and keep what was done.
///
/// After installStopHandler(), the first SIGINT or SIGTERM only records the signal and says
/// on stderr that the job is finishing; the job polls stopSignal() between its steps (a frame,
/// a run) and ends as it would at the end of its input, writing its results, then exits with
/// stopExitCode(). A second signal ends the program at once (the default action).
///
///   core::installStopHandler("devslam-run");
///   while (more() && !core::stopSignal()) step();
///   ...write results...
///   if (const int sig = core::stopSignal()) return core::stopExitCode(sig);

#include <string>

namespace devslam::core {

/// Installs the handler for SIGINT and SIGTERM, except for one ignored at start (a background
/// job's SIGINT); `program` prefixes its message (kept as a pointer: pass a string literal).
void installStopHandler(const char* program);
/// 0 while no stop was asked for, else the signal's number.
[[nodiscard]] int stopSignal();
/// "SIGINT", "SIGTERM", or "signal N".
[[nodiscard]] std::string signalName(int sig);
/// The shell's exit status for a program ended by `sig`: 128 + sig (130 for Ctrl-C).
[[nodiscard]] constexpr int stopExitCode(int sig) {
    return 128 + sig;
}
/// Whether a child's std::system status says it was stopped by SIGINT or SIGTERM: killed by
/// it, or exited with stopExitCode (a child that finished its step first).
[[nodiscard]] bool endedByStopSignal(int system_status);
/// For tests: forget a recorded signal (the handler stays installed as it is).
void clearStopSignal();

}  // namespace devslam::core
