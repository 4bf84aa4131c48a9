// Two-frame smoke test of the whole devslam-bench command: renders a synthetic sequence in
// two seeds and one without walkers, runs devslam-run in the three modes on the renders and
// on the shipped TUM frames (plus the diagnostic truth mask on the synthetic ones), scores the
// filter against the person truth, and writes the tables and the RESULTS section.
#include "RunJson.h"
#include "Targets.h"

#include <devslam/core/Config.h>
#include <devslam/io/TumReader.h>
#include <devslam/io/TumWriter.h>

#include <gtest/gtest.h>

#include "Command.h"
#include "Scratch.h"

#include <algorithm>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <optional>
#include <regex>
#include <sstream>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

namespace fs = std::filesystem;

namespace {
std::string readFile(const fs::path& p) {
    std::ifstream in(p);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}
/// Lines that are not '#' comments.
std::size_t countLines(const std::string& s) {
    std::istringstream in(s);
    std::size_t n = 0;
    for (std::string l; std::getline(in, l);) n += !l.empty() && l[0] != '#';
    return n;
}
}  // namespace

TEST(DevslamBench, TwoFrameSmokeRunOfTheWholeCommand) {
    const std::string root = DEVSLAM_SOURCE_DIR, bin = DEVSLAM_BIN_DIR;
    const fs::path tmp = devslam::test::scratchPath("devslam_bench_smoke");
    fs::remove_all(tmp);
    fs::create_directories(tmp);
    std::ofstream(tmp / "bench.ini")
        << "[bench]\nrepeats = 1\nmodes = none all_persons dynamic truth\n"
           "slam_config = "
        << root
        << "/config_ini/slam_synthetic.ini\n"
           "[sequence_short]\nscenario = short_walking\nseeds = 5 6\n"
           "set = person_1.speed=0.5 person_2.sway_deg=1  person_2.path=[3.5 2.8]\n"
           // Sitters only: its filter rows have no walkers to score.
           "[sequence_sit]\nscenario = sitting_xyz\nseeds = 7\n"
           "[sequence_fr1]\npath = "
        << root << "/data/tum/fr1_xyz_first37\nslam_config = " << root
        << "/config_ini/slam_tum_fr1.ini\n"
           "[targets]\na_fps = short dynamic fps >= 0.001\nb_fps = * dynamic fps >= 1e9\n"
           "c_ratio = fr1 dynamic ate/none <= 1e9\n";
    std::ofstream(tmp / "RESULTS.md") << "# Results\n";
    const std::string cmd =
        "'" + bin + "/devslam-bench' --config '" + (tmp / "bench.ini").string() +
        "' --max-frames 2 --out '" + (tmp / "out").string() + "' --results '" +
        (tmp / "RESULTS.md").string() + "' > '" + (tmp / "log.txt").string() + "' 2>&1";
    ASSERT_EQ(std::system(cmd.c_str()), 0) << readFile(tmp / "log.txt");
    // The synthetic sequence was rendered (2 frames) with its person truth, once per seed:
    // the same camera path, other noise.
    for (const char* render : {"out/synth/short_seed5", "out/synth/short_seed6"}) {
        EXPECT_TRUE(fs::exists(tmp / render / "persons.txt")) << render;
        EXPECT_EQ(countLines(readFile(tmp / render / "groundtruth.txt")), 2u) << render;
        // Renders run side by side, each with its output in its own log.
        EXPECT_NE(readFile(tmp / (std::string(render) + ".log")).find("frames 2 (30 Hz)"),
                  std::string::npos)
            << render;
    }
    EXPECT_EQ(readFile(tmp / "out/synth/short_seed5/groundtruth.txt"),
              readFile(tmp / "out/synth/short_seed6/groundtruth.txt"));
    // Each run's summary is in its log; a run without masks says so rather than scoring them.
    EXPECT_NE(readFile(tmp / "out/runs/short/none/seed5_r0/log.txt")
                  .find("masks      : none (mode none)"),
              std::string::npos);
    EXPECT_NE(readFile(tmp / "out/runs/short/dynamic/seed5_r0/log.txt")
                  .find("masks      : walking people masked in "),
              std::string::npos);
    // The sequence's `set` items reached devslam-synth (its render.txt records them).
    const std::string render_txt = readFile(tmp / "out/synth/short_seed5/render.txt");
    EXPECT_NE(render_txt.find("set person_1.speed=0.5"), std::string::npos) << render_txt;
    EXPECT_NE(render_txt.find("set person_2.sway_deg=1"), std::string::npos) << render_txt;
    EXPECT_NE(render_txt.find("set person_2.path=[3.5 2.8]"), std::string::npos) << render_txt;
    EXPECT_NE(readFile(tmp / "out/synth/short_seed5/depth/1700000400.000000.png"),
              readFile(tmp / "out/synth/short_seed6/depth/1700000400.000000.png"));
    // 4 modes on each render of short, 3 on sit (mode truth's mask would be empty: nobody
    // walks) and on fr1 (no person truth), 1 repeat, every run succeeded.
    const std::string runs = readFile(tmp / "out/runs.csv");
    EXPECT_EQ(countLines(runs), 1u + 8u + 3u + 3u) << runs;
    EXPECT_EQ(runs.find("sit,truth"), std::string::npos) << runs;
    EXPECT_NE(runs.find("short,truth,5,0,"), std::string::npos) << runs;
    EXPECT_NE(runs.find("short,truth,6,0,"), std::string::npos) << runs;
    EXPECT_NE(runs.find("fr1,dynamic,,0,"), std::string::npos) << runs;
    EXPECT_EQ(runs.find("fr1,truth"), std::string::npos) << runs;
    const std::string ate = readFile(tmp / "out/table2_ate.csv");
    EXPECT_EQ(countLines(ate), 1u + 4u + 3u + 3u);
    std::istringstream lines(ate);
    std::string line;
    std::getline(lines, line);  // header
    while (std::getline(lines, line))
        EXPECT_EQ(line.substr(line.rfind(',') + 1), line.rfind("short,", 0) == 0 ? "2" : "1")
            << line;
    for (const char* f : {"table1_rpe.csv", "table3_fps.csv", "filter_truth.csv", "tables.md"})
        EXPECT_TRUE(fs::exists(tmp / "out" / f)) << f;
    // Two frames give no ATE, so no run has a plot: no Trajectories heading over nothing.
    EXPECT_EQ(readFile(tmp / "out/tables.md").find("**Trajectories**"), std::string::npos);
    const std::string filter = readFile(tmp / "out/filter_truth.csv");
    EXPECT_EQ(countLines(filter), 1u + 2u + 2u) << filter;  // {short, sit} x {all_persons, dynamic}
    // A sequence without walkers has no walker figures (not "0 % of 0").
    EXPECT_NE(filter.find("\nsit,dynamic,n/a,n/a,"), std::string::npos) << filter;
    const std::string results = readFile(tmp / "RESULTS.md");
    EXPECT_NE(results.find("Table 1: RPE"), std::string::npos);
    EXPECT_NE(results.find("Table 2: ATE"), std::string::npos);
    EXPECT_NE(results.find("Table 3: speed"), std::string::npos);
    // The command that made the section, as it can be run again (the whole config path).
    EXPECT_NE(results.find("by `devslam-bench --config " + (tmp / "bench.ini").string() +
                           " --out '" + (tmp / "out").string() + "' --max-frames 2`"),
              std::string::npos)
        << results;
    // Sequences in the order bench.ini gives them (MRPT alone would sort them).
    EXPECT_NE(results.find("short 2 renders (seed 5 6) x 1 run, sit 1 render (seed 7) x 1 run, fr1 "
                           "1 run per mode"),
              std::string::npos)
        << results;
    EXPECT_NE(results.find("| short | dynamic | "), std::string::npos);
    EXPECT_NE(results.find("| sit | dynamic | n/a (no walkers) | n/a | "), std::string::npos)
        << results;
    EXPECT_NE(results.find("ATE RMSE (m) per render"), std::string::npos);
    // The targets, checked on the medians: one that every run meets, one that none can
    // ("*": the worst sequence shown), and one without a figure (two frames give no ATE),
    // which is not met.
    EXPECT_NE(results.find("| a_fps: short dynamic fps >= 0.001 | "), std::string::npos) << results;
    EXPECT_NE(results.find("| b_fps: * dynamic fps >= 1e+09 | "), std::string::npos) << results;
    EXPECT_NE(results.find("| c_ratio: fr1 dynamic ate/none <= 1e+09 | n/a | **no** | 0 of 0 |  |"),
              std::string::npos)
        << results;
    // Each render counted on its own figure: both renders of short meet a_fps; b_fps is
    // missed on both, on sit's render and on fr1 (one input).
    EXPECT_NE(results.find(" | yes | 2 of 2 |"), std::string::npos) << results;
    EXPECT_NE(results.find(" | **no** | 0 of 4 |"), std::string::npos) << results;
    // No target has a per-render interval here, so the count stands alone.
    EXPECT_NE(results.find("1 of 3 targets met on the medians.\n"), std::string::npos) << results;
    const std::string targets = readFile(tmp / "out/targets.csv");
    EXPECT_EQ(countLines(targets), 1u + 3u) << targets;
    const auto row = [&](const std::string& key) {
        const auto at = targets.find("\n" + key + ",");
        return at == std::string::npos
                   ? std::string()
                   : targets.substr(at + 1, targets.find('\n', at + 1) - at - 1);
    };
    EXPECT_EQ(row("a_fps").rfind("a_fps,short,dynamic,fps,>=,0.001,", 0), 0u) << targets;
    const auto endsWith = [](const std::string& a, const std::string& b) {
        return a.size() >= b.size() && a.compare(a.size() - b.size(), b.size(), b) == 0;
    };
    EXPECT_TRUE(endsWith(row("a_fps"), ",1,2,2,n/a,n/a,n/a,")) << targets;  // met, 2 of 2 renders
    EXPECT_TRUE(endsWith(row("b_fps"), ",0,0,4,n/a,n/a,n/a,")) << targets;
    // No paired ratio: fps is no ratio, and fr1 is one input without an ATE here.
    EXPECT_EQ(row("c_ratio"), "c_ratio,fr1,dynamic,ate/none,<=,1e+09,n/a,,0,0,0,n/a,n/a,n/a,")
        << targets;
    EXPECT_NE(results.find(" (seed 5), "), std::string::npos) << results;
    EXPECT_NE(results.find("Sequences: short is scenario `short_walking` with `devslam-synth "
                           "--set person_1.speed=0.5 --set person_2.sway_deg=1 --set "
                           "'person_2.path=[3.5 2.8]'`; sit is scenario `sitting_xyz`."),
              std::string::npos)
        << results;

    // --reuse-runs keeps whole runs and runs again one that stopped at a frame it could not
    // read (devslam-run's run.json then names it in read_error).
    const fs::path stopped = tmp / "out/runs/fr1/dynamic/r0/run.json";
    std::string js = readFile(stopped);
    const std::string key = "\"read_error\": \"\"";
    ASSERT_NE(js.find(key), std::string::npos) << js.substr(0, 300);
    js.replace(js.find(key), key.size(), "\"read_error\": \"x.png: cannot decode\"");
    std::ofstream(stopped) << js;
    // Another spelling of the output folder ("<tmp>/./out/") reuses them too (its runs'
    // command lines were compared as written).
    std::string again =
        cmd.substr(0, cmd.find(" > ")) + " --reuse-runs" + cmd.substr(cmd.find(" > "));
    ASSERT_NE(again.find("/out'"), std::string::npos);
    again.replace(again.find("/out'"), 5, "/./out/'");
    ASSERT_EQ(std::system(again.c_str()), 0) << readFile(tmp / "log.txt");
    // Their figures are from when their run.json files were written: the text says when.
    EXPECT_NE(readFile(tmp / "RESULTS.md")
                  .find("13 of 14 runs were kept from an earlier invocation that made them "
                        "(`--reuse-runs`: their figures, speed included, are from their "
                        "run.json files, written 20"),
              std::string::npos)
        << readFile(tmp / "RESULTS.md");
    EXPECT_NE(readFile(stopped).find(key), std::string::npos);
    fs::remove_all(tmp);
}

// run.json is read strictly: one whole JSON value, each scalar by its whole path, values in
// arrays checked but not kept.
TEST(RunJson, ScalarsAreFoundByTheirWholePath) {
    using devslam::bench::jsonScalars;
    const auto s = jsonScalars(
        R"({"a": {"b": 1.5e-3, "c": "x\"y", "e": {}}, "l": [1, {"d": 2}, []], "t": true,
            "n": null, "s": ""} )");
    ASSERT_TRUE(s);
    std::map<std::string, std::pair<bool, std::string>> got;
    for (const auto& [k, v] : *s) got[k] = {v.string, v.text};
    const std::map<std::string, std::pair<bool, std::string>> want{{"a.b", {false, "1.5e-3"}},
                                                                   {"a.c", {true, R"(x\"y)"}},
                                                                   {"t", {false, "true"}},
                                                                   {"n", {false, "null"}},
                                                                   {"s", {true, ""}}};
    EXPECT_EQ(got, want);
    for (const char* bad : {"", " ", "{", R"({"a": 1} x)", R"({"a" 1})", R"({"a": "b})",
                            R"({"a": [1,]})", R"({"a": 1,})", "{a: 1}", R"({"a": tru})"})
        EXPECT_FALSE(jsonScalars(bad)) << bad;
    EXPECT_TRUE(jsonScalars("3"));
}

// A figure the run has not is n/a, never the same key of another object: the ATE's median
// used to be found by searching for the first "median" after "ate", which in a run.json without
// one was the loop error's. A run.json without the keys devslam-run always writes is refused.
TEST(RunJson, EachFigureComesFromItsOwnObject) {
    using devslam::bench::readRun;
    devslam::test::TempDir d("devslam_run_json_");
    const std::string json = d.str("run.json");
    const std::string always =
        R"("median_fps": 41.5, "mean_fps": 40, "lost_frames": 2, "read_error": "",)";
    std::ofstream(json) << "{" << always << R"( "interrupted": "",
        "ate": {"rmse": 0.002}, "loop_error_m": {"mean": 9, "median": 9},
        "rpe_1s": {"trans": {"rmse": 0.003, "mean": 0.002, "median": 0.001}},
        "mask_truth": {"moving_recall": 0.9, "moving_instances": 0, "static_instances": 4,
                       "static_masked": 0.25, "precision": 0.5}})";
    auto f = readRun(json);
    EXPECT_TRUE(f.ok) << f.unreadable;
    EXPECT_EQ(f.ate_rmse, 0.002);
    EXPECT_TRUE(std::isnan(f.ate_mean));
    EXPECT_TRUE(std::isnan(f.ate_median));
    EXPECT_EQ(f.rpe_t_median, 0.001);
    EXPECT_TRUE(std::isnan(f.rpe_r_rmse));
    EXPECT_EQ(f.fps_median, 41.5);
    EXPECT_EQ(f.fps_mean, 40);
    EXPECT_EQ(f.lost, 2);
    EXPECT_TRUE(std::isnan(f.moving_recall));  // of no moving instance: undefined
    EXPECT_EQ(f.static_masked, 0.25);
    EXPECT_EQ(f.mask_precision, 0.5);

    std::ofstream(json) << "{" << always << R"( "interrupted": "SIGINT at frame 3"})";
    f = readRun(json);
    EXPECT_FALSE(f.ok);
    EXPECT_EQ(f.unreadable, "");  // a run that stopped, not a file that cannot be read

    std::ofstream(json) << R"({"mean_fps": 40, "lost_frames": 2, "read_error": "",
                             "interrupted": "", "ate": {"rmse": 0.002}})";
    f = readRun(json);
    EXPECT_FALSE(f.ok);
    EXPECT_EQ(f.unreadable, json + R"( has no "median_fps" (not a devslam-run run.json?))");

    f = readRun(d.str("nowhere.json"));
    EXPECT_FALSE(f.ok);
    EXPECT_EQ(f.unreadable, "");  // the run wrote nothing
}

// A target is checked on the medians over all renders, and counted render by render: a ratio
// compares the two modes on the same render.
TEST(BenchTargets, MediansDecideRendersAreCountedOneByOne) {
    using devslam::bench::Target;
    // ATE per (sequence, mode, seed); "r" is a real sequence (one input, no seed).
    const std::map<std::tuple<std::string, std::string, std::optional<std::uint64_t>>, double> ate =
        {{{"s", "dynamic", 1}, 1.0},
         {{"s", "all", 1}, 2.0},  // 0.5
         {{"s", "dynamic", 2}, 3.0},
         {{"s", "all", 2}, 2.0},  // 1.5
         {{"s", "dynamic", 3}, 2.5},
         {{"s", "all", 3}, 1.0},  // 2.5
         {{"r", "dynamic", std::nullopt}, 0.5},
         {{"r", "all", std::nullopt}, 1.0}};
    const auto median = [&](const std::string& seq, const std::string& mode,
                            std::optional<std::uint64_t> seed) -> double {
        std::vector<double> v;
        for (const auto& [k, x] : ate)
            if (std::get<0>(k) == seq && std::get<1>(k) == mode &&
                (!seed || std::get<2>(k) == seed))
                v.push_back(x);
        if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
        std::sort(v.begin(), v.end());
        return v.size() % 2 ? v[v.size() / 2] : (v[v.size() / 2 - 1] + v[v.size() / 2]) / 2;
    };
    const devslam::bench::FigureOf figure = [&](const std::string& seq, const std::string& mode,
                                                const std::string& fig,
                                                std::optional<std::uint64_t> seed) {
        if (fig == "ate") return median(seq, mode, seed);
        return median(seq, mode, seed) / median(seq, fig.substr(4), seed);  // ate/<mode>
    };
    const std::vector<devslam::bench::SequenceInputs> inputs = {{"s", {1, 2, 3}}, {"r", {}}};

    // Medians: s dynamic 2.5, all 2.0 -> 1.25, not met; yet one render of three meets it.
    const Target ratio{"k", "s", "dynamic", "ate/all", "<", 1.0};
    const auto c = devslam::bench::check(ratio, inputs, figure);
    EXPECT_DOUBLE_EQ(c.measured, 1.25);
    EXPECT_FALSE(c.met);
    const auto n = devslam::bench::tallyInputs(ratio, inputs, figure);
    EXPECT_EQ(n.met, 1);
    EXPECT_EQ(n.of, 3);
    // "*": every sequence's inputs; the worst median decides.
    const Target all{"k", "*", "dynamic", "ate", "<=", 2.0};
    const auto ca = devslam::bench::check(all, inputs, figure);
    EXPECT_EQ(ca.sequence, "s");
    EXPECT_DOUBLE_EQ(ca.measured, 2.5);
    const auto na = devslam::bench::tallyInputs(all, inputs, figure);
    EXPECT_EQ(na.met, 2);  // s seed 1 (1.0) and r (0.5)
    EXPECT_EQ(na.of, 4);
    // A figure no input has is counted nowhere.
    const Target none{"k", "s", "truth", "ate", "<=", 1.0};
    EXPECT_EQ(devslam::bench::tallyInputs(none, inputs, figure).of, 0);

    // The renders' own ratios, 0.5, 1.5 and 2.5: their geometric mean and its 95 % interval
    // (Student's t, 2 dof, on the logarithms), which holds 1: these renders tie the modes.
    const auto p = devslam::bench::pairedRatio(ratio, "s", inputs, figure);
    EXPECT_EQ(p.count, 3u);
    EXPECT_NEAR(p.geomean, std::cbrt(0.5 * 1.5 * 2.5), 1e-12);
    const std::vector<double> logs = {std::log(0.5), std::log(1.5), std::log(2.5)};
    const double mean = (logs[0] + logs[1] + logs[2]) / 3;
    double ss = 0;
    for (const double x : logs) ss += (x - mean) * (x - mean);
    const double half = 4.302652729911275 * std::sqrt(ss / 2 / 3);  // t(0.975, 2 dof)
    EXPECT_NEAR(p.lo, std::exp(mean - half), 1e-9);
    EXPECT_NEAR(p.hi, std::exp(mean + half), 1e-9);
    EXPECT_LT(p.lo, 1.0);
    EXPECT_GT(p.hi, 1.0);
    // The bound 1 inside the interval: open, whichever side the medians fall on.
    using devslam::bench::RenderVerdict;
    EXPECT_EQ(devslam::bench::renderVerdict(ratio, p), RenderVerdict::Open);
    // Bounds beyond either end of the interval: both ends meet it, or both miss it.
    const Target loose{"k", "s", "dynamic", "ate/all", "<", p.hi * 1.01};
    EXPECT_EQ(devslam::bench::renderVerdict(loose, p), RenderVerdict::Met);
    const Target tight{"k", "s", "dynamic", "ate/all", "<", p.lo * 0.99};
    EXPECT_EQ(devslam::bench::renderVerdict(tight, p), RenderVerdict::Missed);
    const Target above{"k", "s", "dynamic", "ate/all", ">=", p.lo * 0.99};
    EXPECT_EQ(devslam::bench::renderVerdict(above, p), RenderVerdict::Met);
    // The sentence under the table names the open ones and those the interval contradicts.
    EXPECT_EQ(devslam::bench::targetsSummary(7, 7, {}, {}), "7 of 7 targets met on the medians.");
    EXPECT_EQ(devslam::bench::targetsSummary(6, 7, {"a", "b", "c"}, {"d"}),
              "6 of 7 targets met on the medians. The per-render interval holds the bound of a, "
              "b and c: the renders do not settle these. The per-render interval lies wholly on "
              "the other side of the bound for d.");
    EXPECT_EQ(devslam::bench::targetsSummary(7, 7, {"a"}, {}),
              "7 of 7 targets met on the medians. The per-render interval holds the bound of a: "
              "the renders do not settle this one.");
    // A real sequence (one input, no renders), a plain figure: no paired ratio.
    EXPECT_EQ(devslam::bench::pairedRatio(ratio, "r", inputs, figure).count, 0u);
    EXPECT_EQ(devslam::bench::renderVerdict(
                  ratio, devslam::bench::pairedRatio(ratio, "r", inputs, figure)),
              RenderVerdict::None);
    const Target plain{"k", "s", "dynamic", "ate", "<=", 2.0};
    EXPECT_TRUE(std::isnan(devslam::bench::pairedRatio(plain, "s", inputs, figure).geomean));
}

// Ctrl-C during a bench reaches the bench and the devslam-run it waits for: the run stops
// (or ends first), the bench stops after it, keeping the finished runs and leaving the
// results file as it was, and the same command with --reuse-runs resumes.
TEST(DevslamBench, CtrlCStopsTheBenchAndReuseRunsResumes) {
    const std::string root = DEVSLAM_SOURCE_DIR;
    const fs::path tmp = devslam::test::scratchPath("devslam_bench_ctrl_c");
    fs::remove_all(tmp);
    fs::create_directories(tmp);
    // A copy of the config (with the filter config it names), changed at the end.
    fs::copy_file(root + "/config_ini/slam_tum_fr1.ini", tmp / "slam.ini");
    fs::copy_file(root + "/config_ini/dynamic_filter.ini", tmp / "dynamic_filter.ini");
    // Eight runs: the signal comes at the second, with six more to go even on a slow machine.
    std::ofstream(tmp / "bench.ini")
        << "[bench]\nrepeats = 8\nmodes = none\n"
        << "[sequence_fr1]\npath = " << root
        << "/data/tum/fr1_xyz_first37\nslam_config = " << (tmp / "slam.ini").string() << "\n";
    std::ofstream(tmp / "RESULTS.md") << "# Results\n";
    const std::string args = "--config " + (tmp / "bench.ini").string() + " --max-frames 3 --out " +
                             (tmp / "out").string() + " --results " + (tmp / "RESULTS.md").string();
    const auto r = devslam::test::signalAppWhen("devslam-bench", args, "[2/8]", SIGINT,
                                                (tmp / "log.txt").string());
    ASSERT_TRUE(r.signalled) << "the bench ended before the signal:\n" << r.out;
    EXPECT_EQ(r.rc, 130) << r.out;
    // "before run k" when the signal came before the bench started that run.
    EXPECT_TRUE(r.out.find("devslam-bench: interrupted (SIGINT) during run ") !=
                    std::string::npos ||
                r.out.find("devslam-bench: interrupted (SIGINT) before run ") != std::string::npos)
        << r.out;
    EXPECT_NE(r.out.find("the results file was left as it was"), std::string::npos) << r.out;
    EXPECT_EQ(readFile(tmp / "RESULTS.md"), "# Results\n");
    // The runs that finished; an interrupted one says so in its run.json and runs again.
    int finished = 0;
    for (int k = 0; k < 8; ++k) {
        const std::string js =
            readFile(tmp / "out/runs/fr1/none" / ("r" + std::to_string(k)) / "run.json");
        finished += !js.empty() && js.find("\"interrupted\": \"\"") != std::string::npos;
    }
    EXPECT_GE(finished, 1);
    EXPECT_LE(finished, 7);
    const auto resumed = devslam::test::runApp("devslam-bench", args + " --reuse-runs");
    EXPECT_EQ(resumed.rc, 0) << resumed.out;
    EXPECT_NE(readFile(tmp / "RESULTS.md")
                  .find(std::to_string(finished) + " of 8 runs were kept from an earlier"),
              std::string::npos)
        << readFile(tmp / "RESULTS.md");

    // A SIGINT sent to the bench alone lets the run finish, then stops the bench. The runs of
    // another command (here another frame count) are not kept: they run again.
    const std::string other =
        std::regex_replace(args, std::regex(" --max-frames 3"), " --max-frames 2") +
        " --reuse-runs";
    const auto alone = devslam::test::signalAppWhen("devslam-bench", other, "[2/8]", SIGINT,
                                                    (tmp / "log2.txt").string(), false);
    ASSERT_TRUE(alone.signalled) << "the bench ended before the signal:\n" << alone.out;
    EXPECT_EQ(alone.rc, 130) << alone.out;
    EXPECT_NE(alone.out.find("not kept: its run.json was made by another command (command.txt)"),
              std::string::npos)
        << alone.out;
    // The run it was in finished whole (or, had the signal come before the bench started run
    // 2, the first); either way with this command's 2 frames.
    std::smatch stop;
    ASSERT_TRUE(std::regex_search(
        alone.out, stop,
        std::regex(R"(devslam-bench: interrupted \(SIGINT\) (during|before) run (\d+) of 8)")))
        << alone.out;
    const int last = std::stoi(stop[2].str()) - (stop[1] == "during" ? 1 : 2);
    const std::string js =
        readFile(tmp / "out/runs/fr1/none" / ("r" + std::to_string(last)) / "run.json");
    EXPECT_NE(js.find("\"interrupted\": \"\""), std::string::npos) << js.substr(0, 300);
    EXPECT_NE(js.find("\"frames\": 2,"), std::string::npos) << js.substr(0, 300);

    // Finished, then the config changes, keeping its old time (as `cp -p` or `tar x` do): the
    // runs made from the old content are not kept.
    ASSERT_EQ(devslam::test::runApp("devslam-bench", other).rc, 0);
    const auto when = fs::last_write_time(tmp / "slam.ini");
    std::ofstream(tmp / "slam.ini", std::ios::app) << "# changed\n";
    fs::last_write_time(tmp / "slam.ini", when);
    const auto changed = devslam::test::runApp("devslam-bench", other);
    EXPECT_EQ(changed.rc, 0) << changed.out;
    EXPECT_NE(changed.out.find("not kept: its run.json was made from another " +
                               (tmp / "slam.ini").string() + " (its content changed since)"),
              std::string::npos)
        << changed.out;
    EXPECT_EQ(readFile(tmp / "RESULTS.md").find("runs were kept"), std::string::npos);

    // A run made on another machine (an out/ folder carried over): other kernels, other
    // trajectories and speeds; not kept (it was, and its figures passed for this machine's).
    const fs::path cmd_txt = tmp / "out/runs/fr1/none/r0/command.txt";
    std::string made = readFile(cmd_txt);
    const auto at = made.find("\nmachine: ");
    ASSERT_NE(at, std::string::npos) << made;
    made.replace(at + 1, made.find('\n', at + 1) - at - 1,
                 "machine: 2 hardware threads, Imaginary CPU (family 0 model 0), OpenCV SIMD AVX2");
    std::ofstream(cmd_txt, std::ios::trunc) << made;
    const auto moved = devslam::test::runApp("devslam-bench", other);
    EXPECT_EQ(moved.rc, 0) << moved.out;
    EXPECT_NE(moved.out.find("not kept: its run.json was made on another machine (2 hardware "
                             "threads, Imaginary CPU (family 0 model 0), OpenCV SIMD AVX2)"),
              std::string::npos)
        << moved.out;
    EXPECT_NE(readFile(tmp / "RESULTS.md").find("7 of 8 runs were kept from an earlier"),
              std::string::npos)
        << readFile(tmp / "RESULTS.md");
    fs::remove_all(tmp);
}

// A bad bench INI stops the bench before anything runs, naming the file, section and key.
// --reuse-runs kept a run whose run.json was garbage or empty (its figures n/a, "runs ok
// 1/1", no word): such a run is not kept but made again, with a warning naming the file.
TEST(DevslamBench, ReuseRunsDoesNotKeepAnUnreadableRunJson) {
    const std::string root = DEVSLAM_SOURCE_DIR;
    const devslam::test::TempDir d("devslam_");
    const fs::path tmp = d.str();
    std::ofstream(tmp / "bench.ini")
        << "[bench]\nmodes = none\nrepeats = 1\nmax_frames = 3\n[sequence_tiny]\npath = " << root
        << "/data/tum/fr1_xyz_first37\nslam_config = " << root << "/config_ini/slam_tum_fr1.ini\n";
    const std::string args = "--config '" + (tmp / "bench.ini").string() +
                             "' --results none --out '" + (tmp / "out").string() + "'";
    const fs::path json = tmp / "out/runs/tiny/none/r0/run.json";
    auto r = devslam::test::runApp("devslam-bench", args);
    ASSERT_EQ(r.rc, 0) << r.out;
    ASSERT_TRUE(fs::exists(json));
    for (const char* bad : {"{garbage\n", "", "{\"ate\": {\"rmse\": 0.1}"}) {
        std::ofstream(json) << bad;
        r = devslam::test::runApp("devslam-bench", args + " --reuse-runs");
        EXPECT_EQ(r.rc, 0) << r.out;
        EXPECT_NE(r.out.find("WARNING: not kept: " + json.string() + " is not a whole JSON object"),
                  std::string::npos)
            << bad << "\n"
            << r.out;
        EXPECT_EQ(r.out.find("runs were kept from an earlier invocation"), std::string::npos)
            << r.out;
        EXPECT_NE(readFile(json).find("\"per_frame\""), std::string::npos) << "made again";
    }
    // A whole one is kept, without a warning.
    r = devslam::test::runApp("devslam-bench", args + " --reuse-runs");
    EXPECT_EQ(r.rc, 0) << r.out;
    EXPECT_EQ(r.out.find("WARNING"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("1 of 1 runs were kept"), std::string::npos) << r.out;
}

// A run that lost every frame (black images: nothing to track) is a whole run without an
// ATE: devslam-run exits with kExitNoPose, and the bench counts its figures instead of
// calling it failed.
TEST(DevslamBench, ARunThatLostEveryFrameIsARunWithoutAnAte) {
    const std::string root = DEVSLAM_SOURCE_DIR;
    const devslam::test::TempDir d("devslam_");
    const fs::path tmp = d.str();
    {
        devslam::io::TumReader in(root + "/data/tum/fr1_xyz_first37");
        devslam::io::TumWriter out((tmp / "black").string(), "three black frames");
        for (std::size_t i = 0; i < 3; ++i) {
            auto f = in.read(i);
            f.bgr.setTo(0);
            out.write(f);
        }
        out.close();
    }
    std::ofstream(tmp / "bench.ini")
        << "[bench]\nmodes = none\nrepeats = 1\n[sequence_black]\npath = "
        << (tmp / "black").string() << "\nslam_config = " << root
        << "/config_ini/slam_tum_fr1.ini\n";
    const auto r = devslam::test::runApp(
        "devslam-bench", "--config '" + (tmp / "bench.ini").string() + "' --results none --out '" +
                             (tmp / "out").string() + "'");
    EXPECT_EQ(r.rc, 0) << r.out;
    EXPECT_EQ(r.out.find("devslam-run failed"), std::string::npos) << r.out;
    EXPECT_NE(readFile(tmp / "out/runs/black/none/r0/log.txt")
                  .find("devslam-run: no frame took a pose: all 3 frames were lost"),
              std::string::npos);
    const std::string runs = readFile(tmp / "out/runs.csv");
    EXPECT_NE(runs.find("black,none,,0,"), std::string::npos) << runs;
}

TEST(DevslamBench, CompareSetsEachRunBesideTheSameRenderBefore) {
    // Two renders, two modes; runs written by hand (--compare renders and runs nothing).
    const std::string root = DEVSLAM_SOURCE_DIR;
    const devslam::test::TempDir d("devslam_");
    const fs::path tmp = d.str();
    std::ofstream(tmp / "bench.ini")
        << "[bench]\nmodes = none dynamic\nrepeats = 1\nslam_config = " << root
        << "/config_ini/slam_synthetic.ini\n[sequence_short]\nscenario = short_walking\n"
           "seeds = 5 6\n";
    const auto write = [&](const fs::path& runs, const std::string& mode, int seed, double ate,
                           int keyframes) {
        const fs::path dir = runs / "short" / mode / ("seed" + std::to_string(seed) + "_r0");
        fs::create_directories(dir);
        std::ofstream(dir / "run.json")
            << "{\"read_error\": \"\", \"interrupted\": \"\", \"median_fps\": 30, "
               "\"mean_fps\": 25, \"lost_frames\": 0, \"keyframes\": "
            << keyframes << ", \"landmarks\": " << 10 * keyframes
            << ", \"map_mb\": " << 0.1 * keyframes << ", \"ate\": {\"rmse\": " << ate << "}}\n";
    };
    const fs::path before = tmp / "before", after = tmp / "out/runs";
    // dynamic: half the ATE on both renders; none: doubled on one, halved on the other.
    write(before, "dynamic", 5, 0.02, 100), write(after, "dynamic", 5, 0.01, 50);
    write(before, "dynamic", 6, 0.02, 100), write(after, "dynamic", 6, 0.01, 50);
    write(before, "none", 5, 0.1, 80), write(after, "none", 5, 0.2, 80);
    write(before, "none", 6, 0.2, 80), write(after, "none", 6, 0.1, 80);
    const std::string args = "--config '" + (tmp / "bench.ini").string() + "' --out '" +
                             (tmp / "out").string() + "' --compare '" + before.string() + "'";
    auto r = devslam::test::runApp("devslam-bench", args);
    ASSERT_EQ(r.rc, 0) << r.out;
    EXPECT_NE(r.out.find("| short | dynamic | 0.02000 | 0.01000 | 0.500 | 2 of 2 | 100.0 / 50.0 | "
                         "1000 / 500 | 10.0 / 5.0 | 30.0 / 30.0 |"),
              std::string::npos)
        << r.out;
    EXPECT_NE(r.out.find("| short | none | 0.15000 | 0.15000 | 1.000 | 1 of 2 | 80.0 / 80.0 |"),
              std::string::npos)
        << r.out;
    EXPECT_NE(r.out.find("none on 0 of 1 sequences; dynamic on 1 of 1 sequences; 4 runs "
                         "compared."),
              std::string::npos)
        << r.out;
    EXPECT_FALSE(fs::exists(tmp / "out/runs.csv")) << "nothing run";
    // The comparison is printed only: onto a full disk it is lost, which is an error.
    const auto full = devslam::test::runAppOntoFullDisk("devslam-bench", args);
    EXPECT_EQ(full.rc, 1) << full.out;
    EXPECT_EQ(full.out,
              "devslam-bench: cannot write the standard output (No space left on device)\n");
    // A run one side lacks is left out, and said so.
    fs::remove_all(after / "short/none/seed6_r0");
    r = devslam::test::runApp("devslam-bench", args);
    ASSERT_EQ(r.rc, 0) << r.out;
    EXPECT_NE(r.out.find("| short | none | 0.10000 | 0.20000 | 2.000 | 0 of 1 |"),
              std::string::npos)
        << r.out;
    EXPECT_NE(r.out.find("3 runs compared, 1 missing in one or both folders (left out)."),
              std::string::npos)
        << r.out;
    // One cut short (a run killed while writing it) is left out too, and named.
    const fs::path cut = before / "short/dynamic/seed6_r0/run.json";
    fs::resize_file(cut, 50);
    r = devslam::test::runApp("devslam-bench", args);
    ASSERT_EQ(r.rc, 0) << r.out;
    EXPECT_NE(r.out.find("devslam-bench: --compare: " + cut.string() +
                         " is not a whole JSON object (empty, cut short or garbage): left out"),
              std::string::npos)
        << r.out;
    EXPECT_NE(r.out.find("2 runs compared, 2 missing in one or both folders (left out)."),
              std::string::npos)
        << r.out;
    // A folder that is not there, or holds none of these runs: an error naming it.
    r = devslam::test::runApp("devslam-bench", args + "x");
    EXPECT_NE(r.rc, 0);
    EXPECT_NE(r.out.find("--compare: no such folder '" + before.string() + "x'"), std::string::npos)
        << r.out;
    fs::create_directories(tmp / "empty");
    r = devslam::test::runApp("devslam-bench", "--config '" + (tmp / "bench.ini").string() +
                                                   "' --out '" + (tmp / "out").string() +
                                                   "' --compare '" + (tmp / "empty").string() +
                                                   "'");
    EXPECT_NE(r.rc, 0);
    EXPECT_NE(r.out.find("have no run of this bench in common"), std::string::npos) << r.out;
}

// An older build given by --bin, whose devslam-run and devslam-synth know no --check-config
// and --check (they print the usage after saying so): the checks are skipped, said once each,
// and the bench goes on to the renders (here a fake devslam-synth that fails them).
TEST(DevslamBench, AnOlderBuildWithoutTheChecksIsRunWithoutThem) {
    const fs::path tmp = devslam::test::scratchPath("devslam_bench_oldbin");
    fs::remove_all(tmp);
    fs::create_directories(tmp / "bin");
    for (const auto& [name, option] : std::vector<std::pair<std::string, std::string>>{
             {"devslam-run", "unknown argument '--check-config'"},
             {"devslam-synth", "unknown option '--check'"}}) {
        std::ofstream(tmp / "bin" / name) << "#!/bin/sh\necho \"" << name << ": " << option
                                          << "\"\nfor i in 1 2 3 4 5 6 7 8; do echo \"usage line "
                                             "$i\"; done\nexit 1\n";
        fs::permissions(tmp / "bin" / name, fs::perms::owner_all);
    }
    std::ofstream(tmp / "bench.ini") << "[sequence_a]\nscenario = short_walking\n";
    const std::string cmd = "'" + std::string(DEVSLAM_BIN_DIR) + "/devslam-bench' --config '" +
                            (tmp / "bench.ini").string() + "' --out '" + (tmp / "out").string() +
                            "' --results none --bin '" + (tmp / "bin").string() + "' > '" +
                            (tmp / "log.txt").string() + "' 2>&1";
    EXPECT_NE(std::system(cmd.c_str()), 0);
    const std::string said = readFile(tmp / "log.txt");
    const auto count = [&](const std::string& what) {
        std::size_t n = 0;
        for (auto at = said.find(what); at != std::string::npos; at = said.find(what, at + 1)) ++n;
        return n;
    };
    EXPECT_EQ(count("/devslam-run has no --check-config: the SLAM INIs are checked by its runs"),
              1u)
        << said;
    EXPECT_EQ(count("/devslam-synth has no --check: the scenarios are checked by their renders"),
              1u)
        << said;
    EXPECT_NE(said.find("devslam-synth failed for a of "), std::string::npos) << said;

    // A --bin without the programs: said so, where it was "devslam-run refuses its SLAM INI
    // ... (exit 127): ... not found".
    fs::remove(tmp / "bin" / "devslam-run");
    const std::string none = "'" + std::string(DEVSLAM_BIN_DIR) + "/devslam-bench' --config '" +
                             (tmp / "bench.ini").string() + "' --out '" + (tmp / "out").string() +
                             "' --results none --bin '" + (tmp / "bin").string() + "' > '" +
                             (tmp / "log.txt").string() + "' 2>&1";
    EXPECT_NE(std::system(none.c_str()), 0);
    EXPECT_EQ(readFile(tmp / "log.txt"), "devslam-bench: --bin '" + (tmp / "bin").string() +
                                             "': no program devslam-run there (the folder of "
                                             "devslam-bench's own build by default)\n");
}

TEST(DevslamBench, BadIniIsRefusedNamingSectionAndKey) {
    const std::string root = DEVSLAM_SOURCE_DIR, bin = DEVSLAM_BIN_DIR;
    const fs::path tmp = devslam::test::scratchPath("devslam_bench_bad");
    fs::remove_all(tmp);
    fs::create_directories(tmp);
    const auto refused = [&](const std::string& ini) {
        std::ofstream(tmp / "bench.ini") << ini;
        const std::string cmd =
            "'" + bin + "/devslam-bench' --config '" + (tmp / "bench.ini").string() + "' --out '" +
            (tmp / "out").string() + "' --results '" + (tmp / "RESULTS.md").string() + "' > '" +
            (tmp / "log.txt").string() + "' 2>&1";
        EXPECT_NE(std::system(cmd.c_str()), 0) << ini;
        EXPECT_FALSE(fs::exists(tmp / "out/runs.csv")) << ini << ": nothing may run";
        return readFile(tmp / "log.txt");
    };
    std::ofstream(tmp / "dup.ini") << "[tracker]\nmin_matches = 5\nmin_matches = 6\n";
    std::ofstream(tmp / "nofilter.ini") << "[run]\nfilter_config = nowhere_filter.ini\n";
    // A SLAM INI whose filter INI names a detector there is not: it failed only the runs
    // that detect, after the renders and the runs of mode none.
    std::ofstream(tmp / "baddet_filter.ini") << "[detector]\ndetector = yolov9\n";
    std::ofstream(tmp / "baddet.ini") << "[run]\nfilter_config = baddet_filter.ini\n";
    // devslam-run's own keys, and the INI's mode (which the bench's --mode overrides): a typo
    // there failed every run, after every render.
    const std::string filter = "filter_config = " + root + "/config_ini/dynamic_filter.ini\n";
    std::ofstream(tmp / "badrun.ini") << "[run]\n" << filter << "async_filtre = true\n";
    std::ofstream(tmp / "badmode.ini") << "[run]\n" << filter << "mode = dynamik\n";
    const std::string fr1 = "path = " + root + "/data/tum/fr1_xyz_first37\n";
    const std::string synth = "[sequence_a]\nscenario = short_walking\n";
    const std::string real = "[sequence_a]\n" + fr1;
    // (bench INI, what its message must say)
    const std::vector<std::pair<std::string, std::string>> cases = {
        {synth + "seeds = 5 x\n", "[sequence_a] seeds: expected an integer"},
        {synth + "seeds = 5 6 5\n", "seed 5 is listed twice"},
        {real + "seeds = 5\n", "[sequence_a] seeds: only a synthetic sequence"},
        {real + "repeats = 0x\n", "bench.ini [sequence_a] repeats: expected an integer"},
        {"[bench]\nrepeats = 2x\n" + real, "bench.ini [bench] repeats: expected an integer"},
        {real + "[sequense_b]\n" + fr1,
         "bench.ini: unknown section [sequense_b] (known: bench, sequence_*, targets)"},
        {real + "seed = 5\n", "bench.ini [sequence_a]: unknown key 'seed' (known: "},
        {"[bench]\nmax_frames = -1\n" + real, "bench.ini [bench] max_frames: must be >= 0"},
        {"[bench]\nrender_jobs = -1\n" + real, "bench.ini [bench] render_jobs: must be 0..64"},
        {"[bench]\nmodes = none Dynamic\n" + real,
         "bench.ini [bench] modes: unknown mask mode 'Dynamic'"},
        {"[bench]\nmodes = none dynamic none\n" + real,
         "bench.ini [bench] modes: 'none' is listed twice"},
        {"[bench]\nmodes =\n" + real, "bench.ini [bench] modes: empty"},
        {real + "slam_config = " + (tmp / "baddet.ini").string() + "\n",
         "baddet_filter.ini [detector] detector: unknown detector 'yolov9'"},
        {"[sequence_a]\npath = " + root + "/data/tum\n",
         "bench.ini [sequence_a] path: " + root + "/data/tum"},
        {"[sequence_a]\nscenario = no_such_scenario\n",
         "bench.ini [sequence_a]: devslam-synth refuses its scenario 'no_such_scenario' (exit "
         "1):\n  devslam-synth: no scenario file 'no_such_scenario' and no '" +
             root + "/sim_worlds/synth/no_such_scenario.ini'"},
        {"[sequence_a]\npath = " + root + "/data/tum/no_such_folder\n",
         "bench.ini [sequence_a] path: no such file or folder '"},
        {real + "slam_config = nowhere.ini\n", "bench.ini [sequence_a] slam_config: no such file"},
        {real + "slam_config = nowhere.ini\n", "' (nor '" + (tmp / "nowhere.ini").string() + "')"},
        {real + "name = ..\n", "[sequence_a] name: '..' ('.' and '..' are taken by every folder"},
        {synth + "slam_config = " + (tmp / "badrun.ini").string() + "\n",
         "bench.ini [sequence_a]: devslam-run refuses its SLAM INI '" +
             (tmp / "badrun.ini").string() + "' in mode none (exit 1):\n  devslam-run: " +
             (tmp / "badrun.ini").string() + " [run]: unknown key 'async_filtre'"},
        {synth + "slam_config = " + (tmp / "badmode.ini").string() + "\n",
         "badmode.ini [run] mode: unknown mode 'dynamik'"},
        // A broken SLAM INI, or the filter INI it names, is read before any run too.
        {real + "slam_config = " + (tmp / "dup.ini").string() + "\n", "dup.ini"},
        {real + "slam_config = " + (tmp / "nofilter.ini").string() + "\n", "nowhere_filter.ini"},
        {"[bench]\nslam_config = /nowhere.ini\n" + synth,
         "bench.ini [bench] slam_config: no such file '/nowhere.ini'"},
        {real + "name = fr1/xyz\n", "bench.ini [sequence_a] name: 'fr1/xyz' (letters, digits"},
        {real + "[sequence_b]\nname = a\n" + fr1,
         "bench.ini [sequence_b] name: 'a' is already the name of an earlier sequence"},
        {synth + "seeds = 1\n[sequence_b]\nname = a_seed1\nscenario = short_walking\n",
         "bench.ini [sequence_b] name: its render a_seed1 would share a folder with sequence "
         "'a''s"},
        {real + "set = person_1.speed=1\n", "[sequence_a] set: only a synthetic sequence"},
        {synth + fr1,
         "bench.ini [sequence_a]: give 'path' (a TUM folder) or 'scenario' (synthetic), not both"},
        {"[bench]\nmodes = truth\n" + real,
         "bench.ini [bench] modes: truth needs person truth, which no sequence has"},
        {synth + "set = person_1.speed=1 speed=2\n",
         "[sequence_a] set item 'speed=2': expected SECTION.KEY=VALUE"},
        {synth + "set = person_2.path=[3.5 2.8\n",
         "[sequence_a] set 'person_2.path=[3.5 2.8': a '[' is not closed"},
        // A key the scenario does not know stops the bench before any render (devslam-synth
        // --check), in the words of devslam-synth.
        {synth + "set = person_1.sped=1\n",
         "bench.ini [sequence_a]: devslam-synth refuses its scenario 'short_walking' with its "
         "set items (exit 1):\n  devslam-synth: " +
             root +
             "/sim_worlds/synth/short_walking.ini with --set [person_1]: unknown key 'sped'"},
        {real + "[targets]\nx = a dynamic ate <=\n",
         "[targets] x: expected 'SEQUENCE MODE FIGURE OP VALUE'"},
        {real + "[targets]\nx = b dynamic ate <= 1\n", "unknown sequence 'b'"},
        {real + "[targets]\nx = a dynamic speed <= 1\n", "unknown figure 'speed'"},
        {real + "[targets]\nx = a dynamic ate/truth <= 1\n", "ratio 'ate/truth'"},
        {real + "[targets]\nx = a dynamic ate =< 1\n", "unknown comparison '=<'"},
        {real + "[targets]\nx = * dynamic ate <= 1x\n",
         "bench.ini [targets] x: expected a number, got '1x'"},
        {real + "[targets]\nx,y = a dynamic ate <= 1\n",
         "[targets] x,y: a target's name is letters, digits"},
    };
    for (const auto& [ini, msg] : cases) {
        const std::string said = refused(ini);
        EXPECT_NE(said.find(msg), std::string::npos) << ini << "\n" << said;
        // A SLAM INI or a scenario is refused before the renders (their logs are under --out).
        if (ini.find("badrun.ini") != std::string::npos || ini.find("sped") != std::string::npos) {
            EXPECT_EQ(said.find("render (if changed)"), std::string::npos) << said;
        }
    }
    // --out onto a file, --results onto the bench's own INI: refused naming the option, the
    // INI left as it was (it got a Markdown section appended and no longer parsed).
    std::ofstream(tmp / "bench.ini") << real;
    std::ofstream(tmp / "a_file") << "x";
    const auto ran = [&](const std::string& opts) {
        const std::string cmd = "'" + bin + "/devslam-bench' --config '" +
                                (tmp / "bench.ini").string() + "' " + opts + " > '" +
                                (tmp / "log.txt").string() + "' 2>&1";
        EXPECT_NE(std::system(cmd.c_str()), 0) << cmd;
        return readFile(tmp / "log.txt");
    };
    // An empty --out (a script's unset variable) wrote into the INI's out_dir.
    std::string said = ran("--out '' --results none");
    EXPECT_NE(said.find("--out '': give a folder"), std::string::npos) << said;
    said = ran("--out '" + (tmp / "a_file").string() + "' --results none");
    EXPECT_NE(said.find("--out '" + (tmp / "a_file").string() + "': cannot make the folder"),
              std::string::npos)
        << said;
    said = ran("--out '" + (tmp / "out").string() + "' --results '" + (tmp / "bench.ini").string() +
               "'");
    EXPECT_NE(said.find("is not a Markdown file (.md)"), std::string::npos) << said;
    EXPECT_EQ(readFile(tmp / "bench.ini"), real);
    EXPECT_FALSE(fs::exists(tmp / "out/runs.csv")) << "nothing may run";
    // A run that fails (here: a TUM folder whose first colour image does not decode; a folder
    // that is no TUM sequence is refused before any run) is counted and named; the results
    // file keeps its last whole bench, and the exit status says so.
    fs::copy(root + "/data/tum/fr1_xyz_first37", tmp / "not_tum", fs::copy_options::recursive);
    {
        std::ifstream list(tmp / "not_tum/rgb.txt");
        std::string line;
        while (std::getline(list, line) && (line.empty() || line[0] == '#')) {
        }
        std::ofstream(tmp / "not_tum" / line.substr(line.find(' ') + 1)) << "not a png";
    }
    std::ofstream(tmp / "RESULTS.md") << "# Results\n";
    std::ofstream(tmp / "bench.ini")
        << "[bench]\nmodes = none\nrepeats = 1\n[sequence_a]\npath = " << (tmp / "not_tum").string()
        << "\n[sequence_b]\n"
        << fr1;
    const std::string cmd = "'" + bin + "/devslam-bench' --max-frames 5 --config '" +
                            (tmp / "bench.ini").string() + "' --out '" + (tmp / "out").string() +
                            "' --results '" + (tmp / "RESULTS.md").string() + "' > '" +
                            (tmp / "log.txt").string() + "' 2>&1";
    EXPECT_EQ(WEXITSTATUS(std::system(cmd.c_str())), 1);
    const std::string log = readFile(tmp / "log.txt");
    EXPECT_NE(log.find("devslam-run failed (exit 1):\n  devslam-run: "), std::string::npos) << log;
    EXPECT_NE(log.find("cannot decode colour image"), std::string::npos) << log;
    EXPECT_NE(log.find("  to run it again: '" + bin + "/devslam-run' --input '" +
                       (tmp / "not_tum").string() + "' --config "),
              std::string::npos)
        << log;
    EXPECT_NE(log.find("1 of 2 runs failed (the first: "), std::string::npos) << log;
    EXPECT_NE(log.find("RESULTS.md left as it was; --reuse-runs runs only those again"),
              std::string::npos)
        << log;
    EXPECT_EQ(readFile(tmp / "RESULTS.md"), "# Results\n");
    EXPECT_TRUE(fs::exists(tmp / "out/tables.md"));
    // Nor its pictures (sequence b's plot was copied beside it before the bench failed).
    EXPECT_TRUE(fs::exists(tmp / "out/b_none_trajectory.png"));
    EXPECT_FALSE(fs::exists(tmp / "images")) << "the pictures RESULTS.md shows were changed";
    // The failed run's figures are n/a in runs.csv, not zeros.
    const std::string runs = readFile(tmp / "out/runs.csv");
    EXPECT_NE(runs.find("\na,none,,0,n/a,n/a,n/a,"), std::string::npos) << runs;
    // Results in the output folder the bench makes.
    std::ofstream(tmp / "bench.ini") << "[bench]\nmodes = none\nrepeats = 1\n[sequence_a]\n" << fr1;
    const std::string fresh =
        "'" + bin + "/devslam-bench' --config '" + (tmp / "bench.ini").string() +
        "' --max-frames 2 --out '" + (tmp / "fresh").string() + "' --results '" +
        (tmp / "fresh/R.md").string() + "' > '" + (tmp / "log.txt").string() + "' 2>&1";
    EXPECT_EQ(std::system(fresh.c_str()), 0) << readFile(tmp / "log.txt");
    EXPECT_NE(readFile(tmp / "fresh/R.md").find("<!-- BEGIN bench -->"), std::string::npos);
    // --results none writes no results file (it wrote one named 'none'), and --max-frames 0
    // runs whole sequences over the INI's max_frames.
    std::ofstream(tmp / "bench.ini")
        << "[bench]\nmodes = none\nrepeats = 1\nmax_frames = 2\n[sequence_a]\n"
        << fr1;
    const std::string none = "cd '" + tmp.string() + "' && '" + bin +
                             "/devslam-bench' --config bench.ini --max-frames 0 --out whole "
                             "--results none > log.txt 2>&1";
    EXPECT_EQ(std::system(none.c_str()), 0) << readFile(tmp / "log.txt");
    EXPECT_FALSE(fs::exists(tmp / "none"));
    EXPECT_TRUE(fs::exists(tmp / "whole/tables.md"));
    const std::string whole_runs = readFile(tmp / "whole/runs.csv");
    EXPECT_NE(whole_runs.find("\na,none,,0,"), std::string::npos) << whole_runs;
    EXPECT_NE(readFile(tmp / "whole/runs/a/none/r0/log.txt").find("frames     : 32 "),
              std::string::npos)
        << readFile(tmp / "whole/runs/a/none/r0/log.txt");
    // tables.md shows the plots beside it in the output folder (it linked RESULTS.md's
    // images/, which that folder has not); with no filter run on a render, its table is a
    // line, not a header over no rows.
    const std::string whole_md = readFile(tmp / "whole/tables.md");
    EXPECT_NE(whole_md.find("![a none](a_none_trajectory.png)"), std::string::npos) << whole_md;
    EXPECT_TRUE(fs::exists(tmp / "whole/a_none_trajectory.png"));
    EXPECT_EQ(whole_md.find("images/"), std::string::npos) << whole_md;
    EXPECT_NE(whole_md.find("person truth**: no row"), std::string::npos) << whole_md;
    EXPECT_NE(readFile(tmp / "log.txt").find("![a none](a_none_trajectory.png)"),
              std::string::npos);
    // A scenario file is found from the bench INI's folder, as `path` is (devslam-synth
    // looked in the working directory): run from another one.
    fs::create_directories(tmp / "conf");
    std::string scenario = readFile(root + "/sim_worlds/synth/short_walking.ini");
    const auto room = scenario.find("office_room.ini");
    ASSERT_NE(room, std::string::npos);
    scenario.insert(room, root + "/sim_worlds/synth/");
    // (its person textures too: they are found from the scenario file's folder)
    for (auto p = scenario.find("../../data/"); p != std::string::npos;
         p = scenario.find("../../data/"))
        scenario.replace(p, 11, root + "/data/");
    std::ofstream(tmp / "conf/mine.ini") << scenario;
    std::ofstream(tmp / "conf/bench.ini") << "[bench]\nmodes = none\nrepeats = 1\n[sequence_m]\n"
                                             "scenario = mine.ini\n";
    const std::string mine = "cd / && '" + bin + "/devslam-bench' --config '" +
                             (tmp / "conf/bench.ini").string() + "' --max-frames 2 --out '" +
                             (tmp / "mine").string() + "' --results none > '" +
                             (tmp / "log.txt").string() + "' 2>&1";
    EXPECT_EQ(std::system(mine.c_str()), 0) << readFile(tmp / "log.txt");
    EXPECT_NE(
        readFile(tmp / "mine/synth/m/render.txt").find("--- " + (tmp / "conf/mine.ini").string()),
        std::string::npos)
        << readFile(tmp / "mine/synth/m/render.txt");
    fs::remove_all(tmp);
}

// Ctrl-C stops devslam-synth after the current frame: the frames so far are a TUM folder with
// their ground truth, and without render.txt the folder is not taken for a finished render.
// (The signal comes with the first progress line, about 4.5 s in; 300 frames take 30 s.)
TEST(DevslamSynth, CtrlCKeepsTheFramesRenderedSoFar) {
    const fs::path tmp = devslam::test::scratchPath("devslam_synth_ctrl_c");
    fs::remove_all(tmp);
    fs::create_directories(tmp);
    const auto r = devslam::test::signalAppWhen(
        "devslam-synth", "walking_xyz --frames 300 --no-labels -o '" + (tmp / "seq").string() + "'",
        "render walking_xyz [", SIGINT, (tmp / "log.txt").string());
    ASSERT_TRUE(r.signalled) << "the render ended before the signal:\n" << r.out;
    EXPECT_EQ(r.rc, 130) << r.out;
    std::smatch m;
    ASSERT_TRUE(std::regex_search(
        r.out, m,
        std::regex(
            R"(devslam-synth: interrupted \(SIGINT\) after (\d+) of 300 frames: .* holds them)")))
        << r.out;
    const std::size_t frames = std::stoul(m[1].str());
    EXPECT_GE(frames, 1u);
    EXPECT_LT(frames, 300u);
    const auto lines = [&](const char* name) {
        std::istringstream in(readFile(tmp / "seq" / name));
        std::size_t n = 0;
        for (std::string l; std::getline(in, l);) n += !l.empty() && l[0] != '#';
        return n;
    };
    EXPECT_EQ(lines("rgb.txt"), frames);
    EXPECT_EQ(lines("depth.txt"), frames);
    EXPECT_EQ(lines("groundtruth.txt"), frames);
    EXPECT_TRUE(fs::exists(tmp / "seq/camera.ini"));
    EXPECT_FALSE(fs::exists(tmp / "seq/render.txt"));
    fs::remove_all(tmp);
}

// devslam-synth --seed: the same scene and camera path with other noise (how a setting is
// compared on several renders, docs/dynamic.md); a bad value is refused.
TEST(DevslamSynth, SeedOptionGivesAnotherRenderOfTheSameScene) {
    const std::string bin = DEVSLAM_BIN_DIR;
    const fs::path tmp = devslam::test::scratchPath("devslam_synth_seed");
    fs::remove_all(tmp);
    fs::create_directories(tmp);
    auto render = [&](const std::string& name, const std::string& extra) {
        const std::string cmd = "'" + bin + "/devslam-synth' short_walking --frames 2 -o '" +
                                (tmp / name).string() + "' " + extra + " > '" +
                                (tmp / (name + ".log")).string() + "' 2>&1";
        return std::system(cmd.c_str());
    };
    ASSERT_EQ(render("a", "--seed 5"), 0) << readFile(tmp / "a.log");
    ASSERT_EQ(render("b", "--seed 5"), 0) << readFile(tmp / "b.log");
    ASSERT_EQ(render("c", "--seed 6"), 0) << readFile(tmp / "c.log");
    for (const char* f : {"groundtruth.txt", "rgb.txt", "persons.txt"}) {
        EXPECT_EQ(readFile(tmp / "a" / f), readFile(tmp / "b" / f)) << f;
        EXPECT_EQ(readFile(tmp / "a" / f), readFile(tmp / "c" / f)) << f << ": same scene";
    }
    std::vector<fs::path> images;
    for (const auto& e : fs::directory_iterator(tmp / "a/depth")) images.push_back(e.path());
    ASSERT_EQ(images.size(), 2u);
    for (const auto& p : images) {
        const auto f = p.filename();
        EXPECT_EQ(readFile(p), readFile(tmp / "b/depth" / f)) << f << ": same seed, same file";
        EXPECT_NE(readFile(p), readFile(tmp / "c/depth" / f)) << f << ": other seed, other noise";
    }
    EXPECT_NE(render("d", "--seed -3"), 0);
    EXPECT_NE(readFile(tmp / "d.log").find("--seed: expected an integer >= 0, got '-3'"),
              std::string::npos)
        << readFile(tmp / "d.log");
    EXPECT_NE(render("e", "--seed 7x"), 0);
    EXPECT_NE(readFile(tmp / "e.log").find("got '7x'"), std::string::npos)
        << readFile(tmp / "e.log");
    fs::remove_all(tmp);
}

// bench_short.ini is bench.ini cut down, not another bench: the same [bench] settings and
// targets, and each of its sequences one of bench.ini's with the same keys and values but for
// `seeds`, whose renders are some of bench.ini's (the first ones, so that its runs are
// bench.ini's).
TEST(DevslamBench, TheShortBenchIsTheShippedBenchCutDown) {
    const std::string dir = std::string(DEVSLAM_SOURCE_DIR) + "/config_ini/";
    const auto full = devslam::core::loadIni(dir + "bench.ini");
    const auto part = devslam::core::loadIni(dir + "bench_short.ini");
    std::vector<std::string> sections;
    part->getAllSections(sections);
    ASSERT_FALSE(sections.empty());
    for (const auto& s : sections) {
        std::vector<std::string> keys, full_keys;
        part->getAllKeys(s, keys);
        full->getAllKeys(s, full_keys);
        ASSERT_FALSE(full_keys.empty()) << "[" << s << "] is not in bench.ini";
        EXPECT_EQ(keys, full_keys) << "[" << s << "]";
        for (const auto& k : full_keys) {
            const std::string a = part->read_string(s, k, "<none>"),
                              b = full->read_string(s, k, "<none>");
            if (k != "seeds") {
                EXPECT_EQ(a, b) << "[" << s << "] " << k;
            } else {
                const auto words = [](const std::string& t) {
                    std::istringstream in(t);
                    return std::vector<std::string>{std::istream_iterator<std::string>(in), {}};
                };
                const auto mine = words(a), all = words(b);
                EXPECT_TRUE(!mine.empty() && mine.size() <= all.size() &&
                            std::equal(mine.begin(), mine.end(), all.begin()))
                    << "[" << s << "] seeds: not bench.ini's first ones";
            }
        }
    }
    std::vector<std::string> full_sections;
    full->getAllSections(full_sections);
    EXPECT_LT(sections.size(), full_sections.size());
}
