// devslam-run: the main job. RGB-D SLAM with the dynamic-object filter over a TUM folder
// or an MRPT rawlog; prints a summary and writes trajectories, maps and plots.
//
//   devslam-run                                   # data/tum/fr1_xyz_first37, dynamic mode
//   devslam-run --input DIR|FILE.rawlog --mode none|all_persons|dynamic|truth
//               --config config_ini/slam_tum_fr1.ini --out DIR
//   devslam-run --bench 5                         # all modes x 5 runs -> docs/RESULTS.md
#include "GivenTruthReader.h"
#include "MaskSource.h"
#include "Pipeline.h"
#include "ReplayReader.h"

#include <devslam/core/Config.h>
#include <devslam/core/Interrupt.h>
#include <devslam/core/Parse.h>
#include <devslam/core/Results.h>
#include <devslam/core/Stats.h>
#include <devslam/io/TrajectoryIO.h>
#include <devslam/slam/MapFile.h>

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using namespace devslam;

namespace {

const char* kUsage =
    "usage: devslam-run [--input PATH] [--mode none|all_persons|dynamic|truth] [--config INI]\n"
    "                   [--out DIR] [--max-frames N] [--quiet] [--set SECTION.KEY=VALUE]...\n"
    "                   [--replay N]  (play the input forward/backward N times)\n"
    "                   [--groundtruth FILE]  (TUM trajectory to score against: a rawlog\n"
    "                                          holds none; replaces a TUM folder's)\n"
    "                   [--localize MAP]  (localization only, in the slam_map.yml an earlier\n"
    "                                      run wrote: poses in that map's frame, the map\n"
    "                                      kept as it is)\n"
    "                   [--extend-map]  (with --localize: map on from the first pose\n"
    "                                    found in it, in its frame)\n"
    "                   [--no-slam-map]  (write the other outputs, not slam_map.yml)\n"
    "                   [--check-config]  (read the INIs as a run would, make the filter,\n"
    "                                      print 'ok' and stop; reads no frame, only\n"
    "                                      the camera of an input that exists)\n"
    "                   [--allow-damaged]  (a rawlog cut short, a TUM folder missing images,\n"
    "                                       frames that do not decode: run on what is intact)\n"
    "       devslam-run --bench N [--input PATH] [--config INI] [--results FILE]\n"
    "                   [--section NAME] [--modes-only]  (--results none: print the\n"
    "                   section only)\n"
    "defaults: --input " DEVSLAM_SOURCE_DIR
    "/data/tum/fr1_xyz_first37\n"
    "          --config " DEVSLAM_SOURCE_DIR
    "/config_ini/slam_tum_fr1.ini\n"
    "          --mode from the INI's [run] mode (dynamic), --out ./out/devslam-run,\n"
    "          --max-frames 0 (every frame)\n"
    "          (--out '' writes no files: the summary only)\n"
    "mode truth (diagnostic, devslam-synth folders only): the mask is the renderer's\n"
    "walking people, dilated by [dynamic_filter] mask_margin - a perfect filter.\n";

struct Args {
    std::string input = std::string(DEVSLAM_SOURCE_DIR) + "/data/tum/fr1_xyz_first37";
    std::string config = std::string(DEVSLAM_SOURCE_DIR) + "/config_ini/slam_tum_fr1.ini";
    std::string mode;  // empty: from INI
    std::string out = "out/devslam-run";
    std::string results = std::string(DEVSLAM_SOURCE_DIR) + "/docs/RESULTS.md";
    std::size_t max_frames = 0;
    int bench = 0;
    bool quiet = false;
    std::vector<std::string> sets;  ///< INI overrides "section.key=value"
    int replay = 0;                 ///< > 0: ReplayReader with that many passes
    std::string section = "slam";   ///< RESULTS.md section written by --bench
    bool modes_only = false;        ///< --bench without the ablation and the long run
    bool allow_damaged = false;     ///< a damaged input: run on what is intact
    std::string groundtruth;        ///< --groundtruth: the input's ground truth from this file
    std::string localize;           ///< --localize: a saved map to localize in
    bool extend_map = false;        ///< --extend-map: and map on from there
    bool no_slam_map = false;       ///< --no-slam-map: no slam_map.yml
    bool check_config = false;      ///< --check-config: the INIs only, no run
    bool out_given = false;         ///< --out was on the command line
    bool results_given = false;     ///< --results was on the command line
    bool section_given = false;     ///< --section was on the command line
};

Args parse(int argc, char** argv) {
    Args a;
    auto value = [&](int& i) { return core::optionValue(argc, argv, i); };
    devslam::core::refuseRepeatedOptions(argc, argv, {"--set"});
    for (int i = 1; i < argc; ++i) {
        const std::string k = argv[i];
        if (k == "--input")
            a.input = value(i);
        else if (k == "--mode")
            a.mode = value(i);
        else if (k == "--config")
            a.config = value(i);
        else if (k == "--out") {
            a.out = value(i);
            a.out_given = true;
        } else if (k == "--results") {
            a.results = value(i);
            a.results_given = true;
        } else if (k == "--max-frames")
            a.max_frames = std::size_t(core::parseInteger(value(i), "--max-frames", 0));
        else if (k == "--bench")
            a.bench = int(core::parseInteger(value(i), "--bench", 1, 1000));
        else if (k == "--quiet")
            a.quiet = true;
        else if (k == "--section") {
            a.section = value(i);
            a.section_given = true;
        } else if (k == "--modes-only")
            a.modes_only = true;
        else if (k == "--replay")
            a.replay = int(core::parseInteger(value(i), "--replay", 1, 1000));
        else if (k == "--set")
            a.sets.push_back(value(i));
        else if (k == "--allow-damaged")
            a.allow_damaged = true;
        else if (k == "--groundtruth") {
            a.groundtruth = value(i);
            if (a.groundtruth.empty()) throw std::invalid_argument("--groundtruth: no file named");
        } else if (k == "--localize") {
            a.localize = value(i);
            if (a.localize.empty()) throw std::invalid_argument("--localize: no map named");
        } else if (k == "--extend-map")
            a.extend_map = true;
        else if (k == "--no-slam-map")
            a.no_slam_map = true;
        else if (k == "--check-config")
            a.check_config = true;
        else if (k == "-h" || k == "--help") {
            std::cout << kUsage;
            std::exit(0);
        } else
            throw std::invalid_argument("unknown argument '" + k + "'\n" + kUsage);
    }
    if (a.check_config && a.bench > 0)
        throw std::invalid_argument("--check-config does not go with --bench");
    if (a.extend_map && a.localize.empty())
        throw std::invalid_argument("--extend-map extends the map --localize names; none named");
    if (!a.localize.empty() && a.bench > 0)
        throw std::invalid_argument("--localize does not go with --bench (it makes its maps)");
    if (!a.groundtruth.empty() && a.bench > 0)
        throw std::invalid_argument(
            "--groundtruth does not go with --bench (its inputs carry their own)");
    // Found now, not when the run's results are written (after the whole run): a file where
    // the folder or one above it goes, or a folder it cannot be made in. Nothing is created.
    // (--bench writes no run folder: its default --out, relative to where it was started,
    // refused a bench started in a folder it cannot write in)
    if (a.bench == 0 && !a.out.empty() && !a.check_config) {
        namespace fs = std::filesystem;
        const fs::path full = fs::absolute(a.out).lexically_normal();
        if (fs::exists(full) && !fs::is_directory(full))
            throw std::invalid_argument("--out '" + a.out + "': a file is there, not a folder");
        const fs::path p = core::nearestExisting(a.out);
        if (!fs::is_directory(p))
            throw std::invalid_argument("--out '" + a.out + "': '" + p.string() +
                                        "' is a file, not a folder");
        if (!core::canMakeFilesIn(p))
            throw std::invalid_argument("--out '" + a.out + "': cannot write in '" + p.string() +
                                        "'");
    }
    if (a.bench == 0)
        for (const auto& [given, option] : {std::pair{a.results_given, "--results"},
                                            {a.section_given, "--section"},
                                            {a.modes_only, "--modes-only"}})
            if (given)
                throw std::invalid_argument(std::string(option) +
                                            " goes with --bench N only (a single run writes no "
                                            "table)");
    if (a.bench > 0) {
        // Its table says it ran the INI as it is on every frame of the input, in all modes.
        for (const auto& [given, option] : {std::pair{a.max_frames > 0, "--max-frames"},
                                            {!a.sets.empty(), "--set"},
                                            {!a.mode.empty(), "--mode"},
                                            {a.replay > 0, "--replay"},
                                            {a.out_given, "--out"},
                                            {a.allow_damaged, "--allow-damaged"}})
            if (given)
                throw std::invalid_argument(std::string(option) +
                                            " does not go with --bench, whose table is of the "
                                            "INI as it is on the whole input, in every mode "
                                            "(write another INI for other settings)");
        // Its own sections only (another command's would be replaced), checked before the work.
        if (a.section != "slam" && a.section != "slam-synthetic")
            throw std::invalid_argument("--section '" + a.section +
                                        "': devslam-run writes 'slam' or 'slam-synthetic'");
        if (a.results != "none") core::checkResultsSection(a.results, a.section);
    }
    return a;
}

struct Loaded {
    std::unique_ptr<mrpt::config::CConfigFileMemory> cfg, filter_cfg;
    io::ReaderOptions reader;
    std::string mode;
    bool async_filter = true;
    std::string config_source, filter_source;  ///< RunConfig's, for the INIs' errors
};

/// Applies --set "section.key=value" overrides to an INI held in memory.
void applySets(mrpt::config::CConfigFileMemory& cfg, const std::vector<std::string>& sets) {
    core::applyOverrides(cfg, sets, "--set");
}

Loaded loadConfig(const Args& a, const std::vector<std::string>& extra_sets = {}) {
    Loaded l;
    l.cfg = core::loadIni(a.config);
    // Every section the run reads: a mistyped one would be ignored with all of its keys. The
    // filter's are in this file when [run] filter_config names none, and --set reaches both.
    std::vector<std::string> sections = slam::SlamOptions::sections();
    sections.insert(sections.end(), {"run", "dataset", "grid_map"});
    std::vector<std::string> with_filter = sections;
    with_filter.insert(with_filter.end(), core::filterSections().begin(),
                       core::filterSections().end());
    core::requireKnownSections(
        *l.cfg, l.cfg->read_string("run", "filter_config", "").empty() ? with_filter : sections,
        a.config);
    // An empty file, or the filter's INI given for the SLAM's, ran on the code's defaults.
    if (std::none_of(sections.begin(), sections.end(),
                     [&](const std::string& s) { return l.cfg->sectionExists(s); }))
        throw std::invalid_argument(a.config +
                                    ": none of a SLAM INI's sections ([run], [dataset], [orb], "
                                    "[tracker], ...): is it one? (the shipped ones are "
                                    "config_ini/slam_*.ini)");
    applySets(*l.cfg, a.sets);
    applySets(*l.cfg, extra_sets);
    core::requireKnownSections(*l.cfg, with_filter, "--set");
    const bool set = !a.sets.empty() || !extra_sets.empty();
    l.config_source = a.config + (set ? " with --set" : "");
    core::requireKnownKeys(*l.cfg, "run",
                           {"mode", "filter_config", "filter_overrides", "async_filter"},
                           l.config_source);
    l.filter_source = core::filterSource(*l.cfg, a.config);
    if (set)
        l.filter_source +=
            l.filter_source.find(" with ") == std::string::npos ? " with --set" : " and --set";
    l.async_filter = core::namingSource(
        l.config_source, [&] { return core::readBool(*l.cfg, "run", "async_filter", true); });
    // The INI's mode is checked when --mode overrides it too: "dynamik" there went unnoticed
    // by every devslam-bench run (which always passes --mode) until a run without --mode.
    const std::string ini_mode = l.cfg->read_string("run", "mode", "dynamic");
    for (const auto& [mode, where] : {std::pair{ini_mode, l.config_source + " [run] mode"},
                                      std::pair{a.mode, std::string("--mode")}}) {
        if (mode.empty() && where == "--mode") continue;  // no --mode (an empty INI mode is bad)
        try {
            run::requireMode(mode);
        } catch (const std::invalid_argument& e) {
            throw std::invalid_argument(where + ": " + e.what());
        }
    }
    l.mode = a.mode.empty() ? ini_mode : a.mode;
    // [run] filter_config / filter_overrides: the filter's INI, with "section.key=value ..."
    // overrides (so a SLAM config can pick e.g. the detection interval without copying it).
    // (Its errors name a.config, which filter_config is relative to; a value --set gave is
    // named as such, as the other keys' are.)
    try {
        l.filter_cfg = core::loadFilterIni(*l.cfg, a.config);
    } catch (const std::exception& e) {
        const std::string msg = e.what();
        if (!set || msg.rfind(a.config + " [run]", 0) != 0) throw;
        throw std::invalid_argument(l.config_source + msg.substr(a.config.size()));
    }
    applySets(*l.filter_cfg, a.sets);
    applySets(*l.filter_cfg, extra_sets);
    core::namingSource(l.config_source, [&] { l.reader.loadFromConfig(*l.cfg, "dataset"); });
    l.reader.allow_damaged = a.allow_damaged;
    return l;
}

/// The input reader, wrapped in a ReplayReader when asked. A Ctrl-C while a rawlog is read
/// through as it opens stops it there (io::OpeningStopped); `progress`: the opening's bar on
/// stderr.
std::unique_ptr<io::RgbdReader> openInput(const std::string& input, const io::ReaderOptions& ro,
                                          int replay, bool progress = false,
                                          const std::optional<core::Trajectory>& truth = {},
                                          const std::string& truth_path = {}) {
    std::unique_ptr<io::RgbdReader> reader =
        io::openRgbdWithProgress(input, ro, progress ? stderr : nullptr);
    if (truth)  // (before the replay, which maps it with the frames)
        reader = std::make_unique<run::GivenTruthReader>(std::move(reader), *truth, truth_path);
    if (replay <= 0) return reader;
    return std::make_unique<run::ReplayReader>(*reader, replay, ro.allow_damaged);
}

/// A run of `mode` with the loaded INIs and the command line's input and frame limit,
/// without a progress bar or an output folder (the callers set what differs).
run::RunConfig runConfig(const Args& a, const Loaded& l, const std::string& mode) {
    run::RunConfig rc;
    rc.config_source = l.config_source;
    rc.filter_source = l.filter_source;
    rc.input = a.input;
    rc.mode = mode;
    rc.progress = false;
    rc.max_frames = a.max_frames;
    rc.async_filter = l.async_filter;
    return rc;
}

/// --localize's map, read and checked against the INI's [orb] (nullptr without --localize):
/// before the input opens, so that a bad map is named at once.
std::shared_ptr<slam::MapFile> loadLocalizeMap(const Args& a, const Loaded& l) {
    if (a.localize.empty()) return nullptr;
    auto m = std::make_shared<slam::MapFile>(slam::loadMap(a.localize));
    if (m->map.empty() || m->map.landmarks().empty())
        throw std::invalid_argument(a.localize + ": the map has no " +
                                    (m->map.empty() ? "keyframe" : "landmark") + " to localize in");
    slam::checkOrbMatches(*m, a.localize, slam::SlamOptions::fromConfig(*l.cfg).orb);
    return m;
}

/// --check-config: every setting of the INIs read and the filter made, as before a run's
/// first frame (devslam-bench asks this of each SLAM INI before its renders), and the
/// frame size of an input that exists (its camera, no frame read) against the filter's.
int checkOnly(const Args& a) {
    const auto l = loadConfig(a);
    if (!a.groundtruth.empty()) (void)io::readTumTrajectory(a.groundtruth);
    (void)loadLocalizeMap(a, l);
    std::optional<core::CameraIntrinsics> camera;
    if (fs::exists(a.input)) camera = openInput(a.input, l.reader, 0)->intrinsics();
    run::checkConfig(runConfig(a, l, l.mode), *l.cfg, *l.filter_cfg, camera);
    std::cout << "ok: " << l.config_source << " (filter: " << l.filter_source << "), mode "
              << l.mode << "\n";
    return 0;
}

int runOnce(const Args& a) {
    auto l = loadConfig(a);
    // The replay gives its frames new stamps, and the truth mask is looked up by stamp.
    if (a.replay > 0 && l.mode == "truth")
        throw std::invalid_argument(
            "--replay with mode truth: the renderer's person truth is found by the frames' "
            "stamps, which the replay makes anew; replay another mode");
    // Read before the input, which may take seconds to open: a bad file is named at once.
    std::optional<core::Trajectory> truth;
    if (!a.groundtruth.empty()) truth = io::readTumTrajectory(a.groundtruth);
    auto map = loadLocalizeMap(a, l);
    std::unique_ptr<io::RgbdReader> reader;
    try {
        reader = openInput(a.input, l.reader, a.replay, !a.quiet, truth, a.groundtruth);
    } catch (const io::OpeningStopped&) {
        std::cerr << "devslam-run: interrupted (" << core::signalName(core::stopSignal())
                  << ") while opening the input; nothing written\n";
        return 1;
    }
    if (const std::string lost = reader->damage(); !lost.empty())
        std::cerr << "devslam-run: WARNING: running on the intact part of the input only: " << lost
                  << "\n";
    auto rc = runConfig(a, l, l.mode);
    rc.out_dir = a.out;
    rc.truth_file = a.groundtruth;
    rc.localize_in = std::move(map);
    rc.localize_map = a.localize;
    rc.extend_map = a.extend_map;
    rc.save_map = !a.no_slam_map;
    rc.progress = !a.quiet;
    rc.allow_damaged = a.allow_damaged;
    rc.score_masks = a.replay <= 0;
    // The folder is this run's until it ends: a second run into it at once is refused (the
    // two mixed their files). Taken before the frames, as are its outputs' names.
    std::optional<core::FolderClaim> claim;
    if (!a.out.empty()) {
        claim.emplace(a.out);
        run::checkOutputFolder(a.out);
    }
    const auto rep = run::runSequence(*reader, rc, *l.cfg, *l.filter_cfg);
    if (!rep.interrupted.empty() && rep.frames == 0) {
        std::cerr << "devslam-run: interrupted (" << rep.interrupted
                  << ") before the first frame; nothing written\n";
        return 1;
    }
    std::cout << run::formatSummary(rep);
    // Outputs the disk did not take: named, after the figures (whole, above).
    for (const auto& e : rep.output_errors) std::cerr << "devslam-run: " << e << "\n";
    if (!rep.output_errors.empty() && rep.out_dir.empty() && !a.out.empty())
        std::cerr << "devslam-run: nothing of this run was written; " << a.out
                  << " keeps the whole run that was there; the figures above are whole\n";
    else if (!rep.output_errors.empty())
        std::cerr << "devslam-run: " << rep.output_errors.size() << " of the run's outputs in "
                  << rep.out_dir << " were not written, nor run.json (which says they are whole); "
                  << "the figures above are whole\n";
    const std::string kept = rep.out_dir.empty() ? std::string()
                             : rep.out_dir == a.out
                                 ? "; " + a.out + " holds their results"
                                 : "; " + rep.out_dir + " holds their results (" + a.out +
                                       " keeps the whole run that was there)";
    if (!rep.read_error.empty()) {
        std::cerr << "devslam-run: " << rep.read_error << "\ndevslam-run: stopped after "
                  << rep.frames << " frames" << kept << "\n";
        return 1;
    }
    if (!rep.interrupted.empty()) {
        std::cerr << "devslam-run: interrupted (" << rep.interrupted << ") after " << rep.frames
                  << " frames" << kept << "\n";
        return 1;
    }
    if (core::stopSignal())  // it came after the last frame was read (finalize, outputs)
        std::cerr << "devslam-run: " << core::signalName(core::stopSignal())
                  << " came after the last frame; the run is whole\n";
    // An earlier stopped run's outputs, kept beside the run they did not replace, stayed
    // there unmentioned once a whole run replaced that one: said, and left.
    if (!rep.out_dir.empty() && rep.out_dir == a.out &&
        std::filesystem::is_directory(std::filesystem::path(a.out) / "stopped_run"))
        std::cerr << "devslam-run: note: "
                  << (std::filesystem::path(a.out) / "stopped_run").string()
                  << " holds an earlier run that stopped early, not this one\n";
    if (!rep.output_errors.empty()) return 1;
    // Every frame lost: the run is whole, but a script that went on (devslam-eval, a
    // navigation run on its map) met an empty trajectory; it said 0 until 2026-12-08.
    if (rep.lost.size() == rep.frames) {
        std::cerr << "devslam-run: no frame took a pose: "
                  << (rep.frames == 0   ? std::string("the input gave no frame")
                      : rep.frames == 1 ? std::string("the one frame was lost")
                                        : "all " + std::to_string(rep.frames) + " frames were lost")
                  << (rep.localize_map.empty() ? std::string()
                                               : " (not localized in " + rep.localize_map + ")")
                  << (rep.log.empty() ? std::string()
                                      : "; the first: " + rep.log.front().lost_reason)
                  << "; exit status " << core::kExitNoPose << "\n";
        return core::kExitNoPose;
    }
    return 0;
}

std::string fmt(double v, int p) {
    char b[32];
    std::snprintf(b, sizeof b, "%.*f", p, v);
    return b;
}

/// Throws unless `rep` covers the whole input: a bench over part of it would mislead (a frame
/// that did not read, a Ctrl-C), so the bench writes nothing.
void requireWhole(const run::RunReport& rep) {
    if (!rep.read_error.empty()) throw std::runtime_error(rep.read_error);
    if (!rep.interrupted.empty())
        throw std::runtime_error("interrupted (" + rep.interrupted + "); the bench wrote nothing");
}

/// The bench section's title and the head of its mode table.
std::string benchHeader(const Args& a) {
    // The command that makes the section again, run from the repository: every option that
    // is not its default (the paths relative to the repository when they lie in it).
    const Args defaults;
    const std::string root = DEVSLAM_SOURCE_DIR;
    const auto path_option = [&](const char* option, const std::string& p, const std::string& d) {
        return fs::path(p).lexically_normal() == fs::path(d).lexically_normal()
                   ? std::string()
                   : std::string(" ") + option + " " + core::shownPath(p, root);
    };
    const bool rendered = fs::is_regular_file(fs::path(a.input) / "render.txt");
    std::ostringstream md;
    md << "## SLAM (`devslam-run --bench " << a.bench << (a.modes_only ? " --modes-only" : "")
       << (a.section != "slam" ? " --section " + a.section : std::string())
       << path_option("--config", a.config, defaults.config)
       << path_option("--input", a.input, defaults.input) << "`)\n\n"
       << "Sequence `" << fs::path(a.input).filename().string() << "`"
       << (rendered ? " (rendered by devslam-synth; its render.txt says how, docs/slam.md gives "
                      "the command)"
                    : "")
       << ", config `" << fs::path(a.config).filename().string() << "`, " << a.bench
       << " runs per mode, medians over runs. FPS = whole pipeline per frame (detector, filter, "
          "features, tracking, mapping, back end; image decoding excluded). ATE over every frame "
          "(lost frames included), TUM-exact (devslam::eval).\n\n"
       << "| mode | ATE RMSE [m] | ATE max [m] | RPE 1 frame [m] | median FPS | mean FPS | "
          "median CPU ms/frame | keyframes | landmarks | lost | peak RSS [MB] | map KiB/keyframe "
          "|\n"
       << "|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    return md.str();
}

/// One mode's figures over the bench's runs.
struct ModeRuns {
    std::vector<double> ate, ate_max, rpe, mfps, afps, cpu, kfs, lms, lost, rss, kib;
    std::vector<double> st[6], stm[6];  // per-stage median / mean ms

    void add(const run::RunReport& rep) {
        if (rep.ate) {
            ate.push_back(rep.ate->trans.rmse);
            ate_max.push_back(rep.ate->trans.max);
        }
        if (rep.rpe_frame) rpe.push_back(rep.rpe_frame->trans.rmse);
        mfps.push_back(rep.median_fps);
        afps.push_back(rep.mean_fps);
        cpu.push_back(rep.median_cpu_ms);
        kfs.push_back(static_cast<double>(rep.keyframes));
        lms.push_back(static_cast<double>(rep.landmarks));
        lost.push_back(static_cast<double>(rep.lost.size()));
        rss.push_back(rep.peak_rss_mb);
        kib.push_back(rep.bytes_per_keyframe / 1024.0);
        const auto& m = rep.stage_median_ms;
        const double v[6] = {m.detect, m.filter, m.features, m.tracking, m.mapping, m.backend};
        for (int k = 0; k < 6; ++k) st[k].push_back(v[k]);
        const auto& mm = rep.stage_mean_ms;
        const double w[6] = {mm.detect,   mm.filter,  mm.features,
                             mm.tracking, mm.mapping, mm.backend};
        for (int k = 0; k < 6; ++k) stm[k].push_back(w[k]);
    }
    /// The mode table's row: medians over the runs.
    [[nodiscard]] std::string row(const std::string& mode) const {
        using core::median;
        std::ostringstream md;
        md << "| " << mode << " | " << (ate.empty() ? "-" : fmt(median(ate), 4)) << " | "
           << (ate_max.empty() ? "-" : fmt(median(ate_max), 4)) << " | "
           << (rpe.empty() ? "-" : fmt(median(rpe), 4)) << " | " << fmt(median(mfps), 1) << " | "
           << fmt(median(afps), 1) << " | " << fmt(median(cpu), 1) << " | " << fmt(median(kfs), 0)
           << " | " << fmt(median(lms), 0) << " | " << fmt(median(lost), 0) << " | "
           << fmt(median(rss), 0) << " | " << fmt(median(kib), 0) << " |\n";
        return md.str();
    }
    /// The per-stage table's row.
    [[nodiscard]] std::string stageRow(const std::string& mode) const {
        std::ostringstream md;
        md << "| " << mode;
        for (int k = 0; k < 6; ++k)
            md << " | " << fmt(core::median(st[k]), 2) << " / " << fmt(core::median(stm[k]), 2);
        md << " |\n";
        return md.str();
    }
};

/// The three modes, a.bench runs each: the mode table's rows, then the per-stage table.
std::string benchModes(const Args& a) {
    std::ostringstream md, stages;
    stages << "\nPer-stage time [ms], median / mean over frames (median over runs); with detection "
              "every 3rd frame the median frame runs no detector, the mean shows its cost:\n\n"
           << "| mode | detect | filter | features | tracking | mapping | backend |\n"
           << "|---|---|---|---|---|---|---|\n";
    for (const std::string mode : {"none", "all_persons", "dynamic"}) {
        ModeRuns runs;
        for (int r = 0; r < a.bench; ++r) {
            auto l = loadConfig(a);
            auto reader = openInput(a.input, l.reader, 0);
            const auto rc = runConfig(a, l, mode);
            const auto rep = run::runSequence(*reader, rc, *l.cfg, *l.filter_cfg);
            requireWhole(rep);
            runs.add(rep);
            std::cerr << "bench " << mode << " run " << r + 1 << "/" << a.bench << ": ATE "
                      << (rep.ate ? fmt(rep.ate->trans.rmse, 4) : "-") << " m, median "
                      << fmt(rep.median_fps, 1) << " FPS\n";
        }
        md << runs.row(mode);
        stages << runs.stageRow(mode);
    }
    return md.str() + stages.str();
}

/// Ablation: one design choice changed at a time (mode none; ATE is deterministic).
std::string benchAblations(const Args& a) {
    std::ostringstream abl;
    abl << "\nAblation (mode none, one run each, `devslam-run --mode none --set KEY=VALUE`):\n\n"
        << "| change | ATE RMSE [m] | keyframes | median FPS |\n|---|---|---|---|\n";
    const std::vector<std::pair<std::string, std::vector<std::string>>> ablations = {
        {"(defaults of the INI)", {}},
        {"orb.depth_factor=0.9662 (depth scaled by 1/1.035)", {"orb.depth_factor=0.9662"}},
        {"mapping.depth_time_compensation=false", {"mapping.depth_time_compensation=false"}},
        {"mapping.refine_frames=false", {"mapping.refine_frames=false"}},
        {"local_ba.enabled=false", {"local_ba.enabled=false"}},
        {"orb.n_levels=8, orb.scale_factor=1.2 (ORB-SLAM2 pyramid)",
         {"orb.n_levels=8", "orb.scale_factor=1.2"}},
        {"keyframes.max_frames=1 (every frame a keyframe)", {"keyframes.max_frames=1"}},
    };
    for (const auto& [name, sets] : ablations) {
        auto l = loadConfig(a, sets);
        auto reader = openInput(a.input, l.reader, 0);
        const auto rc = runConfig(a, l, "none");
        const auto rep = run::runSequence(*reader, rc, *l.cfg, *l.filter_cfg);
        requireWhole(rep);
        abl << "| " << name << " | " << (rep.ate ? fmt(rep.ate->trans.rmse, 4) : "-") << " | "
            << rep.keyframes << " | " << fmt(rep.median_fps, 1) << " |\n";
        std::cerr << "ablation " << name << ": ATE "
                  << (rep.ate ? fmt(rep.ate->trans.rmse, 4) : "-") << "\n";
    }
    return abl.str();
}

/// Memory on the longest sequence we have: the input replayed forward/backward.
std::string benchLongRun(const Args& a) {
    constexpr int kPasses = 9;
    auto l = loadConfig(a);
    auto src = openInput(a.input, l.reader, 0);
    run::ReplayReader reader(*src, kPasses, l.reader.allow_damaged);
    auto rc = runConfig(a, l, "dynamic");
    rc.max_frames = 0;       // every replayed frame
    rc.score_masks = false;  // replayed: timestamps are not the truth's
    const auto rep = run::runSequence(reader, rc, *l.cfg, *l.filter_cfg);
    requireWhole(rep);
    std::ostringstream mem;
    mem << "\nLong run (memory): the input replayed forward/backward " << kPasses
        << " times (`devslam-run --replay " << kPasses << " --mode dynamic`): " << rep.frames
        << " frames, " << rep.keyframes << " keyframes, " << rep.landmarks << " landmarks, "
        << rep.loops << " loops closed, " << rep.lost.size() << " lost; peak RSS "
        << fmt(rep.peak_rss_mb, 0)
        << " MB (whole process: libraries, detector network, the source frames held by the "
           "replay), map "
        << fmt(rep.map_mb, 2) << " MB = " << fmt(rep.bytes_per_keyframe / 1024.0, 0)
        << " KiB per keyframe (keypoints, descriptors, depths, landmarks); ATE "
        << (rep.ate ? fmt(rep.ate->trans.rmse, 4) : "-") << " m.\n";
    return mem.str();
}

int runBench(const Args& a) {
    std::string md = benchHeader(a) + benchModes(a);
    if (!a.modes_only) md += benchAblations(a) + benchLongRun(a);
    md +=
        "\nPeak RSS is per run (VmHWM reset before each run). Wall-clock FPS depends on the "
        "load and the drifting speed of this 2-core VM; the CPU time per frame (all threads) "
        "is printed by `devslam-run` beside it. Measured on " +
        core::measuredOnLine() + ".\n";
    // Printed first: a results file that cannot be written after the whole bench must not
    // take the table with it.
    std::cout << md << std::flush;
    if (a.results != "none") core::replaceResultsSection(a.results, a.section, md);
    return 0;
}

int runMain(int argc, char** argv) {
    try {
        const Args a = parse(argc, argv);
        if (a.check_config) return checkOnly(a);
        return a.bench > 0 ? runBench(a) : runOnce(a);
    } catch (const io::DamagedInput& e) {
        std::cerr << "devslam-run: " << e.what() << "\n";
        if (e.intact() > 0)
            std::cerr << "devslam-run: --allow-damaged runs on those " << e.intact()
                      << " intact frames\n";
        return 1;
    } catch (const std::exception& e) {
        std::cerr << "devslam-run: " << e.what() << "\n";
        return 1;
    }
}
}  // namespace

int main(int argc, char** argv) {
    core::installStopHandler("devslam-run");
    const int rc = runMain(argc, argv);
    // Stopped by Ctrl-C, after writing what was done: end by the signal, so that a shell
    // script running this stops too.
    if (const int sig = core::stopSignal()) core::exitBySignal(sig);
    return core::withStandardOutput("devslam-run", rc);  // its summary is the result
}
