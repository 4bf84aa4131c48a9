#pragma once
/// Ctrl-C for long jobs: stop after the current step and keep what was done.
///
/// After installStopHandler(), the first SIGINT or SIGTERM only records the signal and says
/// on stderr that the job is finishing; the job polls stopSignal() between its steps (a frame,
/// a run) and ends as it would at the end of its input, writing its results. Then it ends by
/// the signal itself (exitBySignal), so that a shell script running it stops too (bash goes on
/// after a child that merely exits 130). A second signal, of either kind, ends the program at
/// once (the default action).
///
///   core::installStopHandler("devslam-run");
///   while (more() && !core::stopSignal()) step();
///   ...write results...
///   if (const int sig = core::stopSignal()) core::exitBySignal(sig);

#include <string>

namespace devslam::core {

/// Installs the handler for SIGINT and SIGTERM, except for one ignored at start (a background
/// job's SIGINT); `program` prefixes its message (kept as a pointer: pass a string literal).
/// Also ignores SIGXFSZ: past a file-size limit a write fails (EFBIG) and is reported like a
/// full disk, instead of the process being killed (the programs runCommand starts inherit it).
void installStopHandler(const char* program);
/// Only the SIGXFSZ part of installStopHandler, for programs without a stop handler (their
/// Ctrl-C ends them at once): past a file-size limit their writes fail and are reported.
void ignoreFileSizeSignal();
/// 0 while no stop was asked for, else the first signal's number.
[[nodiscard]] int stopSignal();
/// "SIGINT", "SIGTERM", or "signal N".
[[nodiscard]] std::string signalName(int sig);
/// Flushes stdout and stderr and ends the program by `sig` with its default action (the
/// shell then reports 128 + sig: 130 for Ctrl-C). Call it after every file is closed.
[[noreturn]] void exitBySignal(int sig);
/// The signal that stopped a child, from its exit status (waitpid's, std::system's): SIGINT
/// or SIGTERM when it was killed by it or exited with 128 + it, else 0.
[[nodiscard]] int stopSignalOf(int status);
/// Runs one command line through /bin/sh, which execs it (so a signal sent to it reaches the
/// program, not a shell that would die at once and orphan it), and waits for it; returns its
/// waitpid status, -1 when it could not start. Unlike std::system, the caller keeps its own
/// SIGINT handling meanwhile: a Ctrl-C reaches both, and a SIGINT sent to the caller alone
/// is its own to handle. The child starts with the signal dispositions the caller started
/// with, and is killed if the calling thread dies first (a second Ctrl-C ends the program),
/// so that no run goes on unseen. `cmd` is one simple command, redirections allowed.
[[nodiscard]] int runCommand(const std::string& cmd);
/// For tests: forget a recorded signal (the handlers are left as they are).
void clearStopSignal();

}  // namespace devslam::core
