// devslam-bench: the paper's comparison in one command. Runs devslam-run in the modes
// none / all_persons / dynamic on the sequences of a bench INI (synthetic ones rendered by
// devslam-synth when missing, each in the renders its `seeds` list, real TUM folders as
// they are), N repeats per render and mode, and writes
// Table 1 (RPE), Table 2 (ATE), Table 3 (FPS) and the filter's precision/recall against the
// renderer's person truth as Markdown + CSV, trajectory plots, and the `bench` section of
// docs/RESULTS.md.
//
//   devslam-bench                                   # config_ini/bench.ini
//   devslam-bench --config INI [--repeats N] [--max-frames N] [--out DIR] [--results FILE]
//                 [--render-jobs N]

#include <devslam/core/Config.h>
#include <devslam/core/Interrupt.h>
#include <devslam/core/Parse.h>
#include <devslam/core/Results.h>
#include <devslam/core/Stats.h>
#include <devslam/dynamic/DynamicObjectFilter.h>
#include <devslam/eval/MaskScore.h>
#include <devslam/io/RgbdReader.h>

#include "BenchConfig.h"
#include "RunJson.h"
#include "Targets.h"

#include <mrpt/config/CConfigFileMemory.h>

#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <ctime>
#include <limits>
#include <optional>

#include <sys/wait.h>
#include <unistd.h>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <iterator>
#include <map>
#include <mutex>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace fs = std::filesystem;
using namespace devslam;
using bench::Bench;
using bench::Input;
using bench::inputsOf;
using bench::loadBench;
using bench::readRun;
using bench::RunFigures;
using bench::runsMode;
using bench::Sequence;

namespace {

const std::string kRoot = DEVSLAM_SOURCE_DIR;

const char* kUsage =
    "usage: devslam-bench [--config INI] [--repeats N] [--max-frames N] [--out DIR]\n"
    "                     [--results FILE|none] [--bin DIR] [--reuse-runs] [--render-jobs N]\n"
    "       devslam-bench [--config INI] [--out DIR] --compare BEFORE\n"
    "--max-frames N: the first N frames of each sequence (0: whole sequences, also over the\n"
    "              INI's [bench] max_frames)\n"
    "--results none: write no RESULTS.md section (the tables and plots go to the output\n"
    "              folder only)\n"
    "--reuse-runs: keep the runs already in the output folder that this command would make\n"
    "              (resume a bench): a whole run.json, and a command.txt with this command\n"
    "              line and the same content of program, configs and input lists\n"
    "--compare BEFORE: renders and runs nothing; compares the runs in the output folder\n"
    "              (<out>/runs) with those of the same bench kept in the folder BEFORE (an\n"
    "              earlier <out>/runs, copied aside), render for render: ATE, keyframes,\n"
    "              landmarks and map size per sequence and mode, as a Markdown table\n"
    "--render-jobs N: renders made at once (default: [bench] render_jobs, else the CPU's\n"
    "              threads, at most 8); the SLAM runs, whose FPS is measured, always run one\n"
    "              at a time\n"
    "defaults: --config " DEVSLAM_SOURCE_DIR
    "/config_ini/bench.ini, repeats and out from the INI,\n"
    "          --results " DEVSLAM_SOURCE_DIR
    "/docs/RESULTS.md (section 'bench'), --bin: this program's folder\n";

std::string fmt(double v, int prec) {
    if (std::isnan(v)) return "n/a";
    char b[64];
    std::snprintf(b, sizeof b, "%.*f", prec, v);
    return b;
}

/// `s` as one word for /bin/sh (single quotes; a single quote inside closes, escapes, reopens).
std::string quote(const std::string& s) {
    std::string q = "'";
    for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return q + "'";
}

/// The last `n` lines of the text file `path`, each ending in a newline ("" if unreadable).
std::string lastLines(const std::string& path, std::size_t n) {
    std::ifstream in(path);
    std::vector<std::string> lines;
    for (std::string l; std::getline(in, l);) {
        // devslam-synth's progress line redraws itself with '\r': keep its last state.
        l = l.substr(l.find_last_of('\r') == std::string::npos ? 0 : l.find_last_of('\r') + 1);
        if (!l.empty()) lines.push_back(l);
    }
    std::string out;
    for (std::size_t k = lines.size() > n ? lines.size() - n : 0; k < lines.size(); ++k)
        out += "  " + lines[k] + "\n";
    return out;
}

/// How a child process ended, from core::runCommand's status: "exit N", "killed by signal
/// N", or that it never started (-1: no process could be made or waited for).
std::string endedBy(int status) {
    if (status == -1) return "could not be started: no process could be made or waited for";
    return WIFSIGNALED(status) ? "killed by signal " + std::to_string(WTERMSIG(status))
                               : "exit " + std::to_string(WEXITSTATUS(status));
}

/// Ctrl-C (or SIGTERM) reached the bench or the program it was running: the bench stops,
/// keeping the renders and runs made (`--reuse-runs` resumes), and leaves RESULTS alone.
struct Interrupted : std::runtime_error {
    int sig;
    explicit Interrupted(int s, const std::string& what) : std::runtime_error(what), sig(s) {}
};

/// The signal that stops the bench after a child ended with `status`, 0 = none: the bench's
/// own (a signal sent to it alone, or the terminal's Ctrl-C, which reaches both), or the
/// child's.
int stopAfter(int status) {
    if (const int sig = core::stopSignal()) return sig;
    return core::stopSignalOf(status);
}

/// What a run is made from, as its command.txt records it: the command line, the machine
/// (core::hostLine: runs on another CPU or SIMD level give other trajectories and speeds,
/// docs/bench.md), then the content hash (core::fileHash) and path of each file it reads
/// that the bench knows of.
/// `hash` caches the hashes (a rawlog or the program is read once per bench), by path, size
/// and modification time: a file edited or rebuilt while the bench runs is hashed again, so a
/// later run's command.txt names what that run read.
constexpr const char* kMachine = "machine: ";  // command.txt's second line

std::string provenance(const std::string& cmd, const std::vector<std::string>& files,
                       std::map<std::string, std::string>& hash) {
    std::string text = cmd + "\n" + kMachine + core::hostLine() + "\n";
    for (const auto& f : files) {
        std::error_code ec;
        const auto size = fs::file_size(f, ec);
        const auto when = fs::last_write_time(f, ec).time_since_epoch().count();
        const std::string key = f + "\n" + std::to_string(size) + " " + std::to_string(when);
        auto it = hash.find(key);
        if (it == hash.end()) it = hash.emplace(key, core::fileHash(f)).first;
        text += (it->second.empty() ? "unreadable" : it->second) + " " + f + "\n";
    }
    return text;
}

/// The files a run of `input` with `slam_config` reads that decide its figures: the
/// devslam-run program, the SLAM config and the filter config it names, the rawlog or the
/// TUM folder's lists and truth (the images are not read: a rendered folder's render.txt
/// stands for its images, docs/render.md).
std::vector<std::string> runInputs(const std::string& bin, const std::string& slam_config,
                                   const std::string& input) {
    std::vector<std::string> files = {bin + "/devslam-run", slam_config};
    const std::string filter = core::filterIniPath(*core::loadIni(slam_config), slam_config);
    if (filter != slam_config) files.push_back(filter);
    if (fs::is_regular_file(input)) {
        files.push_back(input);
    } else {
        for (const char* f :
             {"rgb.txt", "depth.txt", "groundtruth.txt", "camera.ini", "render.txt", "persons.txt"})
            if (fs::exists(fs::path(input) / f)) files.push_back((fs::path(input) / f).string());
    }
    return files;
}

/// Why the whole run.json in `dir` cannot stand for the run whose provenance is `made_from`
/// now ("" = it can): its command.txt names another command, or a file that has changed.
std::string staleRun(const fs::path& dir, const std::string& made_from) {
    std::ifstream in(dir / "command.txt");
    if (!in) return "made without a command.txt (by an older devslam-bench)";
    std::stringstream ss;
    ss << in.rdbuf();
    const std::string had = ss.str();
    if (had == made_from) return "";
    // Line 1: the command; line 2 the machine; then "HASH PATH" lines, compared by path
    // (one file more or less shifts the lines).
    const auto parse = [](const std::string& text, std::string& cmd, std::string& machine) {
        std::map<std::string, std::string> files;
        std::istringstream lines(text);
        std::getline(lines, cmd);
        for (std::string l; std::getline(lines, l);)
            if (l.rfind(kMachine, 0) == 0)
                machine = l.substr(std::string(kMachine).size());
            else if (const auto sp = l.find(' '); sp != std::string::npos)
                files[l.substr(sp + 1)] = l.substr(0, sp);
        return files;
    };
    std::string had_cmd, now_cmd, had_machine, now_machine;
    const auto had_files = parse(had, had_cmd, had_machine),
               now_files = parse(made_from, now_cmd, now_machine);
    if (had_cmd != now_cmd) return "made by another command (command.txt)";
    if (had_machine != now_machine)
        return had_machine.empty() ? "made where its machine was not recorded (command.txt)"
                                   : "made on another machine (" + had_machine + ")";
    for (const auto& [path, hash] : now_files) {
        const auto it = had_files.find(path);
        if (it == had_files.end()) return "made without " + path;
        if (it->second != hash) return "made from another " + path + " (its content changed since)";
    }
    for (const auto& [path, hash] : had_files)
        if (!now_files.count(path)) return "made with " + path + ", which it would not read now";
    return "made from other files (command.txt)";
}

/// One devslam-synth call of the bench: its command line, the log its output goes to.
struct RenderJob {
    std::string what;   ///< "walking_xyz seed 11", for messages
    std::string where;  ///< the sequence's section, "<bench INI> [sequence_x]"
    std::string cmd;
    std::string log;
};

/// Runs the render commands, `jobs` at a time, each with its output in its log, and says
/// when each starts and ends. After a failure no new render starts; the ones running finish,
/// and the first failure is thrown, naming its log.
void runRenders(const std::vector<RenderJob>& renders, int jobs) {
    std::mutex mu;
    std::size_t next = 0, finished = 0;
    std::string failure;
    int stop = 0;  // the signal that interrupted a render
    const auto say = [&](const std::string& line) {
        std::cout << line << "\n" << std::flush;  // under `mu`
    };
    const auto worker = [&] {
        for (;;) {
            std::size_t i = 0;
            {
                std::lock_guard<std::mutex> lock(mu);
                if (next == renders.size() || !failure.empty() || core::stopSignal()) return;
                i = next++;
                say("render (if changed) " + renders[i].what + ": " + renders[i].cmd + " > " +
                    quote(renders[i].log));
            }
            const auto t0 = std::chrono::steady_clock::now();
            const int rc =
                core::runCommand(renders[i].cmd + " > " + quote(renders[i].log) + " 2>&1");
            const double s =
                std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
            std::lock_guard<std::mutex> lock(mu);
            ++finished;
            // Said as the render itself ended; a signal to the bench alone lets it finish.
            if (core::stopSignalOf(rc)) {
                say("  render " + renders[i].what + " interrupted");
            } else if (rc != 0) {
                if (failure.empty())
                    failure = "devslam-synth failed for " + renders[i].what + " of " +
                              renders[i].where + " (" + endedBy(rc) + "):\n" +
                              lastLines(renders[i].log, 5) +
                              "(whole output: " + renders[i].log + ")";
                say("  render " + renders[i].what + " FAILED, see " + renders[i].log);
            } else {
                say("  [" + std::to_string(finished) + "/" + std::to_string(renders.size()) +
                    " renders] " + renders[i].what + " ready (" + fmt(s, 0) + " s)");
            }
            if (const int sig = stopAfter(rc); sig && !stop) {
                stop = sig;
                failure = "interrupted (" + core::signalName(sig) + ") while rendering " +
                          renders[i].what + "; the renders that finished are kept" +
                          (failure.empty() ? std::string() : "\nbefore that: " + failure);
            }
        }
    };
    std::vector<std::thread> pool;
    for (int k = 1; k < std::min<int>(jobs, int(renders.size())); ++k) pool.emplace_back(worker);
    worker();
    for (auto& t : pool) t.join();
    if (!stop && core::stopSignal()) {  // between two renders
        stop = core::stopSignal();
        failure =
            "interrupted (" + core::signalName(stop) + "); the renders that finished are kept";
    }
    if (stop) throw Interrupted(stop, failure);
    if (!failure.empty()) throw std::runtime_error(failure);
}

/// The command line.
struct Args {
    std::string config = kRoot + "/config_ini/bench.ini";
    std::string out_override;                          ///< --out
    std::string results = kRoot + "/docs/RESULTS.md";  ///< "" = none
    std::string bin;                                   ///< devslam-run's and devslam-synth's folder
    int repeats = 0;                                   ///< --repeats, 0 = the INI's
    int render_jobs = 0;                               ///< --render-jobs, 0 = the INI's
    bool reuse = false;                                ///< --reuse-runs
    std::string compare;                               ///< --compare: the earlier runs folder
    std::optional<std::size_t> max_frames;             ///< --max-frames
};

/// The command line's options; nullopt when it asked for --help (printed).
std::optional<Args> parseArgs(int argc, char** argv) {
    Args a;
    a.bin = fs::absolute(argv[0]).parent_path().string();
    devslam::core::refuseRepeatedOptions(argc, argv);
    for (int i = 1; i < argc; ++i) {
        const std::string k = argv[i];
        const auto value = [&] { return core::optionValue(argc, argv, i); };
        if (k == "--config")
            a.config = value();
        else if (k == "--repeats")
            a.repeats = int(core::parseInteger(value(), "--repeats", 1, 100));
        else if (k == "--max-frames")
            a.max_frames = std::size_t(core::parseInteger(value(), "--max-frames", 0));
        else if (k == "--out") {
            a.out_override = value();
            // (a script's unset variable: the bench wrote into the INI's out_dir instead)
            if (a.out_override.empty())
                throw std::invalid_argument("--out '': give a folder (without --out the INI's "
                                            "[bench] out_dir is used)");
        }
        else if (k == "--results") {
            a.results = value();
            if (a.results.empty() || a.results == "none") a.results.clear();
        } else if (k == "--bin")
            a.bin = value();
        else if (k == "--reuse-runs")
            a.reuse = true;
        else if (k == "--compare")
            a.compare = value();
        else if (k == "--render-jobs")
            a.render_jobs = int(core::parseInteger(value(), "--render-jobs", 1, 64));
        else if (k == "-h" || k == "--help") {
            std::cout << kUsage;
            return std::nullopt;
        } else
            throw std::invalid_argument("unknown option '" + k + "'\n" + kUsage);
    }
    return a;
}

/// The programs the bench runs: a --bin without them was reported as devslam-run refusing
/// the SLAM INI (exit 127, "not found").
void requireProgram(const Args& a, const char* app) {
    if (const auto p = fs::path(a.bin) / app;
        !fs::is_regular_file(p) || ::access(p.c_str(), X_OK) != 0)
        throw std::invalid_argument("--bin '" + a.bin + "': no program " + app +
                                    " there (the folder of devslam-bench's own build by default)");
}

/// The bench INI with the command line's overrides; its output folder made.
Bench benchOf(const Args& a) {
    Bench b = loadBench(a.config);
    if (a.repeats > 0) {  // for every sequence, also those with their own `repeats`
        b.repeats = a.repeats;
        for (auto& q : b.sequences) q.repeats = 0;
    }
    if (a.max_frames) b.max_frames = *a.max_frames;
    if (!a.out_override.empty()) b.out_dir = a.out_override;
    {  // One spelling of the folder ("./out/" is "out"): its runs' command lines, which
       // --reuse-runs compares, name it.
        fs::path o = fs::path(b.out_dir).lexically_normal();
        if (!o.has_filename() && o.has_parent_path()) o = o.parent_path();
        b.out_dir = o.string();
    }
    std::error_code ec;
    fs::create_directories(b.out_dir, ec);
    if (!fs::is_directory(b.out_dir))
        throw std::invalid_argument(
            std::string(a.out_override.empty() ? "[bench] out_dir" : "--out") + " '" + b.out_dir +
            "': cannot make the folder (" + (ec ? ec.message() : std::string("a file is there")) +
            ")");
    return b;
}

int repeatsOf(const Bench& b, const Sequence& q) {
    return q.repeats > 0 ? q.repeats : b.repeats;
}

/// Runs one program's check of an input (`cmd` ends in its --check option) with its output
/// in `log`: "" when it passes, what it said when it refuses, nothing when the program has
/// no such option (an older build given by --bin: its runs find what the check would have).
std::optional<std::string> askCheck(const std::string& cmd, const std::string& option,
                                    const std::string& log) {
    const int rc = core::runCommand(cmd + " > " + quote(log) + " 2>&1");
    if (const int sig = stopAfter(rc))
        throw Interrupted(sig, "interrupted (" + core::signalName(sig) +
                                   ") while checking the bench's inputs; nothing was run");
    if (rc == 0) return std::string();
    // (the whole log: a program that does not know the option prints its usage after it)
    const std::string all = lastLines(log, 1000);
    if (all.find("unknown argument '" + option + "'") != std::string::npos ||
        all.find("unknown option '" + option + "'") != std::string::npos)
        return std::nullopt;
    return endedBy(rc) + "):\n" + lastLines(log, 5) + "(command: " + cmd + ")";
}

/// 0. What each run and render will read, before any of them: each SLAM INI as devslam-run
/// reads it, in each mode the bench runs (devslam-run --check-config), and each synthetic
/// sequence's scenario with its `set` items (devslam-synth --check); a tenth of a second
/// each. loadBench read the INIs and made their filters, but devslam-run's own sections and
/// keys ([run], [orb], [tracker], ...) were found wrong only by the runs, after every render
/// (up to an hour of them), and a scenario's `set` key only by its render, after the
/// earlier sequences' renders.
void checkInputs(const Bench& b, const Args& a) {
    const std::string log = (fs::path(b.out_dir) / "check_inputs.log").string();
    std::set<std::pair<std::string, std::string>> checked;  // (INI, mode)
    bool run_checks = true;
    requireProgram(a, "devslam-run");
    for (const auto& q : b.sequences)
        if (!q.scenario.empty()) {
            requireProgram(a, "devslam-synth");
            break;
        }
    for (const auto& q : b.sequences)
        for (const auto& m : b.modes) {
            if (!run_checks || !checked.insert({q.slam_config, m}).second) continue;
            const std::string cmd = quote(a.bin + "/devslam-run") + " --check-config --config " +
                                    quote(q.slam_config) + " --mode " + m;
            const auto refused = askCheck(cmd, "--check-config", log);
            if (!refused) {
                std::cout << "(" << a.bin
                          << "/devslam-run has no --check-config: the SLAM INIs are checked by "
                             "its runs)\n";
                run_checks = false;
            } else if (!refused->empty()) {
                throw std::invalid_argument(q.where + ": devslam-run refuses its SLAM INI '" +
                                            q.slam_config + "' in mode " + m + " (" + *refused);
            }
        }
    for (const auto& q : b.sequences) {
        if (q.scenario.empty()) continue;
        std::string cmd = quote(a.bin + "/devslam-synth") + " " + quote(q.scenario);
        for (const auto& item : q.sets) cmd += " --set " + quote(item);
        const auto refused = askCheck(cmd + " --check", "--check", log);
        if (!refused) {
            std::cout << "(" << a.bin
                      << "/devslam-synth has no --check: the scenarios are checked by their "
                         "renders)\n";
            break;
        }
        if (!refused->empty())
            throw std::invalid_argument(
                q.where + ": devslam-synth refuses its scenario '" + q.scenario + "'" +
                (q.sets.empty() ? "" : " with its set items") + " (" + *refused);
    }
    std::error_code ec;
    fs::remove(log, ec);
}

/// 1. Synthetic sequences: renders the missing ones, and those whose scenario, room, seed,
/// frame count or renderer changed since (devslam-synth --if-changed, render.txt). Renders
/// are not timed, so several run at once; the SLAM runs, whose FPS is measured, run one at
/// a time.
void renderSequences(const Bench& b, const Args& a) {
    std::vector<RenderJob> renders;
    for (const auto& q : b.sequences) {
        if (q.scenario.empty()) continue;
        for (const auto& in : inputsOf(q, b.out_dir)) {
            RenderJob j;
            j.what = q.name + (in.seed ? " seed " + std::to_string(*in.seed) : std::string());
            j.where = q.where;
            j.log = in.path + ".log";
            fs::create_directories(fs::path(in.path).parent_path());
            j.cmd = quote(a.bin + "/devslam-synth") + " " + quote(q.scenario) + " -o " +
                    quote(in.path) + " --if-changed";
            if (in.seed) j.cmd += " --seed " + std::to_string(*in.seed);
            for (const auto& item : q.sets) j.cmd += " --set " + quote(item);
            if (b.max_frames) j.cmd += " --frames " + std::to_string(b.max_frames);
            renders.push_back(j);
        }
    }
    int jobs = a.render_jobs ? a.render_jobs : b.render_jobs;
    if (jobs == 0)  // each render holds a sequence's images in memory: at most 8
        jobs = int(std::clamp(std::thread::hardware_concurrency(), 1u, 8u));
    runRenders(renders, jobs);
}

/// The SLAM runs of a bench: each (sequence, mode)'s runs, over its renders and repeats.
struct Runs {
    std::map<std::pair<std::string, std::string>, std::vector<RunFigures>> of;
    std::string csv;  ///< runs.csv: a row a run
    std::size_t total = 0, reused = 0;
    /// When the runs kept from an earlier bench were made (their run.json files' times).
    std::optional<std::time_t> kept_from, kept_to;
    std::vector<std::string> failed;  ///< logs of the runs that failed
    /// The runs of (seq, mode), of one render when `seed` is given.
    [[nodiscard]] std::vector<RunFigures> get(const std::string& seq, const std::string& mode,
                                              std::optional<std::uint64_t> seed) const {
        std::vector<RunFigures> v;
        const auto it = of.find({seq, mode});
        if (it != of.end())
            for (const auto& f : it->second)
                if (!seed || f.seed == seed) v.push_back(f);
        return v;
    }
};

/// A run.json's modification time as a time_t (file_time_type's clock is not system_clock
/// before C++20).
std::time_t writtenAt(const fs::path& file) {
    return std::chrono::system_clock::to_time_t(
        std::chrono::system_clock::now() +
        std::chrono::duration_cast<std::chrono::system_clock::duration>(
            fs::last_write_time(file) - fs::file_time_type::clock::now()));
}

/// A run's folder under <out>/runs/SEQ/MODE: [seedS_]rR.
std::string runLeaf(const Input& in, int r) {
    return (in.seed ? "seed" + std::to_string(*in.seed) + "_" : std::string()) + "r" +
           std::to_string(r);
}

/// runs.csv's row for run `r` of `q` in mode `m` ("n/a" for the figures of a failed run,
/// not the zeros of an empty RunFigures).
std::string csvRow(const Sequence& q, const std::string& m, const std::string& seed, int r,
                   const RunFigures& f) {
    const auto fig = [&](double x, int prec) { return f.ok ? fmt(x, prec) : std::string("n/a"); };
    std::ostringstream row;
    row << q.name << "," << m << "," << seed << "," << r << "," << fig(f.ate_rmse, 6) << ","
        << fig(f.ate_mean, 6) << "," << fig(f.ate_median, 6) << "," << fig(f.rpe_t_rmse, 6) << ","
        << fig(f.rpe_t_mean, 6) << "," << fig(f.rpe_t_median, 6) << "," << fig(f.rpe_r_rmse, 4)
        << "," << fig(f.rpe_r_mean, 4) << "," << fig(f.rpe_r_median, 4) << ","
        << fig(f.fps_median, 2) << "," << fig(f.fps_mean, 2) << "," << fig(f.lost, 0) << "\n";
    return row.str();
}

/// 2. The SLAM runs, one at a time (their FPS is measured), each in
/// <out>/runs/SEQ/MODE/[seedS_]rR; with --reuse-runs a whole run made by this same command
/// from the same files is kept. Throws Interrupted on Ctrl-C, keeping the runs that finished.
Runs runSlam(const Bench& b, const Args& a) {
    Runs runs;
    // Written when every run is done: an interrupted bench leaves the last one's.
    runs.csv =
        "sequence,mode,seed,repeat,ate_rmse_m,ate_mean_m,ate_median_m,rpe_t_rmse_m,rpe_t_mean_m,"
        "rpe_t_median_m,rpe_r_rmse_deg,rpe_r_mean_deg,rpe_r_median_deg,fps_median,fps_mean,"
        "lost_frames\n";
    for (const auto& q : b.sequences)
        for (const auto& m : b.modes)
            runs.total += runsMode(q, b.out_dir, m)
                              ? std::size_t(repeatsOf(b, q)) * inputsOf(q, b.out_dir).size()
                              : 0;
    std::size_t done = 0;
    std::map<std::string, std::string> hashes;  // file -> content hash, for command.txt
    for (const auto& q : b.sequences)
        for (const auto& m : b.modes) {
            // Once per sequence and mode, not per run: for mode truth it reads persons.txt.
            if (!runsMode(q, b.out_dir, m)) continue;
            for (const auto& in : inputsOf(q, b.out_dir))
                for (int r = 0; r < repeatsOf(b, q); ++r) {
                    const std::string seed = in.seed ? std::to_string(*in.seed) : std::string();
                    const fs::path dir = fs::path(b.out_dir) / "runs" / q.name / m / runLeaf(in, r);
                    fs::create_directories(dir);
                    std::string cmd = quote(a.bin + "/devslam-run") + " --input " + quote(in.path) +
                                      " --config " + quote(q.slam_config) + " --mode " + m +
                                      " --out " + quote(dir.string()) + " --quiet --no-slam-map";
                    if (b.max_frames) cmd += " --max-frames " + std::to_string(b.max_frames);
                    const std::string again = cmd;  // for a failed run's message
                    cmd += " > " + quote((dir / "log.txt").string()) + " 2>&1";
                    std::cout << "[" << ++done << "/" << runs.total << "] " << q.name << " " << m
                              << (in.seed ? " seed " + seed : std::string()) << " run " << r + 1
                              << "\n"
                              << std::flush;
                    const std::string json = (dir / "run.json").string();
                    RunFigures f = a.reuse ? readRun(json) : RunFigures{};
                    if (!f.unreadable.empty())  // run again, as a failed run is
                        std::cerr << "  WARNING: not kept: " << f.unreadable << "\n";
                    const std::string made_from =
                        provenance(cmd, runInputs(a.bin, q.slam_config, in.path), hashes);
                    if (f.ok) {  // a whole run made earlier: kept if it is this one
                        if (const std::string why = staleRun(dir, made_from); !why.empty()) {
                            std::cout << "  not kept: its run.json was " << why << "\n";
                            f = RunFigures{};
                        }
                    }
                    const bool have = f.ok;
                    int rc = 0;
                    const bool start = !have && !core::stopSignal();
                    if (start) {
                        // A run killed before it wrote its own must not leave an older one.
                        fs::remove(json);
                        core::writeFileWhole((dir / "command.txt").string(), made_from);
                        rc = core::runCommand(cmd);
                    }
                    if (const int sig = stopAfter(rc))
                        throw Interrupted(sig, "interrupted (" + core::signalName(sig) + ") " +
                                                   (start ? "during" : "before") + " run " +
                                                   std::to_string(done) + " of " +
                                                   std::to_string(runs.total) +
                                                   "; the runs that finished are kept");
                    runs.reused += have;
                    if (have) {
                        const std::time_t written = writtenAt(json);
                        runs.kept_from = std::min(runs.kept_from.value_or(written), written);
                        runs.kept_to = std::max(runs.kept_to.value_or(written), written);
                    }
                    // kExitNoPose: a whole run that lost every frame; its run.json says so,
                    // and its figures without a trajectory (no ATE) count as the run's.
                    const bool whole =
                        rc == 0 || (WIFEXITED(rc) && WEXITSTATUS(rc) == core::kExitNoPose);
                    if (!have) f = whole ? readRun(json) : RunFigures{};
                    f.seed = in.seed;
                    f.dir = dir;
                    if (!f.ok) {
                        runs.failed.push_back((dir / "log.txt").string());
                        std::cerr << "  devslam-run failed ("
                                  << (!whole                 ? endedBy(rc)
                                      : f.unreadable.empty() ? std::string("no readable run.json")
                                                             : f.unreadable)
                                  << "):\n"
                                  << lastLines((dir / "log.txt").string(), 3)
                                  << "  (whole output: " << (dir / "log.txt").string()
                                  << ")\n  to run it again: " << again << "\n";
                    }
                    runs.of[{q.name, m}].push_back(f);
                    runs.csv += csvRow(q, m, seed, r, f);
                }
        }
    return runs;
}

/// A figure of the runs that finished and have it (no ground truth, too short for the RPE).
std::vector<double> having(const std::vector<RunFigures>& v, double RunFigures::*field) {
    std::vector<double> x;
    for (const auto& f : v)
        if (f.ok && !std::isnan(f.*field)) x.push_back(f.*field);
    return x;
}

/// Its median over those runs; NaN when none has it.
double med(const std::vector<RunFigures>& v, double RunFigures::*field) {
    const auto x = having(v, field);
    return x.empty() ? std::numeric_limits<double>::quiet_NaN() : core::median(x);
}

/// 3. The tables: medians over the runs (renders x repeats), as Markdown and CSV, and the
/// trajectory plots of the median-ATE runs.
struct Tables {
    std::ostringstream t1, t2, t3, t4, t5;  ///< RPE, ATE, FPS, filter, ATE per render
    std::ostringstream c1, c2, c3, c4;      ///< the CSV files of t1-t4
    std::map<std::string, std::vector<std::string>> plots;      ///< sequence -> modes with a plot
    std::vector<std::pair<fs::path, fs::path>> results_images;  ///< copied beside RESULTS.md
    int filter_rows = 0;                                        ///< rows of t4
};

/// Copies the plot of the run of `v` whose ATE is nearest the median (with an even number of
/// runs the median lies between two) into the output folder as <seq>_<mode>_trajectory.png,
/// and lists it (for tables.md), and for RESULTS.md's images when there is a results file.
void keepMedianPlot(const Bench& b, const Sequence& q, const std::string& m,
                    const std::vector<RunFigures>& v, const std::string& results, Tables& t) {
    const double target = med(v, &RunFigures::ate_rmse);
    std::optional<std::size_t> nearest;
    for (std::size_t r = 0; r < v.size(); ++r)
        if (v[r].ok && !std::isnan(v[r].ate_rmse) &&
            (!nearest ||
             std::abs(v[r].ate_rmse - target) < std::abs(v[*nearest].ate_rmse - target)))
            nearest = r;
    if (!nearest || !fs::exists(v[*nearest].dir / "trajectory.png")) return;
    const fs::path src = v[*nearest].dir / "trajectory.png";
    // A copy that fails (a read-only file left by another user, a full disk) loses that one
    // plot, not every table after it.
    const fs::path dst = fs::path(b.out_dir) / (q.name + "_" + m + "_trajectory.png");
    std::error_code ec;
    fs::copy_file(src, dst, fs::copy_options::overwrite_existing, ec);
    if (ec)
        std::cerr << "devslam-bench: warning: plot not copied to " << dst.string() << " ("
                  << ec.message() << ")\n";
    else
        t.plots[q.name].push_back(m);
    // Beside RESULTS.md, for its figures (the diagnostic truth mode's plots stay in the
    // results folder).
    if (!results.empty() && m != "truth") {  // copied with the section, if whole
        const fs::path img = fs::path(results).parent_path() / "images";
        t.results_images.emplace_back(src, img / ("bench_" + q.name + "_" + m + ".png"));
    }
}

/// The filter's row of `v` against the renderer's person truth (t4, c4); none for the modes
/// without a filter or sequences without person truth.
void filterRow(const Sequence& q, const std::string& m, const std::vector<RunFigures>& v,
               Tables& t) {
    using R = RunFigures;
    // none masks nothing and truth is the truth: no filter to score.
    if (m == "none" || m == "truth" || std::isnan(med(v, &R::moving_instances))) return;
    const auto pct = [](double x) {
        return std::isnan(x) ? std::string("n/a") : fmt(100 * x, 1) + " %";
    };
    // "x % of N" for N person-frames; a sequence without such people says so.
    const auto ofInstances = [&](double R::*frac, double R::*count, const char* none) {
        const double n = med(v, count);
        return n > 0 ? pct(med(v, frac)) + " of " + fmt(n, 0) : std::string(none);
    };
    const bool walkers = med(v, &R::moving_instances) > 0;
    ++t.filter_rows;
    t.t4 << "| " << q.name << " | " << m << " | "
         << ofInstances(&R::moving_recall, &R::moving_instances, "n/a (no walkers)") << " | "
         << (walkers ? pct(med(v, &R::moving_area_recall)) : "n/a") << " | "
         << pct(med(v, &R::mask_precision)) << " | "
         << ofInstances(&R::static_masked, &R::static_instances, "n/a (no static people)")
         << " |\n";
    t.c4 << q.name << "," << m << "," << fmt(med(v, &R::moving_recall), 4) << ","
         << fmt(med(v, &R::moving_area_recall), 4) << "," << fmt(med(v, &R::mask_precision), 4)
         << "," << fmt(med(v, &R::static_masked), 4) << "," << fmt(med(v, &R::moving_instances), 0)
         << "," << fmt(med(v, &R::static_instances), 0) << "\n";
}

Tables makeTables(const Bench& b, const Runs& runs, const std::string& results) {
    Tables t;
    t.t1 << "| sequence | mode | trans RMSE (m) | trans mean (m) | trans median (m) | rot RMSE "
            "(deg) | rot mean (deg) | rot median (deg) |\n|---|---|---|---|---|---|---|---|\n";
    t.t2 << "| sequence | mode | ATE RMSE (m) | ATE mean (m) | ATE median (m) | lost frames | "
            "runs ok |\n|---|---|---|---|---|---|---|\n";
    t.t3 << "| sequence | mode | median FPS | mean FPS |\n|---|---|---|---|\n";
    t.t4 << "| sequence | mode | walking people masked (per person and frame) | walking area "
            "masked | masked area on walkers (precision) | static people masked "
            "|\n|---|---|---|---|---|---|\n";
    t.c1 << "sequence,mode,rpe_t_rmse_m,rpe_t_mean_m,rpe_t_median_m,rpe_r_rmse_deg,"
            "rpe_r_mean_deg,rpe_r_median_deg\n";
    t.c2 << "sequence,mode,ate_rmse_m,ate_mean_m,ate_median_m,lost_frames,runs_ok\n";
    t.c3 << "sequence,mode,fps_median,fps_mean\n";
    t.c4 << "sequence,mode,moving_recall,moving_area_recall,precision,static_masked,"
            "moving_instances,static_instances\n";
    for (const auto& q : b.sequences)
        for (const auto& m : b.modes) {
            if (!runsMode(q, b.out_dir, m)) continue;
            const auto v = runs.get(q.name, m, std::nullopt);
            int ok = 0;
            for (const auto& f : v) ok += f.ok;
            using R = RunFigures;
            t.t1 << "| " << q.name << " | " << m << " | " << fmt(med(v, &R::rpe_t_rmse), 4) << " | "
                 << fmt(med(v, &R::rpe_t_mean), 4) << " | " << fmt(med(v, &R::rpe_t_median), 4)
                 << " | " << fmt(med(v, &R::rpe_r_rmse), 3) << " | "
                 << fmt(med(v, &R::rpe_r_mean), 3) << " | " << fmt(med(v, &R::rpe_r_median), 3)
                 << " |\n";
            t.c1 << q.name << "," << m << "," << fmt(med(v, &R::rpe_t_rmse), 6) << ","
                 << fmt(med(v, &R::rpe_t_mean), 6) << "," << fmt(med(v, &R::rpe_t_median), 6) << ","
                 << fmt(med(v, &R::rpe_r_rmse), 4) << "," << fmt(med(v, &R::rpe_r_mean), 4) << ","
                 << fmt(med(v, &R::rpe_r_median), 4) << "\n";
            // The medians are over the runs that have the figure: the table says how many.
            std::string runs_ok = std::to_string(ok) + "/" + std::to_string(v.size());
            if (const auto n = having(v, &R::ate_rmse).size(); n < std::size_t(ok))
                runs_ok += "; ATE from " + std::to_string(n);
            if (const auto n = having(v, &R::rpe_t_rmse).size(); n < std::size_t(ok))
                runs_ok += "; RPE from " + std::to_string(n);
            // 5 decimals: sitting_xyz's modes differ by tenths of a millimetre.
            t.t2 << "| " << q.name << " | " << m << " | " << fmt(med(v, &R::ate_rmse), 5) << " | "
                 << fmt(med(v, &R::ate_mean), 5) << " | " << fmt(med(v, &R::ate_median), 5) << " | "
                 << fmt(med(v, &R::lost), 0) << " | " << runs_ok << " |\n";
            t.c2 << q.name << "," << m << "," << fmt(med(v, &R::ate_rmse), 6) << ","
                 << fmt(med(v, &R::ate_mean), 6) << "," << fmt(med(v, &R::ate_median), 6) << ","
                 << fmt(med(v, &R::lost), 0) << "," << ok << "\n";
            t.t3 << "| " << q.name << " | " << m << " | " << fmt(med(v, &R::fps_median), 1) << " | "
                 << fmt(med(v, &R::fps_mean), 1) << " |\n";
            t.c3 << q.name << "," << m << "," << fmt(med(v, &R::fps_median), 2) << ","
                 << fmt(med(v, &R::fps_mean), 2) << "\n";
            // Per render: the median over its repeats.
            if (!q.seeds.empty()) {
                t.t5 << "| " << q.name << " | " << m << " |";
                for (std::size_t k = 0; k < q.seeds.size(); ++k)
                    t.t5 << (k ? ", " : " ")
                         << fmt(med(runs.get(q.name, m, q.seeds[k]), &R::ate_rmse), 5) << " ("
                         << (k ? "" : "seed ") << q.seeds[k] << ")";
                t.t5 << " |\n";
            }
            keepMedianPlot(b, q, m, v, results, t);
            filterRow(q, m, v, t);
        }
    return t;
}

/// The trajectory plots, a table per sequence: those beside RESULTS.md (`beside_results`:
/// images/bench_<seq>_<mode>.png, truth's left out) or those in the output folder, beside
/// tables.md (<seq>_<mode>_trajectory.png; its links were RESULTS.md's, which it has not).
/// "" when there is none.
std::string plotsMarkdown(const Tables& t, bool beside_results) {
    std::ostringstream figs;
    for (const auto& [seq, all] : t.plots) {
        std::vector<std::string> modes;
        for (const auto& m : all)
            if (!beside_results || m != "truth") modes.push_back(m);
        if (modes.empty()) continue;
        figs << "| " << seq << " |";
        for (const auto& m : modes) figs << " " << m << " |";
        figs << "\n|---|";
        for (std::size_t k = 0; k < modes.size(); ++k) figs << "---|";
        figs << "\n| |";
        for (const auto& m : modes)
            figs << " ![" << seq << " " << m << "]("
                 << (beside_results ? "images/bench_" + seq + "_" + m + ".png"
                                    : seq + "_" + m + "_trajectory.png")
                 << ") |";
        figs << "\n\n";
    }
    return figs.str();
}

/// The [targets], checked on the same medians as the tables, and render by render: the
/// Markdown table and targets.csv ("" for both without targets).
std::pair<std::string, std::string> checkTargets(const Bench& b, const Runs& runs) {
    if (b.targets.empty()) return {};
    const bench::FigureOf figureOf = [&](const std::string& seq, const std::string& mode,
                                         const std::string& figure,
                                         std::optional<std::uint64_t> seed) {
        using R = RunFigures;
        const auto v = runs.get(seq, mode, seed);
        if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
        if (figure == "ate") return med(v, &R::ate_rmse);
        if (figure == "fps") return med(v, &R::fps_median);
        if (figure == "walkers_masked")
            return med(v, &R::moving_instances) > 0 ? med(v, &R::moving_recall) : NAN;
        if (figure == "static_masked")
            return med(v, &R::static_instances) > 0 ? med(v, &R::static_masked) : NAN;
        const auto ref = runs.get(seq, figure.substr(figure.find('/') + 1), seed);  // ate/<mode>
        if (ref.empty()) return std::numeric_limits<double>::quiet_NaN();
        return med(v, &R::ate_rmse) / med(ref, &R::ate_rmse);
    };
    std::vector<bench::SequenceInputs> inputs;
    for (const auto& q : b.sequences) inputs.push_back({q.name, q.seeds});
    std::ostringstream md, csv;
    csv << "target,sequence,mode,figure,op,value,measured,measured_on,met,inputs_met,"
           "inputs,paired_geomean,paired_lo95,paired_hi95,renders_verdict\n";
    md << "**Targets** (bench.ini `[targets]`, checked on the medians of the tables "
          "below; `*`: every sequence with the figure, the worst one shown; ate in "
          "m, masked as fractions of the people's frames; *renders meeting it*: "
          "each render's own figure, a ratio of two modes on the same render, a "
          "real sequence counting as one; *per-render ratio*: for a ratio, the "
          "geometric mean of the renders' own ratios and its 95 % confidence "
          "interval (Student's t on their logarithms), an interval holding 1 "
          "meaning the renders do not tell the two modes apart)\n\n"
          "| target | measured | met | renders meeting it | per-render ratio "
          "[95 % CI] |\n|---|---|---|---|---|\n";
    int met = 0;
    // Targets the medians decide one way and the renders' interval does not (or decides the
    // other way): named under the count, so that a pass by the spread is not read as a result.
    std::vector<std::string> open, against;
    for (const auto& t : b.targets) {
        const auto c = bench::check(t, inputs, figureOf);
        const auto n = bench::tallyInputs(t, inputs, figureOf);
        const auto p = bench::pairedRatio(t, c.sequence, inputs, figureOf);
        const auto verdict = bench::renderVerdict(t, p);
        met += c.met;
        if (verdict == bench::RenderVerdict::Open) open.push_back(t.key);
        if (verdict == (c.met ? bench::RenderVerdict::Missed : bench::RenderVerdict::Met))
            against.push_back(t.key);
        const int prec = t.figure == "fps" ? 1 : t.figure == "ate" ? 5 : 3;
        md << "| " << t.key << ": " << t.text() << " | " << fmt(c.measured, prec)
           << (t.sequence == "*" && !c.sequence.empty() ? " (" + c.sequence + ")" : std::string())
           << " | " << (c.met ? "yes" : "**no**") << " | " << n.met << " of " << n.of << " | "
           << (p.count >= 2 ? fmt(p.geomean, 3) + " [" + fmt(p.lo, 3) + ", " + fmt(p.hi, 3) + "]"
                            : std::string())
           << " |\n";
        csv << t.key << "," << t.sequence << "," << t.mode << "," << t.figure << "," << t.op << ","
            << t.value << "," << fmt(c.measured, 6) << "," << c.sequence << "," << (c.met ? 1 : 0)
            << "," << n.met << "," << n.of << "," << fmt(p.geomean, 6) << "," << fmt(p.lo, 6) << ","
            << fmt(p.hi, 6) << ","
            << (verdict == bench::RenderVerdict::Met      ? "met"
                : verdict == bench::RenderVerdict::Missed ? "missed"
                : verdict == bench::RenderVerdict::Open   ? "open"
                                                          : "")
            << "\n";
    }
    md << "\n" << bench::targetsSummary(met, b.targets.size(), open, against) << "\n\n";
    return {md.str(), csv.str()};
}

/// How often each sequence ran, for the text: "walking_xyz 3 renders (seed 11 14 15) x 1
/// run, ... per mode".
std::string runsLine(const Bench& b) {
    std::ostringstream line;
    for (std::size_t i = 0; i < b.sequences.size(); ++i) {
        const auto& q = b.sequences[i];
        const std::size_t n_in = inputsOf(q, b.out_dir).size();
        line << (i ? ", " : "") << q.name << " ";
        if (!q.seeds.empty()) {
            line << n_in << " render" << (n_in > 1 ? "s" : "") << " (seed";
            for (const auto s : q.seeds) line << " " << s;
            line << ") x ";
        }
        line << repeatsOf(b, q) << " run" << (repeatsOf(b, q) > 1 ? "s" : "");
    }
    line << " per mode";
    return line.str();
}

/// What each synthetic sequence renders, where its name does not say it alone ("" if none).
std::string scenesLine(const Bench& b) {
    std::ostringstream scenes;
    for (const auto& q : b.sequences) {
        if (q.scenario.empty() || (q.sets.empty() && q.name == q.scenario)) continue;
        scenes << (scenes.tellp() > 0 ? "; " : "Sequences: ") << q.name << " is scenario `"
               << (fs::path(q.scenario).is_absolute() ? core::shownPath(q.scenario, kRoot)
                                                      : q.scenario)
               << "`";
        for (std::size_t k = 0; k < q.sets.size(); ++k)
            scenes << (k ? " " : " with `devslam-synth ") << "--set "
                   << (q.sets[k].find(' ') == std::string::npos ? q.sets[k] : quote(q.sets[k]));
        if (!q.sets.empty()) scenes << "`";
    }
    if (scenes.tellp() > 0) scenes << ".\n\n";
    return scenes.str();
}

/// The bench's section: how it was measured, the targets, Tables 1-3, the filter's table,
/// the plots and the paper's figures for reference: RESULTS.md's `bench` (`beside_results`,
/// its plots in images/) or tables.md (its plots beside it).
std::string sectionMarkdown(const Args& a, const Bench& b, const Runs& runs, const Tables& t,
                            const std::string& targets_md, bool beside_results) {
    const std::string plots = plotsMarkdown(t, beside_results);
    std::ostringstream md;
    md << "## Dynamic-SLAM benchmark: the paper's Tables 1-3 (`devslam-bench`)\n\n"
       << "Measured " << core::measuredOnLine() << " by `devslam-bench --config "
       << core::shownPath(a.config, kRoot)
       << (a.out_override.empty() ? std::string() : " --out " + quote(a.out_override))
       << (a.repeats ? " --repeats " + std::to_string(b.repeats) : std::string())
       << (a.max_frames ? " --max-frames " + std::to_string(b.max_frames) : std::string())
       << (a.reuse ? " --reuse-runs" : "") << "`: " << runsLine(b)
       << " with `devslam-run`; the tables give medians over all runs of a sequence and mode. "
       << (runs.reused ? std::to_string(runs.reused) + " of " + std::to_string(runs.total) +
                             " runs were kept from an earlier invocation that made them "
                             "(`--reuse-runs`: their figures, speed included, are from their "
                             "run.json files, written " +
                             core::utcMinute(*runs.kept_from) +
                             (core::utcMinute(*runs.kept_to) == core::utcMinute(*runs.kept_from)
                                  ? std::string()
                                  : " to " + core::utcMinute(*runs.kept_to)) +
                             "). "
                       : std::string())
       << "Synthetic sequences are rendered by `devslam-synth` (exact ground truth; "
          "docs/render.md), each in the renders listed (`--seed`: the same scene and motion "
          "with other image and depth noise, docs/dynamic.md), because one render cannot rank "
          "two settings of this SLAM. RPE over 1 s.\n\n"
       << scenesLine(b)
       << (std::find(b.modes.begin(), b.modes.end(), "truth") != b.modes.end()
               ? std::string("Mode `truth` is a diagnostic, not a method: the SLAM gets the "
                             "renderer's walking people (their pixels, dilated by the filter's "
                             "mask_margin) as the mask, i.e. what a perfect filter would give. "
                             "It bounds what any mask can do on a sequence (synthetic "
                             "sequences where someone walks: elsewhere its mask is empty and "
                             "the run is `none`'s).\n\n")
               : std::string())
       << targets_md << "**Table 1: RPE**\n\n"
       << t.t1.str() << "\n**Table 2: ATE**\n\n"
       << t.t2.str()
       << "\n*runs ok*: the runs that finished, of those made. Tables 1 and 2 give medians over "
          "the runs that have the figure; *runs ok* says so where fewer do (\"RPE from 3\": a "
          "run too short for pairs 1 s apart, or without ground truth).\n"
       << (t.t5.str().empty()
               ? std::string()
               : "\n**ATE RMSE (m) per render** (median over the render's runs; Table 2 gives "
                 "the median over all runs)\n\n| sequence | mode | ATE RMSE per render "
                 "|\n|---|---|---|\n" +
                     t.t5.str())
       << "\n**Table 3: speed** (wall clock, whole pipeline with the detector)\n\n"
       << t.t3.str()
       << (t.filter_rows == 0
               ? std::string("\n**Filter against the renderer's person truth**: no row (no "
                             "run of a filter on a sequence with person truth, i.e. a "
                             "render).\n")
               : "\n**Filter against the renderer's person truth**: the masks the SLAM runs "
                 "used, scored by `devslam-run` frame by frame (medians over the runs). A person "
                 "counts as masked in a frame when at least half of its visible pixels are "
                 "masked; people with fewer than 500 visible pixels are not counted.\n\n" +
                     t.t4.str())
       << (plots.empty() ? std::string("\n")
                         : "\n**Trajectories** (estimate vs ground truth after alignment, the "
                           "run with the median ATE)\n\n" +
                               plots)
       << "For reference, the paper's figures on the real TUM fr3 sequences (not comparable one "
          "to one: "
          "different scenes and sensors): walking_xyz ATE RMSE ORB-SLAM2 0.197 m (paper re-run), "
          "DynaSLAM "
          "0.0195 m, DEV-SLAM 0.01955 m; sitting_xyz ORB-SLAM2 0.01415 m, DynaSLAM 0.01601 m, "
          "DEV-SLAM "
          "0.01501 m; speed ORB-SLAM2 ~54-59 FPS, DynaSLAM 0.2 FPS, DEV-SLAM ~2-3 FPS on an i9.\n\n"
       << "Per-run figures: `" << (fs::path(b.out_dir) / "runs.csv").string()
       << "`; tables as CSV and the "
          "trajectory plots (`<sequence>_<mode>_trajectory.png`, median-ATE run) in `"
       << b.out_dir << "/`.\n";
    return md.str();
}

/// --compare: the runs of <out>/runs against those in `before` (the same bench's runs,
/// kept aside), each run with the one of the same render and repeat. Per sequence and mode:
/// the medians of ATE RMSE, keyframes, landmarks and map size over the runs both have, and
/// the geometric mean of the renders' own ratios (after / before: one render cannot rank two
/// settings, the ATE moves by up to 2-3x between renders). Prints a Markdown table.
int compareRuns(const Bench& b, const std::string& before) {
    if (!fs::is_directory(before))
        throw std::invalid_argument("--compare: no such folder '" + before + "'");
    const fs::path after = fs::path(b.out_dir) / "runs";
    std::ostringstream md;
    md << "Runs in " << after.string() << " (after) against " << before
       << " (before); medians over the runs both have, per-render ratio: geometric mean of "
          "after / before on each render (median over its repeats)\n\n"
       << "| sequence | mode | ATE before | ATE after | per-render ratio | renders lower | "
          "keyframes before / after | landmarks before / after | map MB before / after | "
          "median FPS before / after |\n"
       << "|---|---|---|---|---|---|---|---|---|---|\n";
    std::size_t pairs = 0, missing = 0;
    std::map<std::string, std::pair<int, int>> lower_of;  // mode -> (sequences lower, of)
    for (const auto& q : b.sequences)
        for (const auto& m : b.modes) {
            if (!runsMode(q, b.out_dir, m)) continue;
            std::vector<RunFigures> was, now;  // paired runs, both whole
            std::vector<double> logs;
            int lower = 0;
            for (const auto& in : inputsOf(q, b.out_dir)) {
                std::vector<double> ate0, ate1;
                for (int r = 0; r < repeatsOf(b, q); ++r) {
                    const fs::path leaf = fs::path(q.name) / m / runLeaf(in, r);
                    const RunFigures f0 = readRun((fs::path(before) / leaf / "run.json").string());
                    const RunFigures f1 = readRun((after / leaf / "run.json").string());
                    if (!f0.ok || !f1.ok) {
                        ++missing;
                        // A run.json that is there but broken is named, as --reuse-runs does.
                        for (const auto* f : {&f0, &f1})
                            if (!f->unreadable.empty())
                                std::cerr << "devslam-bench: --compare: " << f->unreadable
                                          << ": left out\n";
                        continue;
                    }
                    ++pairs;
                    was.push_back(f0);
                    now.push_back(f1);
                    if (!std::isnan(f0.ate_rmse) && !std::isnan(f1.ate_rmse)) {
                        ate0.push_back(f0.ate_rmse);
                        ate1.push_back(f1.ate_rmse);
                    }
                }
                if (ate0.empty()) continue;
                const double r = core::median(ate1) / core::median(ate0);
                if (!std::isfinite(r) || r <= 0) continue;  // an ATE of 0 on one side
                logs.push_back(std::log(r));
                lower += r < 1;
            }
            if (was.empty()) continue;
            const double a0 = med(was, &RunFigures::ate_rmse), a1 = med(now, &RunFigures::ate_rmse);
            if (!std::isnan(a0) && !std::isnan(a1)) {
                auto& [lo, of] = lower_of[m];
                lo += a1 < a0;
                ++of;
            }
            const auto both = [&](double RunFigures::*field, int prec) {
                return fmt(med(was, field), prec) + " / " + fmt(med(now, field), prec);
            };
            md << "| " << q.name << " | " << m << " | " << fmt(a0, 5) << " | " << fmt(a1, 5)
               << " | "
               << (logs.empty() ? std::string("n/a")
                                : fmt(std::exp(core::meanInterval95(logs).mean), 3))
               << " | " << lower << " of " << logs.size() << " | "
               << both(&RunFigures::keyframes, 1) << " | " << both(&RunFigures::landmarks, 0)
               << " | " << both(&RunFigures::map_mb, 1) << " | " << both(&RunFigures::fps_median, 1)
               << " |\n";
        }
    if (pairs == 0)
        throw std::invalid_argument("--compare: " + before + " and " + after.string() +
                                    " have no run of this bench in common (" +
                                    std::to_string(missing) + " runs missing in one or both)");
    md << "\nMedian ATE lower after than before:";
    for (const auto& m : b.modes)
        if (lower_of.count(m))
            md << " " << m << " on " << lower_of[m].first << " of " << lower_of[m].second
               << " sequences;";
    md << " " << pairs << " runs compared";
    if (missing) md << ", " << missing << " missing in one or both folders (left out)";
    md << ".\n";
    std::cout << md.str();
    return 0;
}

int run(int argc, char** argv) {
    const std::optional<Args> args = parseArgs(argc, argv);
    if (!args) return 0;  // --help
    const Args& a = *args;
    const Bench b = benchOf(a);
    if (!a.compare.empty()) return compareRuns(b, a.compare);
    // Before hours of work (after the output folder is made: the results may go in it).
    if (!a.results.empty()) core::checkResultsSection(a.results, "bench");
    checkInputs(b, a);
    renderSequences(b, a);
    const Runs runs = runSlam(b, a);
    const Tables t = makeTables(b, runs, a.results);
    const auto [targets_md, targets_csv] = checkTargets(b, runs);
    // RESULTS.md's section (its plots in images/ beside it), and tables.md's (in the output
    // folder, beside its plots); the standard output shows the one of the file written.
    const std::string md = sectionMarkdown(a, b, runs, t, targets_md, true);
    const std::string tables_md = sectionMarkdown(a, b, runs, t, targets_md, false);

    const fs::path out(b.out_dir);
    for (const auto& [name, text] :
         std::vector<std::pair<std::string, std::string>>{{"runs.csv", runs.csv},
                                                          {"table1_rpe.csv", t.c1.str()},
                                                          {"table2_ate.csv", t.c2.str()},
                                                          {"table3_fps.csv", t.c3.str()},
                                                          {"filter_truth.csv", t.c4.str()},
                                                          {"tables.md", tables_md}})
        core::writeFileWhole((out / name).string(), text);
    if (!b.targets.empty())
        core::writeFileWhole((out / "targets.csv").string(), targets_csv);
    else
        fs::remove(out / "targets.csv");  // an earlier bench's, for targets no longer asked
    std::cout << (a.results.empty() ? tables_md : md);
    if (!runs.failed.empty()) {
        // The tables count them as failed runs; a results file keeps its last whole bench.
        std::cerr << "devslam-bench: " << runs.failed.size() << " of " << runs.total
                  << " runs failed (the first: " << runs.failed.front() << "); "
                  << (a.results.empty() ? std::string("") : a.results + " left as it was; ")
                  << "--reuse-runs runs only those again\n";
        return 1;
    }
    if (!a.results.empty()) {
        // The plots it shows with it (a bench with failed runs changed neither).
        // Each whole or not at all (writeFileWhole): a bench stopped while copying leaves
        // every plot either the old one or the new one, never a cut file.
        for (const auto& [src, dst] : t.results_images) {
            fs::create_directories(dst.parent_path());
            std::ifstream in(src, std::ios::binary);
            const std::string png{std::istreambuf_iterator<char>(in), {}};
            if (!in && !in.eof()) throw std::runtime_error("cannot read '" + src.string() + "'");
            core::writeFileWhole(dst.string(), png);
        }
        core::replaceResultsSection(a.results, "bench", md);
    }
    if (const int sig = core::stopSignal())  // the runs were all done by then
        std::cerr << "devslam-bench: " << core::signalName(sig)
                  << " came after the last run; the bench is whole"
                  << (a.results.empty() ? std::string() : " and " + a.results + " was written")
                  << "\n";
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    core::installStopHandler("devslam-bench");
    int rc = 1;
    try {
        rc = run(argc, argv);
    } catch (const Interrupted& e) {
        std::cerr << "devslam-bench: " << e.what()
                  << " (the same command with --reuse-runs resumes); the results file was "
                     "left as it was\n";
        // Ended by the signal, as a shell expects of a program stopped by Ctrl-C.
        core::exitBySignal(e.sig);
    } catch (const std::exception& e) {
        std::cerr << "devslam-bench: " << e.what() << "\n";
    }
    if (const int sig = core::stopSignal()) core::exitBySignal(sig);
    return core::withStandardOutput("devslam-bench", rc);  // the tables are printed there too
}
