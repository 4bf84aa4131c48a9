// Smoke tests of the devslam-run app: outputs written and loadable, bad input reported.
#include <devslam/core/Results.h>
#include <devslam/io/Rawlog.h>
#include <devslam/io/TrajectoryIO.h>
#include <devslam/io/TumReader.h>
#include <devslam/io/TumWriter.h>

#include <gtest/gtest.h>

#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/maps/COccupancyGridMap2D.h>
#include <mrpt/opengl/COpenGLScene.h>
#include <mrpt/serialization/CArchive.h>
#include "Command.h"
#include "Scratch.h"

#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iomanip>
#include <iterator>
#include <memory>
#include <regex>
#include <sstream>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

namespace fs = std::filesystem;

namespace {
devslam::test::CommandResult run(const std::string& args) {
    return devslam::test::runApp("devslam-run", args);
}
std::size_t lines(const fs::path& p) {
    std::ifstream in(p);
    std::size_t n = 0;
    std::string l;
    while (std::getline(in, l))
        if (!l.empty() && l[0] != '#') ++n;
    return n;
}
/// Renders `frames` frames of short_walking into `seq` (with the person truth); the command,
/// for the failure message, and its status.
std::pair<std::string, int> renderShortWalking(const fs::path& seq, int frames) {
    const std::string cmd = std::string(DEVSLAM_BIN_DIR) + "/devslam-synth short_walking -o '" +
                            seq.string() + "' --frames " + std::to_string(frames) +
                            " > /dev/null 2>&1";
    return {cmd, std::system(cmd.c_str())};
}
/// devslam-run on a rendered folder with slam_synthetic.ini, in `mode`, into `out`.
devslam::test::CommandResult runSynthetic(const fs::path& seq, const std::string& mode,
                                          const fs::path& out) {
    return run("--input '" + seq.string() + "' --config " + DEVSLAM_SOURCE_DIR +
               "/config_ini/slam_synthetic.ini --mode " + mode + " --quiet --out " + out.string());
}
std::string readText(const fs::path& p) {
    std::ifstream in(p);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}
}  // namespace

// --check-config reads the INIs as a run does and stops (devslam-bench asks it before its
// renders): every shipped SLAM INI passes in every mode; a bad key in a SLAM section (read
// only when the run starts, not with [run]) or in the filter INI fails; no frame is read,
// but an input that exists is opened for its frame size.
TEST(DevslamRun, CheckConfigReadsTheInisAsARunDoesAndNoInput) {
    const std::string root = DEVSLAM_SOURCE_DIR;
    for (const char* ini : {"slam_tum_fr1.ini", "slam_tum_fr3.ini", "slam_synthetic.ini"})
        for (const char* mode : {"none", "all_persons", "dynamic", "truth"}) {
            const auto r = run("--check-config --input /nonexistent --config " + root +
                               "/config_ini/" + ini + " --mode " + mode);
            EXPECT_EQ(r.rc, 0) << ini << " " << mode << ": " << r.out;
            EXPECT_NE(r.out.find(std::string("ok: ") + root + "/config_ini/" + ini),
                      std::string::npos)
                << r.out;
        }
    auto r = run("--check-config --set local_ba.max_iteratons=3");
    EXPECT_EQ(r.rc, 1);
    EXPECT_NE(r.out.find("with --set [local_ba]: unknown key 'max_iteratons'"), std::string::npos)
        << r.out;
    r = run("--check-config --set dynamic_filter.lk_levels=-1");
    EXPECT_EQ(r.rc, 1);
    EXPECT_NE(r.out.find("[dynamic_filter] lk_levels"), std::string::npos) << r.out;
    // A flow window the shipped 640x480 frames cannot hold (255 px at flow_scale 0.5) is
    // refused for the input that exists, as its run would refuse the first frame; mode none
    // runs no flow, and an input that is not there is not checked.
    const std::string huge = " --set dynamic_filter.lk_window=255";
    r = run("--check-config" + huge);
    EXPECT_EQ(r.rc, 1);
    EXPECT_NE(r.out.find("[dynamic_filter] lk_window / flow_scale: the flow needs frames of at "
                         "least 510x510 px; the input '"),
              std::string::npos)
        << r.out;
    EXPECT_NE(r.out.find("' has 640x480"), std::string::npos) << r.out;
    EXPECT_EQ(run("--check-config --mode none" + huge).rc, 0);
    EXPECT_EQ(run("--check-config --input /nonexistent" + huge).rc, 0);
    r = run("--check-config --bench 1");
    EXPECT_EQ(r.rc, 1);
    EXPECT_NE(r.out.find("--check-config does not go with --bench"), std::string::npos) << r.out;
}

TEST(DevslamRun, WritesEveryOutputAndPrintsTheSummary) {
    const fs::path out = devslam::test::scratchPath("devslam_run_smoke");
    fs::remove_all(out);
    // An earlier run's output that this run does not write (no person truth, no mask
    // errors) must not stay beside its outputs.
    fs::create_directories(out);
    std::ofstream(out / "mask_errors.csv") << "from an earlier run\n";
    const auto r = run("--mode none --quiet --out " + out.string());
    ASSERT_EQ(r.rc, 0) << r.out;
    EXPECT_FALSE(fs::exists(out / "mask_errors.csv"));
    for (const char* key : {"frames     : 32", "lost frames: 0", "ATE        : RMSE", "RPE (1 f)",
                            "median", "tracking", "backend", "finalize   : ", "final BA   : "})
        EXPECT_NE(r.out.find(key), std::string::npos) << key << "\n" << r.out;
    EXPECT_EQ(lines(out / "trajectory.txt"), 32u);
    EXPECT_GE(lines(out / "keyframes.txt"), 3u);
    for (const char* f :
         {"map.ply", "map.3Dscene", "map_grid.png", "map_grid.gridmap", "trajectory.png",
          "run.json", "lost_frames.txt", "loops.txt", "slam_map.yml"})
        EXPECT_TRUE(fs::exists(out / f) && fs::file_size(out / f) > 0) << f;
    mrpt::opengl::COpenGLScene scene;
    EXPECT_TRUE(scene.loadFromFile((out / "map.3Dscene").string()));
    EXPECT_GE(scene.getViewport()->size(), 3u);
    mrpt::maps::COccupancyGridMap2D grid;
    mrpt::io::CFileGZInputStream in((out / "map_grid.gridmap").string());
    auto arch = mrpt::serialization::archiveFrom(in);
    arch >> grid;
    EXPECT_GT(grid.getSizeX(), 10u);
    std::ifstream js(out / "run.json");
    std::stringstream ss;
    ss << js.rdbuf();
    EXPECT_NE(ss.str().find("\"per_frame\""), std::string::npos);
    EXPECT_NE(ss.str().find("\"ate\""), std::string::npos);
    EXPECT_NE(ss.str().find("\"final_ba\": {\"keyframes\": "), std::string::npos);
    // run.json is written whole under its own name (a .part file renamed).
    EXPECT_FALSE(fs::exists(out / "run.json.part"));
    fs::remove_all(out);
}

// A disk that fills while the outputs are written (a file-size limit stands in for one): the
// first output it refused ended the run before its summary, the figures lost, and left that
// output cut. Now each output is tried on its own, the ones refused are named with the
// system's reason, the summary is printed whole, and no run.json passes the folder for whole.
TEST(DevslamRun, ADiskThatFillsLosesNeitherTheFiguresNorTheOtherOutputs) {
    const devslam::test::TempDir d("devslam_");
    const fs::path out = d.str("run");
    // 50 kB: the trajectories fit, the ATE plot (~200 kB) does not. SIGXFSZ is left at its
    // default, which killed the run (exit 153, no summary): devslam-run ignores it itself.
    const auto r = devslam::test::runAppWithFileLimit(
        "devslam-run", "--max-frames 10 --quiet --out " + out.string(), 50000, false);
    EXPECT_EQ(r.rc, 1) << r.out;
    EXPECT_NE(r.out.find("ATE        : RMSE"), std::string::npos) << r.out;
    // 10 frames span a third of a second: the RPE over 1 s says why it is missing (its line
    // vanished without a word).
    EXPECT_NE(r.out.find("RPE (1 s)  : not computed (RPE: no pose pair 1 s apart"),
              std::string::npos)
        << r.out;
    EXPECT_NE(r.out.find("devslam-run: plot: cannot write '" + (out / "trajectory.png").string() +
                         "': File too large\n"),
              std::string::npos)
        << r.out;
    EXPECT_NE(r.out.find(" of the run's outputs in " + out.string() +
                         " were not written, nor run.json (which says they are whole); the "
                         "figures above are whole\n"),
              std::string::npos)
        << r.out;
    EXPECT_FALSE(fs::exists(out / "run.json"));
    EXPECT_EQ(lines(out / "trajectory.txt"), 10u);
    for (const auto& e : fs::directory_iterator(out))  // none left cut, under its name or .part
        EXPECT_LT(fs::file_size(e.path()), 50000u) << e.path();
}

// Found before the run, not after it: a second run into the folder of one in progress (the
// two mixed their files), and an output name taken by a folder (it stopped the outputs after
// the earlier run's were all removed).
TEST(DevslamRun, AFolderInUseOrAnOutputNameThatIsAFolderIsRefusedFirst) {
    const devslam::test::TempDir d("devslam_");
    const std::string out = d.str("run");
    {
        const devslam::core::FolderClaim busy(out);  // as a run in progress holds it
        const auto r = run("--max-frames 3 --quiet --out " + out);
        EXPECT_EQ(r.rc, 1) << r.out;
        EXPECT_NE(
            r.out.find("devslam-run: '" + out + "' is being written by another run at the moment"),
            std::string::npos)
            << r.out;
        std::ofstream(out + "/trajectory.txt") << "the other run's\n";
    }
    EXPECT_EQ(lines(fs::path(out) / "trajectory.txt"), 1u) << "the run wrote into it";
    fs::create_directories(out + "/map.ply/x");
    const auto r = run("--max-frames 3 --quiet --out " + out);
    EXPECT_EQ(r.rc, 1) << r.out;
    EXPECT_NE(r.out.find("devslam-run: '" + out +
                         "/map.ply' is not a file: the run writes its output of that name "
                         "there; move it or name another --out"),
              std::string::npos)
        << r.out;
    EXPECT_EQ(r.out.find("frames     :"), std::string::npos) << "ran first: " << r.out;
    EXPECT_EQ(lines(fs::path(out) / "trajectory.txt"), 1u) << "an earlier output removed";
}

TEST(DevslamRun, BadInputIsReported) {
    auto r = run("--mode flying --quiet --out ''");
    EXPECT_EQ(r.rc, 1);
    EXPECT_NE(r.out.find("unknown mode 'flying'"), std::string::npos) << r.out;
    r = run("--input /nonexistent/folder --mode none --quiet --out ''");
    EXPECT_EQ(r.rc, 1);
    EXPECT_NE(r.out.find("/nonexistent/folder"), std::string::npos) << r.out;
    const fs::path ini = devslam::test::scratchPath("devslam_bad_slam").string() + ".ini";
    std::ofstream(ini) << "[tracker]\nfine_raduis = 3\n";
    r = run("--config " + ini.string() + " --mode none --quiet --out ''");
    EXPECT_EQ(r.rc, 1);
    EXPECT_NE(r.out.find(ini.string() + " [tracker]: unknown key 'fine_raduis'"), std::string::npos)
        << r.out;
    // a bad value names the file it is in, and what was written over it
    std::ofstream(ini) << "[tracker]\nfine_radius = 4x\n";
    r = run("--config " + ini.string() + " --mode none --quiet --out ''");
    EXPECT_EQ(r.rc, 1);
    EXPECT_NE(r.out.find(ini.string() + " [tracker] fine_radius: expected a number, got '4x'"),
              std::string::npos)
        << r.out;
    r = run("--set dynamic_filter.mask_margin=-3 --mode dynamic --quiet --out ''");
    EXPECT_EQ(r.rc, 1);
    EXPECT_NE(r.out.find("dynamic_filter.ini with "), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("[run] filter_overrides and --set [dynamic_filter] mask_margin: must be"),
              std::string::npos)
        << r.out;
    // a mistyped section, in the file or in --set, would drop its keys without a word
    std::ofstream(ini) << "[trackr]\nfine_radius = 3\n";
    r = run("--config " + ini.string() + " --mode none --quiet --out ''");
    EXPECT_EQ(r.rc, 1);
    EXPECT_NE(r.out.find(ini.string() + ": unknown section [trackr] (known: orb, tracker,"),
              std::string::npos)
        << r.out;
    r = run("--set trackr.fine_radius=3 --mode none --quiet --out ''");
    EXPECT_EQ(r.rc, 1);
    EXPECT_NE(r.out.find("--set: unknown section [trackr]"), std::string::npos) << r.out;
    // the INI's mode, its camera preset, a folder given as the INI: named with the key or file
    std::ofstream(ini) << "[run]\nmode = dynamc\n";
    r = run("--config " + ini.string() + " --quiet --out ''");
    EXPECT_EQ(r.rc, 1);
    EXPECT_NE(r.out.find(ini.string() + " [run] mode: unknown mode 'dynamc'"), std::string::npos)
        << r.out;
    // An empty INI, or the filter's given for the SLAM's, ran on the code's defaults.
    for (const std::string& not_slam :
         {ini.string(), std::string(DEVSLAM_SOURCE_DIR) + "/config_ini/dynamic_filter.ini"}) {
        if (not_slam == ini.string()) std::ofstream(ini) << "# nothing\n";
        r = run("--config " + not_slam + " --mode none --quiet --out ''");
        EXPECT_EQ(r.rc, 1);
        EXPECT_NE(r.out.find(not_slam + ": none of a SLAM INI's sections"), std::string::npos)
            << r.out;
    }
    std::ofstream(ini) << "[run]\nmode = dynamc\n";
    // ... also when --mode overrides it (devslam-bench always gives --mode: no run said it).
    r = run("--config " + ini.string() + " --mode none --quiet --out ''");
    EXPECT_EQ(r.rc, 1);
    EXPECT_NE(r.out.find(ini.string() + " [run] mode: unknown mode 'dynamc'"), std::string::npos)
        << r.out;
    // An empty one was taken for no --mode, and named neither the INI nor --set.
    r = run("--set run.mode= --quiet --out ''");
    EXPECT_EQ(r.rc, 1);
    EXPECT_NE(r.out.find(" with --set [run] mode: unknown mode ''"), std::string::npos) << r.out;
    r = run("--set dataset.camera=freiburg9 --mode none --quiet --out ''");
    EXPECT_EQ(r.rc, 1);
    EXPECT_NE(r.out.find("[dataset] camera: unknown camera preset 'freiburg9'"), std::string::npos)
        << r.out;
    r = run("--config " + ini.parent_path().string() + " --mode none --quiet --out ''");
    EXPECT_EQ(r.rc, 1);
    EXPECT_NE(r.out.find("' is a folder"), std::string::npos) << r.out;
    // an --out that is a file is refused before the run, not when its results are written
    r = run("--mode none --quiet --out " + ini.string());
    EXPECT_EQ(r.rc, 1);
    EXPECT_NE(r.out.find("--out '" + ini.string() + "': a file is there, not a folder"),
              std::string::npos)
        << r.out;
    // ... and a file where a folder above it goes (it ran all frames, then failed to write)
    r = run("--mode none --quiet --out " + ini.string() + "/sub/run");
    EXPECT_EQ(r.rc, 1);
    EXPECT_NE(r.out.find("--out '" + ini.string() + "/sub/run': '" + ini.string() +
                         "' is a file, not a folder"),
              std::string::npos)
        << r.out;
    EXPECT_EQ(r.out.find("ATE"), std::string::npos) << "ran before refusing";
    fs::remove(ini);
    // the diagnostic truth mask needs a rendered folder's person truth
    r = run("--mode truth --quiet --out ''");
    EXPECT_EQ(r.rc, 1);
    EXPECT_NE(r.out.find("needs the renderer's person truth"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("fr1_xyz_first37"), std::string::npos) << r.out;
    // --bench's table is of the INI as it is, on the whole input, in its own section:
    // options that change that, another command's section or a broken file are refused
    // before the runs
    r = run("--bench 1 --modes-only --max-frames 5 --results /dev/null/R.md");
    EXPECT_EQ(r.rc, 1);
    EXPECT_NE(r.out.find("--max-frames does not go with --bench"), std::string::npos) << r.out;
    r = run("--bench 1 --modes-only --section nav --results /dev/null/R.md");
    EXPECT_EQ(r.rc, 1);
    EXPECT_NE(r.out.find("--section 'nav': devslam-run writes 'slam' or 'slam-synthetic'"),
              std::string::npos)
        << r.out;
    // ... and its options are refused without it (a run went on, writing no table).
    for (const char* opt : {"--section slam", "--modes-only", "--results /tmp/R.md"}) {
        r = run(std::string("--max-frames 2 ") + opt);
        EXPECT_EQ(r.rc, 1) << opt;
        EXPECT_NE(r.out.find(" goes with --bench N only"), std::string::npos) << r.out;
    }
    const fs::path md = devslam::test::scratchPath("devslam_bad_results").string() + ".md";
    std::ofstream(md) << "# R\n<!-- END slam -->\n";
    r = run("--bench 1 --modes-only --results " + md.string());
    EXPECT_EQ(r.rc, 1);
    EXPECT_NE(r.out.find("section 'slam' needs"), std::string::npos) << r.out;
    EXPECT_EQ(r.out.find("bench none run"), std::string::npos) << "ran before refusing";
    fs::remove(md);
    // The INI itself named as the results file: refused before any run, the INI untouched.
    std::ofstream(ini) << "[tracker]\nfine_radius = 3\n";
    r = run("--config " + ini.string() + " --bench 1 --modes-only --results " + ini.string());
    EXPECT_EQ(r.rc, 1);
    EXPECT_NE(r.out.find("results file '" + ini.string() + "' is not a Markdown file (.md)"),
              std::string::npos)
        << r.out;
    EXPECT_EQ(r.out.find("bench none run"), std::string::npos) << "ran before refusing";
    std::ifstream back(ini);
    EXPECT_EQ(std::string(std::istreambuf_iterator<char>(back), {}),
              "[tracker]\nfine_radius = 3\n");
    back.close();
    fs::remove(ini);
    // --results none prints the section and writes no file (it is no Markdown file's name;
    // before the check it wrote one named 'none').
    const fs::path here = devslam::test::scratchPath("devslam_bench_none");
    fs::remove_all(here);
    fs::create_directories(here);
    const std::string cmd = "cd '" + here.string() + "' && '" + DEVSLAM_BIN_DIR +
                            "/devslam-run' --bench 1 --modes-only --results none > out.txt 2>&1";
    EXPECT_EQ(std::system(cmd.c_str()), 0);
    std::ifstream said(here / "out.txt");
    const std::string text((std::istreambuf_iterator<char>(said)), {});
    EXPECT_NE(text.find("| dynamic |"), std::string::npos) << text;
    EXPECT_FALSE(fs::exists(here / "none"));
    fs::remove_all(here);
    // a replay makes new stamps, by which the truth is found: refused before any frame
    r = run("--mode truth --replay 2 --quiet --out ''");
    EXPECT_EQ(r.rc, 1);
    EXPECT_NE(r.out.find("--replay with mode truth"), std::string::npos) << r.out;
    // it reads [dynamic_filter] as the other modes do: a mistyped key is named
    r = run("--set dynamic_filter.mask_margn=3 --mode truth --quiet --out ''");
    EXPECT_EQ(r.rc, 1);
    EXPECT_NE(r.out.find("[dynamic_filter]: unknown key 'mask_margn'"), std::string::npos) << r.out;
    // ... and [detector], in every mode: an unknown detector, a mistyped key or a score out of
    // range was accepted in modes none and truth, and found only when the mode changed.
    for (const std::string mode : {"none", "truth"}) {
        r = run("--set detector.detector=yolov9 --mode " + mode + " --quiet --out ''");
        EXPECT_EQ(r.rc, 1) << mode;
        EXPECT_NE(r.out.find("[detector] detector: unknown detector 'yolov9' (known: "),
                  std::string::npos)
            << mode << ": " << r.out;
        r = run("--set detector.conf_treshold=0.3 --mode " + mode + " --quiet --out ''");
        EXPECT_EQ(r.rc, 1) << mode;
        EXPECT_NE(r.out.find("unknown key 'conf_treshold'"), std::string::npos)
            << mode << ": " << r.out;
        r = run("--set detector.conf_threshold=7 --mode " + mode + " --quiet --out ''");
        EXPECT_EQ(r.rc, 1) << mode;
        EXPECT_NE(r.out.find("conf_threshold"), std::string::npos) << mode << ": " << r.out;
    }
    // a mistyped [run] key from --set is not blamed on the file alone
    r = run("--set run.moed=none --quiet --out ''");
    EXPECT_EQ(r.rc, 1);
    EXPECT_NE(r.out.find("slam_tum_fr1.ini with --set [run]: unknown key 'moed'"),
              std::string::npos)
        << r.out;
    // so is a filter_config --set gave (it was blamed on the file)
    r = run("--set run.filter_config=nothere.ini --quiet --out ''");
    EXPECT_EQ(r.rc, 1);
    EXPECT_NE(r.out.find("slam_tum_fr1.ini with --set [run] filter_config: no such file"),
              std::string::npos)
        << r.out;
    r = run("--frobnicate");
    EXPECT_EQ(r.rc, 1);
    EXPECT_NE(r.out.find("usage"), std::string::npos);
}

namespace {
/// `app args` fails (non-zero status) and says `says`.
void expectAppRefuses(const std::string& app, const std::string& args, const std::string& says) {
    const auto r = devslam::test::runApp(app, args);
    // An error exit, not an abort: devslam-nav and devslam-overlay ended by an uncaught
    // exception (exit 134, "terminate called ...") whose text held `says`.
    EXPECT_TRUE(r.rc == 1 || r.rc == 2) << app << " " << args << "\n" << r.out;
    EXPECT_EQ(r.out.find("terminate called"), std::string::npos) << app << " " << args << "\n"
                                                                  << r.out;
    EXPECT_NE(r.out.find(says), std::string::npos) << app << " " << args << "\n" << r.out;
}
}  // namespace

// An option whose value is the next option was taken as the value: "--out --quiet" made a
// folder named "--quiet" and ran. Every app names the option instead, and runs nothing.
TEST(Apps, AnOptionsValueIsNotTheNextOption) {
    const std::string fr1 = std::string(DEVSLAM_SOURCE_DIR) + "/data/tum/fr1_xyz_first37";
    for (const auto& [app, args, says] :
         std::vector<std::tuple<std::string, std::string, std::string>>{
             {"devslam-run", "--mode none --out --quiet", "--out needs a value"},
             {"devslam-run", "--input --mode none --quiet --out ''", "--input needs a value"},
             {"devslam-overlay", "--input synthetic:walking --frames 2 --out --quiet",
              "--out needs a value"},
             {"devslam-convert", "--camera --max-frames 2 " + fr1 + " x.rawlog",
              "--camera needs a value"},
             {"devslam-bench", "--config --reuse-runs", "--config needs a value"},
             {"devslam-filter-bench", "--results --threads 1", "--results needs a value"}}) {
        expectAppRefuses(app, args, says);
    }
    EXPECT_FALSE(fs::exists("--quiet"));
    EXPECT_FALSE(fs::exists("x.rawlog"));
}

// An option given twice kept its last value without a word ("--out a ... --out b" wrote
// only b): every app refuses it before any work, --set (a list) excepted.
TEST(Apps, AnOptionGivenTwiceIsRefused) {
    const std::string fr1 = std::string(DEVSLAM_SOURCE_DIR) + "/data/tum/fr1_xyz_first37";
    const std::string world = std::string(DEVSLAM_SOURCE_DIR) + "/sim_worlds/paper_fig6.ini";
    const std::string twice = " is given twice";
    for (const auto& [app, args, option] :
         std::vector<std::tuple<std::string, std::string, std::string>>{
             {"devslam-run", "--input " + fr1 + " --out twice_a --quiet --out twice_b", "--out"},
             {"devslam-synth", "short_walking -o twice_a --out twice_b", "--out"},
             {"devslam-overlay", "--input synthetic:walking --frames 2 --frames 3 --out twice_a",
              "--frames"},
             {"devslam-convert", "--max-frames 2 --max-frames 3 " + fr1 + " twice.rawlog",
              "--max-frames"},
             {"devslam-eval", "--no-rpe --no-rpe a.txt b.txt", "--no-rpe"},
             {"devslam-bench", "--repeats 1 --repeats 2", "--repeats"},
             {"devslam-filter-bench", "--threads 1 --threads 2", "--threads"},
             {"devslam-nav", world + " --method CHolonomicVFF --method CHolonomicND", "--method"},
             {"devslam-nav-bench", "--quick --quick", "--quick"}}) {
        expectAppRefuses(app, args, option + twice);
    }
    for (const char* made : {"twice_a", "twice_b", "twice.rawlog"}) EXPECT_FALSE(fs::exists(made));
}

// A rawlog cut short (a recording that crashed): refused with how much is intact, and run
// on that part with --allow-damaged, which says what was left out.
// TUM -> rawlog keeps the images bit-exact, but a rawlog has one stamp per frame and no ground
// truth: devslam-convert says what it did not keep.
TEST(DevslamConvert, SaysWhatARawlogDoesNotKeep) {
    const fs::path dir = devslam::test::scratchPath("devslam_convert_notes");
    fs::remove_all(dir);
    fs::create_directories(dir);
    const auto r = devslam::test::runApp(
        "devslam-convert", std::string(DEVSLAM_SOURCE_DIR) + "/data/tum/fr1_xyz_first37 " +
                               (dir / "x.rawlog").string() + " --max-frames 3");
    EXPECT_EQ(r.rc, 0) << r.out;
    EXPECT_TRUE(std::regex_search(
        r.out, std::regex(R"(not kept: the depth images' own stamps \(up to \d+ ms from)")))
        << r.out;
    EXPECT_NE(r.out.find("not kept: groundtruth.txt (a rawlog holds no ground truth)"),
              std::string::npos)
        << r.out;
    // A rawlog's folder is made, as a TUM output's is; a file in its way is named.
    const std::string in = std::string(DEVSLAM_SOURCE_DIR) + "/data/tum/fr1_xyz_first37 ";
    auto made = devslam::test::runApp(
        "devslam-convert", in + (dir / "new/sub/y.rawlog").string() + " --max-frames 2");
    EXPECT_EQ(made.rc, 0) << made.out;
    EXPECT_TRUE(fs::is_regular_file(dir / "new/sub/y.rawlog")) << made.out;
    made = devslam::test::runApp("devslam-convert",
                                 in + (dir / "x.rawlog/z.rawlog").string() + " --max-frames 2");
    EXPECT_EQ(made.rc, 1) << made.out;
    EXPECT_NE(made.out.find("cannot write rawlog '" + (dir / "x.rawlog/z.rawlog").string() +
                            "': cannot make folder '" + (dir / "x.rawlog").string() + "': "),
              std::string::npos)
        << made.out;
    fs::remove_all(dir);
}

// A conversion that stops midway leaves a partial rawlog: it must never replace a good one.
// Two files each: a count that is wrong says so (the usage alone did not); a rawlog named in
// capitals is a rawlog (out.RAWLOG made a TUM folder of that name).
TEST(DevslamConvert, FileCountAndRawlogNameInAnyCase) {
    auto r = devslam::test::runApp("devslam-eval", "gt.txt");
    EXPECT_EQ(r.rc, 2);
    EXPECT_NE(r.out.find("devslam-eval: expected two files, GROUNDTRUTH and ESTIMATE, got 1"),
              std::string::npos)
        << r.out;
    r = devslam::test::runApp("devslam-convert", "a b c");
    EXPECT_EQ(r.rc, 2);
    EXPECT_NE(r.out.find("devslam-convert: expected two files, INPUT and OUTPUT, got 3 (the "
                         "third: 'c')"),
              std::string::npos)
        << r.out;
    // A frame delta that is no whole number, before the inputs are read (it came after the
    // ATE, with a hint about short runs); a camera preset named with the choices --help gives.
    r = devslam::test::runApp("devslam-eval", "gt.txt est.txt --delta 0.5 --delta-unit f");
    EXPECT_NE(r.out.find("--delta: in frames (--delta-unit f) a whole number, got 0.5"),
              std::string::npos)
        << r.out;
    EXPECT_EQ(r.out.find("ATE"), std::string::npos) << r.out;
    // A read error names the file (the line reader's own read lost it: "basic_filebuf::
    // underflow error reading the file").
    r = devslam::test::runApp("devslam-eval", "/proc/self/mem /proc/self/mem");
    EXPECT_NE(r.out.find("error reading '/proc/self/mem'"), std::string::npos) << r.out;
    r = devslam::test::runApp("devslam-convert", "in out --camera bogus");
    EXPECT_NE(r.out.find("--camera: unknown camera preset 'bogus' (known: "), std::string::npos)
        << r.out;
    EXPECT_NE(r.out.find(") or auto"), std::string::npos) << r.out;
    const devslam::test::TempDir d("devslam_");
    const fs::path out = fs::path(d.str()) / "upper.RAWLOG";
    r = devslam::test::runApp("devslam-convert", std::string(DEVSLAM_SOURCE_DIR) +
                                                     "/data/tum/fr1_xyz_first37 " + out.string() +
                                                     " --max-frames 2");
    ASSERT_EQ(r.rc, 0) << r.out;
    EXPECT_TRUE(fs::is_regular_file(out)) << "a folder was made";
}

TEST(DevslamConvert, RefusesToWriteOverAnExistingRawlog) {
    const devslam::test::TempDir d("devslam_");
    const fs::path dir = d.str();
    const std::string tum = std::string(DEVSLAM_SOURCE_DIR) + "/data/tum/fr1_xyz_first37";
    const fs::path keep = dir / "keep.rawlog";
    auto c =
        devslam::test::runApp("devslam-convert", tum + " " + keep.string() + " --max-frames 5");
    ASSERT_EQ(c.rc, 0) << c.out;
    const auto size = fs::file_size(keep);
    // a TUM folder whose second depth image does not decode
    c = devslam::test::runApp("devslam-convert",
                              tum + " " + (dir / "bad").string() + " --max-frames 3");
    ASSERT_EQ(c.rc, 0) << c.out;
    std::ifstream list(dir / "bad" / "depth.txt");
    std::string line, image;
    for (int k = 0; k <= 1 && std::getline(list, line);)
        if (!line.empty() && line[0] != '#' && k++ == 1) image = line.substr(line.find(' ') + 1);
    ASSERT_FALSE(image.empty());
    std::ofstream(dir / "bad" / image) << "not a png";

    c = devslam::test::runApp("devslam-convert", (dir / "bad").string() + " " + keep.string());
    EXPECT_EQ(c.rc, 1) << c.out;
    EXPECT_NE(
        c.out.find("OUTPUT '" + keep.string() + "' already exists; remove it or name another"),
        std::string::npos)
        << c.out;
    EXPECT_EQ(fs::file_size(keep), size);
    c = devslam::test::runApp("devslam-convert", keep.string() + " " + (dir / "x").string());
    EXPECT_EQ(c.rc, 0) << c.out;
    EXPECT_NE(c.out.find("wrote 5 frames"), std::string::npos) << c.out;
    // Its summary onto a full disk: an error, not 0.
    c = devslam::test::runAppOntoFullDisk("devslam-convert",
                                          keep.string() + " " + (dir / "y").string());
    EXPECT_EQ(c.rc, 1) << c.out;
    EXPECT_NE(
        c.out.find("devslam-convert: cannot write the standard output (No space left on device)\n"),
        std::string::npos)
        << c.out;
}

// A disk that fills during a conversion (a file-size limit stands in for one): the frame it
// stopped at and the system's reason are named, and the frames before it are kept, said to be
// cut short; a TUM folder written from a rawlog stops the same way.
TEST(DevslamConvert, ADiskThatFillsStopsItSayingWhereAndWhy) {
    const devslam::test::TempDir d("devslam_");
    const fs::path dir = d.str();
    const std::string tum = std::string(DEVSLAM_SOURCE_DIR) + "/data/tum/fr1_xyz_first37";
    // ~600 kB per frame: the second one does not fit in 1 MB.
    const std::string cut = (dir / "cut.rawlog").string();
    auto c = devslam::test::runAppWithFileLimit("devslam-convert", tum + " " + cut, 1000000);
    EXPECT_EQ(c.rc, 1) << c.out;
    EXPECT_NE(c.out.find("devslam-convert: cannot write rawlog '" + cut + "' at " + tum +
                         "/rgb/1305031102.211214.png: File too large\n"),
              std::string::npos)
        << c.out;
    EXPECT_NE(c.out.find("devslam-convert: stopped there; " + cut +
                         " holds the 1 frames before it, but not whole"),
              std::string::npos)
        << c.out;
    EXPECT_TRUE(fs::exists(cut));
    // The other way: a rawlog into a TUM folder whose images do not fit.
    const std::string whole = (dir / "whole.rawlog").string();
    c = devslam::test::runApp("devslam-convert", tum + " " + whole + " --max-frames 3");
    ASSERT_EQ(c.rc, 0) << c.out;
    c = devslam::test::runAppWithFileLimit("devslam-convert",
                                           whole + " " + (dir / "folder").string(), 100000);
    EXPECT_EQ(c.rc, 1) << c.out;
    EXPECT_NE(c.out.find("devslam-convert: cannot write '" + (dir / "folder/rgb/").string()),
              std::string::npos)
        << c.out;
    EXPECT_NE(c.out.find(".png': File too large\n"), std::string::npos) << c.out;
    EXPECT_NE(c.out.find("nothing was written"), std::string::npos) << c.out;
    EXPECT_FALSE(fs::exists(dir / "folder"));
}

// --max-frames 0 wrote a rawlog of no frames, which no reader opens.
TEST(DevslamConvert, MaxFramesMustBeAtLeastOne) {
    const devslam::test::TempDir d("devslam_");
    const fs::path dir = d.str();
    const auto c = devslam::test::runApp(
        "devslam-convert", std::string(DEVSLAM_SOURCE_DIR) + "/data/tum/fr1_xyz_first37 " +
                               (dir / "x.rawlog").string() + " --max-frames 0");
    EXPECT_EQ(c.rc, 1) << c.out;
    EXPECT_NE(c.out.find("--max-frames: expected an integer >= 1, got '0'"), std::string::npos)
        << c.out;
    EXPECT_FALSE(fs::exists(dir / "x.rawlog"));
}

// An empty OUTPUT (a script's unset variable) wrote its TUM folder into / ("" + "/rgb").
TEST(DevslamConvert, AnEmptyNameIsRefused) {
    const std::string data = std::string(DEVSLAM_SOURCE_DIR) + "/data/tum/fr1_xyz_first37";
    const auto out = devslam::test::runApp("devslam-convert", data + " ''");
    EXPECT_EQ(out.rc, 1) << out.out;
    EXPECT_NE(out.out.find("devslam-convert: OUTPUT is empty: name a file or folder"),
              std::string::npos)
        << out.out;
    const auto in = devslam::test::runApp("devslam-convert", "'' x.rawlog");
    EXPECT_EQ(in.rc, 1) << in.out;
    EXPECT_NE(in.out.find("INPUT is empty"), std::string::npos) << in.out;
    EXPECT_THROW(devslam::io::TumWriter("", "x"), std::invalid_argument);
}

// --allow-damaged with no frame that decodes: an empty output is a failure, not rc 0.
TEST(DevslamConvert, NoFrameConvertedIsAFailure) {
    const devslam::test::TempDir d("devslam_");
    const fs::path dir = d.str();
    const fs::path src = std::string(DEVSLAM_SOURCE_DIR) + "/data/tum/fr1_xyz_first37";
    // The first two frames, each listed image made by `make(from, to)`.
    const auto firstTwo = [&](const std::string& list, const std::string& sub,
                              const std::function<void(const fs::path&, const fs::path&)>& make) {
        fs::create_directories(dir / "in" / sub);
        std::ifstream in(src / list);
        std::ofstream out(dir / "in" / list);
        int n = 0;
        for (std::string line; n < 2 && std::getline(in, line);) {
            if (line.empty() || line[0] == '#') continue;
            out << line << "\n";
            const std::string f = line.substr(line.find(' ') + 1);
            make(src / f, dir / "in" / f);
            ++n;
        }
    };
    firstTwo("rgb.txt", "rgb",
             [](const fs::path&, const fs::path& to) { std::ofstream(to) << "not a png"; });
    firstTwo("depth.txt", "depth",
             [](const fs::path& from, const fs::path& to) { fs::copy_file(from, to); });
    const auto c = devslam::test::runApp("devslam-convert",
                                         (dir / "in").string() + " " + (dir / "out").string() +
                                             " --allow-damaged --camera freiburg1");
    EXPECT_EQ(c.rc, 1) << c.out;
    EXPECT_NE(c.out.find("left out (frames that do not decode): 2"), std::string::npos) << c.out;
    EXPECT_NE(c.out.find("no frame converted (every one left out); nothing was written (" +
                         (dir / "out").string() + " removed)"),
              std::string::npos)
        << c.out;
    // The empty output is gone, so the next try is not refused for it.
    EXPECT_FALSE(fs::exists(dir / "out"));
    const auto again = devslam::test::runApp(
        "devslam-convert",
        (dir / "in").string() + " " + (dir / "out2.rawlog").string() + " --camera freiburg1");
    EXPECT_EQ(again.rc, 1) << again.out;
    EXPECT_NE(again.out.find("stopped there; nothing was written (" +
                             (dir / "out2.rawlog").string() + " removed)"),
              std::string::npos)
        << again.out;
    EXPECT_FALSE(fs::exists(dir / "out2.rawlog"));
}

// A frame the writer refuses stops the conversion with the frames before it, the output
// closed whole: a TUM folder holds depth up to 65535 / 5000 m, a rawlog in millimetres more.
TEST(DevslamConvert, AFrameTheWriterRefusesStopsThere) {
    const devslam::test::TempDir d("devslam_");
    const fs::path dir = d.str();
    devslam::io::TumReader tum(std::string(DEVSLAM_SOURCE_DIR) + "/data/tum/fr1_xyz_first37");
    {
        devslam::io::RawlogWriter w((dir / "far.rawlog").string(), {});
        for (std::size_t i = 0; i < 3; ++i) {
            devslam::core::Frame f = tum.read(i);
            f.depth_scale = 1000;  // millimetres: up to 65.5 m
            if (i == 1) f.depth.at<float>(10, 10) = 20.f;
            w.write(f);
        }
        w.close();
    }
    const auto c = devslam::test::runApp(
        "devslam-convert", (dir / "far.rawlog").string() + " " + (dir / "tum").string());
    EXPECT_EQ(c.rc, 1) << c.out;
    EXPECT_NE(c.out.find("does not fit"), std::string::npos) << c.out;
    EXPECT_NE(
        c.out.find("stopped there; " + (dir / "tum").string() + " holds the 1 frames before it"),
        std::string::npos)
        << c.out;
    devslam::io::TumReader back((dir / "tum").string());
    EXPECT_EQ(back.size(), 1u);
}

TEST(DevslamRun, TruncatedRawlogRunsOnItsIntactPartWhenAsked) {
    const fs::path dir = devslam::test::scratchPath("devslam_run_truncated");
    fs::remove_all(dir);
    fs::create_directories(dir);
    const fs::path rawlog = dir / "cut.rawlog";
    const std::string convert = std::string(DEVSLAM_BIN_DIR) + "/devslam-convert " +
                                DEVSLAM_SOURCE_DIR + "/data/tum/fr1_xyz_first37 " +
                                rawlog.string() + " --max-frames 8 > /dev/null 2>&1";
    ASSERT_EQ(std::system(convert.c_str()), 0) << convert;
    fs::resize_file(rawlog, fs::file_size(rawlog) * 6 / 10);

    auto r = run("--input " + rawlog.string() + " --mode none --quiet --out " +
                 (dir / "refused").string());
    EXPECT_EQ(r.rc, 1) << r.out;
    EXPECT_NE(r.out.find("cut.rawlog"), std::string::npos) << r.out;
    const std::string hint = "--allow-damaged runs on those ";
    const auto at = r.out.find(hint);
    ASSERT_NE(at, std::string::npos) << r.out;
    const std::size_t intact = std::stoul(r.out.substr(at + hint.size()));
    EXPECT_GE(intact, 2u);
    EXPECT_LT(intact, 8u);
    EXPECT_FALSE(fs::exists(dir / "refused" / "trajectory.txt"));

    r = run("--input " + rawlog.string() + " --mode none --quiet --allow-damaged --out " +
            (dir / "run").string());
    ASSERT_EQ(r.rc, 0) << r.out;
    EXPECT_NE(r.out.find("WARNING: running on the intact part"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("left out   : " + rawlog.string()), std::string::npos) << r.out;
    EXPECT_EQ(lines(dir / "run" / "trajectory.txt"), intact);
    std::ifstream js(dir / "run" / "run.json");
    std::stringstream ss;
    ss << js.rdbuf();
    EXPECT_NE(ss.str().find("\"input_damage\": \"" + rawlog.string()), std::string::npos);

    // devslam-convert salvages the intact part into a rawlog that reads without damage.
    const fs::path saved = dir / "saved.rawlog";
    const std::string salvage = std::string(DEVSLAM_BIN_DIR) + "/devslam-convert " +
                                rawlog.string() + " " + saved.string() +
                                " --allow-damaged > /dev/null 2>&1";
    ASSERT_EQ(std::system(salvage.c_str()), 0) << salvage;
    r = run("--input " + saved.string() + " --mode none --quiet --out " + (dir / "saved").string());
    ASSERT_EQ(r.rc, 0) << r.out;
    EXPECT_EQ(r.out.find("left out"), std::string::npos) << r.out;
    EXPECT_EQ(lines(dir / "saved" / "trajectory.txt"), intact);
    fs::remove_all(dir);
}

// A rawlog holds no ground truth (the TUM rawlogs MRPT publishes come with it beside them):
// --groundtruth gives it, and the run is scored as the same frames in a TUM folder are. A bad
// file is named before the input is opened.
TEST(DevslamRun, ARawlogIsScoredAgainstTheGroundTruthGivenBesideIt) {
    const fs::path dir = devslam::test::scratchPath("devslam_run_given_truth");
    fs::remove_all(dir);
    fs::create_directories(dir);
    const std::string tum = std::string(DEVSLAM_SOURCE_DIR) + "/data/tum/fr1_xyz_first37";
    const fs::path rawlog = dir / "fr1.rawlog";
    const std::string convert = std::string(DEVSLAM_BIN_DIR) + "/devslam-convert " + tum + " " +
                                rawlog.string() + " --max-frames 12 > /dev/null 2>&1";
    ASSERT_EQ(std::system(convert.c_str()), 0) << convert;
    const auto ateLine = [](const std::string& out) {
        const auto at = out.find("ATE        :");
        return at == std::string::npos ? std::string() : out.substr(at, out.find('\n', at) - at);
    };
    auto bare = run("--input " + rawlog.string() + " --mode none --quiet --out ''");
    ASSERT_EQ(bare.rc, 0) << bare.out;
    EXPECT_EQ(ateLine(bare.out), "ATE        : no ground truth");
    const std::string gt = tum + "/groundtruth.txt";
    // (The rawlog keeps one stamp per frame, not the depth images' own, which the depth-time
    // compensation uses on the folder: off, the two runs are the same.)
    const std::string same = " --set mapping.depth_time_compensation=false";
    auto given = run("--input " + rawlog.string() + " --groundtruth " + gt + same +
                     " --mode none --quiet --out " + (dir / "given").string());
    ASSERT_EQ(given.rc, 0) << given.out;
    EXPECT_NE(given.out.find("truth      : " + gt + " (--groundtruth)"), std::string::npos)
        << given.out;
    auto folder =
        run("--input " + tum + " --max-frames 12" + same + " --mode none --quiet --out ''");
    ASSERT_EQ(folder.rc, 0) << folder.out;
    ASSERT_NE(ateLine(folder.out).find("RMSE"), std::string::npos) << folder.out;
    EXPECT_EQ(ateLine(given.out), ateLine(folder.out));
    EXPECT_NE(readText(dir / "given" / "run.json").find("\"groundtruth_file\": \"" + gt + "\""),
              std::string::npos);
    EXPECT_TRUE(fs::exists(dir / "given" / "trajectory.png"));
    // A bad file, named with its line, before the input is read; none with --bench.
    std::ofstream(dir / "bad.txt") << "1305031102.175304 1 2 3\n";
    auto bad = run("--input /no/such/input --groundtruth " + (dir / "bad.txt").string() +
                   " --quiet --out ''");
    EXPECT_EQ(bad.rc, 1);
    EXPECT_NE(bad.out.find((dir / "bad.txt").string() + " line 1: expected 'timestamp tx ty tz "
                                                        "qx qy qz qw' (8 values), got 4"),
              std::string::npos)
        << bad.out;
    auto bench = run("--bench 1 --groundtruth " + gt + " --results none");
    EXPECT_EQ(bench.rc, 1);
    EXPECT_NE(bench.out.find("--groundtruth does not go with --bench"), std::string::npos)
        << bench.out;
    fs::remove_all(dir);
}

// The map one run saved (slam_map.yml) is localized in by a later one (--localize) that
// starts elsewhere, here 16 frames into the same recording: its poses are the first run's,
// in the first run's frame, and the map comes out as it went in. A bad map, or one made with
// another ORB pyramid, is named before the input opens.
TEST(DevslamRun, ALaterRunLocalizesInTheMapAnEarlierOneSaved) {
    const fs::path dir = devslam::test::scratchPath("devslam_run_localize");
    fs::remove_all(dir);
    fs::create_directories(dir);
    const std::string tum = std::string(DEVSLAM_SOURCE_DIR) + "/data/tum/fr1_xyz_first37";
    auto made = run("--mode none --quiet --out " + (dir / "made").string());
    ASSERT_EQ(made.rc, 0) << made.out;
    const std::string map = (dir / "made" / "slam_map.yml").string();
    ASSERT_TRUE(fs::exists(map));
    // The recording from its 17th frame on.
    const fs::path later = dir / "later";
    fs::copy(tum, later, fs::copy_options::recursive);
    for (const char* list : {"rgb.txt", "depth.txt"}) {
        std::ifstream in(later / list);
        std::ostringstream kept;
        int frame = 0;
        for (std::string l; std::getline(in, l);)
            if (l.empty() || l[0] == '#' || frame++ >= 16) kept << l << "\n";
        in.close();
        std::ofstream(later / list) << kept.str();
    }
    auto loc = run("--input " + later.string() + " --localize " + map +
                   " --mode none --quiet --out " + (dir / "loc").string());
    ASSERT_EQ(loc.rc, 0) << loc.out;
    EXPECT_NE(loc.out.find("localized  : in " + map +
                           " from frame 0 (its keyframes and landmarks kept as they were)"),
              std::string::npos)
        << loc.out;
    EXPECT_NE(loc.out.find("lost frames: 0"), std::string::npos) << loc.out;
    EXPECT_NE(loc.out.find(" keyframes, trained on the map in "), std::string::npos) << loc.out;
    const auto a = devslam::io::readTumTrajectory((dir / "made" / "trajectory.txt").string());
    const auto b = devslam::io::readTumTrajectory((dir / "loc" / "trajectory.txt").string());
    ASSERT_GE(b.size(), 10u);
    double worst = 0, nearest_origin = 1e9;
    for (const auto& p : b) {
        const auto it = std::find_if(a.begin(), a.end(),
                                     [&](const auto& q) { return std::abs(q.t - p.t) < 1e-6; });
        ASSERT_NE(it, a.end()) << p.t;
        worst = std::max(worst, (it->pose.translation() - p.pose.translation()).norm());
        nearest_origin = std::min(nearest_origin, p.pose.translation().norm());
    }
    EXPECT_LT(worst, 0.005);
    EXPECT_GT(nearest_origin, 0.1) << "a new map's origin would be the first frame's";
    const std::string js = readText(dir / "loc" / "run.json");
    EXPECT_NE(js.find("\"localize_map\": \"" + map + "\""), std::string::npos);
    EXPECT_NE(js.find("\"localized_from_frame\": 0,"), std::string::npos);
    EXPECT_NE(js.find("\"place_index\": {\"words\": "), std::string::npos) << js;
    EXPECT_NE(readText(dir / "made" / "run.json").find("\"place_index\": null,"),
              std::string::npos);
    EXPECT_NE(readText(dir / "made" / "run.json").find("\"localized_from_frame\": null,"),
              std::string::npos);
    // --extend-map: the same start, mapping on from there (keyframes of its own), its poses
    // still the first run's.
    auto ext = run("--input " + later.string() + " --localize " + map +
                   " --extend-map --mode none --quiet --out " + (dir / "ext").string());
    ASSERT_EQ(ext.rc, 0) << ext.out;
    EXPECT_NE(ext.out.find("localized  : in " + map +
                           " from frame 0, and mapped on from there (--extend-map)"),
              std::string::npos)
        << ext.out;
    EXPECT_EQ(ext.out.find("keyframes: 7 "), std::string::npos) << ext.out;
    const auto e = devslam::io::readTumTrajectory((dir / "ext" / "trajectory.txt").string());
    ASSERT_EQ(e.size(), b.size());
    for (std::size_t i = 0; i < e.size(); ++i)
        EXPECT_LT((e[i].pose.translation() - b[i].pose.translation()).norm(), 0.005) << i;
    EXPECT_NE(readText(dir / "ext" / "run.json").find("\"extend_map\": true,"), std::string::npos);
    // Frames that find nothing in the map (black): the run is whole and says where it was
    // not localized, with the status of a run that took no pose.
    {
        devslam::io::TumReader in(later.string());
        devslam::io::TumWriter out((dir / "black").string(), "four black frames");
        for (std::size_t i = 0; i < 4; ++i) {
            auto f = in.read(i);
            f.bgr.setTo(0);
            out.write(f);
        }
        out.close();
    }
    auto nowhere_in_map = run("--input " + (dir / "black").string() + " --localize " + map +
                              " --mode none --quiet --out " + (dir / "unloc").string());
    EXPECT_EQ(nowhere_in_map.rc, devslam::core::kExitNoPose) << nowhere_in_map.out;
    EXPECT_NE(nowhere_in_map.out.find("localized  : NOT in " + map), std::string::npos)
        << nowhere_in_map.out;
    EXPECT_NE(nowhere_in_map.out.find("devslam-run: no frame took a pose: all 4 frames were lost "
                                      "(not localized in " +
                                      map + "); the first: "),
              std::string::npos)
        << nowhere_in_map.out;
    EXPECT_TRUE(fs::exists(dir / "unloc" / "run.json"));
    // Each of these fails (status 1) with `message` in its output.
    const auto refused = [&](const std::string& args, const std::string& message) {
        const auto r = run(args);
        EXPECT_EQ(r.rc, 1) << args << "\n" << r.out;
        EXPECT_NE(r.out.find(message), std::string::npos) << args << "\n" << r.out;
    };
    refused("--extend-map --quiet --out ''",
            "--extend-map extends the map --localize names; none named");
    // The map written by the localizing run: the same keyframes (the run's folder may be the
    // one the map came from: it is written again, not lost).
    auto again = run("--input " + later.string() + " --localize " + map +
                     " --mode none --quiet --out " + (dir / "made").string());
    ASSERT_EQ(again.rc, 0) << again.out;
    EXPECT_NE(again.out.find("keyframes: 7"), std::string::npos) << again.out;
    EXPECT_NE(made.out.find("keyframes: 7"), std::string::npos) << made.out;
    auto check = run("--check-config --localize " + map);
    EXPECT_EQ(check.rc, 0) << check.out;
    // Refused before the input opens: a map that is not there, one cut short, another ORB
    // pyramid; and with --bench.
    const std::string nowhere = "--input /no/such/input --quiet --out '' --localize ";
    refused(nowhere + (dir / "none.yml").string(), (dir / "none.yml").string() + ": no such file");
    const std::string text = readText(map);
    std::ofstream(dir / "cut.yml") << text.substr(0, text.size() / 2);
    refused(nowhere + (dir / "cut.yml").string(),
            (dir / "cut.yml").string() + ": cut short (its last line is not 'end_of_map: 1')");
    refused(nowhere + map + " --set orb.n_levels=8",
            map +
                ": the map's keypoints come from an ORB pyramid of scale_factor 1.300000, "
                "n_levels 4; this run's [orb] has 1.300000, 8");
    // A map without a keyframe (written by hand: devslam-run writes none).
    std::ofstream(dir / "empty.yml")
        << "%YAML:1.0\n---\nformat: devslam-map\nversion: 1\norb_scale_factor: 1.3\n"
           "orb_n_levels: 4\ncamera:\n   fx: 517.3\n   fy: 516.5\n   cx: 318.6\n   cy: 255.3\n"
           "   width: 640\n   height: 480\n   dist: !!opencv-matrix\n      rows: 1\n"
           "      cols: 5\n      dt: d\n      data: !!binary |\n"
           "         MWQgICAgICAgICAgICAgICAgICAgICAgAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAA\n"
           "         AAAAAAAAAAAAAAAAAAAAAA==\n"
           "keyframes: []\nlandmarks:\n   count: 0\n   id: []\n   p_w: []\n"
           "   descriptors: []\n   colors: []\n   ref_kf: []\n   created_kf: []\n"
           "   n_visible: []\n   n_found: []\n   n_observations: []\n   observations: []\n"
           "end_of_map: 1\n";
    refused(nowhere + (dir / "empty.yml").string(),
            (dir / "empty.yml").string() + ": the map has no keyframe to localize in");
    // --extend-map with another camera: refused (a BA would move the map's keyframes with
    // the other camera's pixels); localizing only, the map's 3D points serve any camera.
    const std::string fr2 = " --set dataset.camera=freiburg2 --mode none --quiet --out ''";
    refused("--localize " + map + " --extend-map" + fr2,
            map +
                ": the map was made with the camera fx=517.3 fy=516.5 cx=318.6 cy=255.3 "
                "640x480");
    EXPECT_EQ(run("--localize " + map + fr2).rc, 0);
    // A localizing run into the map's own folder whose map write fails keeps the map (it was
    // removed with the folder's other outputs before they were written).
    fs::create_directories(dir / "keep");
    fs::copy_file(map, dir / "keep" / "slam_map.yml");
    const auto full = devslam::test::runAppWithFileLimit(
        "devslam-run",
        "--input " + later.string() + " --localize " + (dir / "keep" / "slam_map.yml").string() +
            " --mode none --quiet --out " + (dir / "keep").string(),
        1000000, false);
    EXPECT_EQ(full.rc, 1) << full.out;
    EXPECT_NE(full.out.find("cannot write '" + (dir / "keep" / "slam_map.yml").string() +
                            "': File too large"),
              std::string::npos)
        << full.out;
    EXPECT_EQ(readText(dir / "keep" / "slam_map.yml"), readText(map));
    refused("--bench 1 --localize " + map + " --results none",
            "--localize does not go with --bench");
    fs::remove_all(dir);
}

// Ctrl-C stops a run after the frame it is on: it writes its results for the frames done, as
// at the end of its input, says so, and exits 130 (128 + SIGINT).
TEST(DevslamRun, CtrlCStopsTheRunAndKeepsTheFramesDone) {
    const fs::path dir = devslam::test::scratchPath("devslam_run_ctrl_c");
    fs::remove_all(dir);
    fs::create_directories(dir);
    // 37000 frames (minutes); the signal comes once the progress shows frames done.
    const auto r = devslam::test::signalAppWhen(
        "devslam-run",
        "--input " + std::string(DEVSLAM_SOURCE_DIR) +
            "/data/tum/fr1_xyz_first37 --replay 1000 --mode none --out " + (dir / "run").string(),
        " fps", SIGINT, (dir / "log.txt").string());
    ASSERT_TRUE(r.signalled) << "it ended before the signal:\n" << r.out;
    EXPECT_EQ(r.rc, 130) << r.out;
    std::smatch at;
    ASSERT_TRUE(std::regex_search(
        r.out, at, std::regex(R"(devslam-run: interrupted \(SIGINT\) after (\d+) )")))
        << r.out;
    const std::size_t frames = std::stoul(at[1].str());
    EXPECT_GT(frames, 0u);
    EXPECT_LT(frames, 37000u);
    EXPECT_NE(r.out.find(" frames; " + (dir / "run").string() + " holds their results"),
              std::string::npos)
        << r.out;
    EXPECT_NE(r.out.find("STOPPED    : after " + std::to_string(frames) +
                         " frames: interrupted (SIGINT)"),
              std::string::npos)
        << r.out;
    EXPECT_EQ(lines(dir / "run" / "trajectory.txt"), frames);
    std::ifstream js(dir / "run" / "run.json");
    std::stringstream ss;
    ss << js.rdbuf();
    EXPECT_NE(ss.str().find("\"interrupted\": \"SIGINT\""), std::string::npos)
        << ss.str().substr(0, 400);
    EXPECT_NE(ss.str().find("\"frames\": " + std::to_string(frames) + ","), std::string::npos);
    fs::remove_all(dir);
}

// A frame whose image is there but does not decode is found only when it is read: the run
// stops there, keeps (writes) the frames before it, names the file and exits with 1.
// Ground truth whose stamps match no frame (another sequence's, stamps in other units), or no
// frame tracked: the run says why there is no ATE, in its summary and in run.json, which
// alone did not tell it from a folder without ground truth.
// A ground truth that covers only lost frames (here black ones: frames 8-23 of 24): their
// poses are the last tracked one held, and the run printed their error as its ATE (0.066 m,
// "16 poses"), although only 3 frames tracked beside them are needed for an ATE at all.
TEST(DevslamRun, AnAteOfLostFramesAloneIsNotGiven) {
    const devslam::test::TempDir d("devslam_");
    const fs::path seq = fs::path(d.str()) / "seq";
    const std::string fr1 = std::string(DEVSLAM_SOURCE_DIR) + "/data/tum/fr1_xyz_first37";
    double first = 0, last = 0;
    {
        devslam::io::TumReader in(fr1);
        devslam::io::TumWriter out(seq.string(), "frames 8-23 black");
        for (std::size_t i = 0; i < 24; ++i) {
            auto f = in.read(i);
            if (i >= 8) f.bgr.setTo(0);
            if (i == 8) first = f.timestamp;
            if (i == 23) last = f.timestamp;
            out.write(f);
        }
        out.close();
    }
    {
        std::ifstream in(fr1 + "/groundtruth.txt");
        std::ofstream gt(seq / "groundtruth.txt");
        for (std::string line; std::getline(in, line);) {
            if (line.empty() || line[0] == '#') continue;
            const double t = std::stod(line.substr(0, line.find(' ')));
            if (t > first - 0.005 && t < last + 0.005) gt << line << "\n";
        }
    }
    const auto r = run("--input " + seq.string() + " --mode none --quiet --out ''");
    EXPECT_EQ(r.rc, 0) << r.out;
    EXPECT_NE(r.out.find("ATE        : not computed (0 of the 16 poses the ground truth covers "
                         "are tracked (the ATE needs 3; the others are lost frames' held "
                         "poses))"),
              std::string::npos)
        << r.out;
    EXPECT_NE(r.out.find("lost frames: 16"), std::string::npos) << r.out;
}

TEST(DevslamRun, WithoutAnAteTheRunSaysWhy) {
    const fs::path dir = devslam::test::scratchPath("devslam_run_gt_off");
    fs::remove_all(dir);
    fs::create_directories(dir);
    fs::copy(std::string(DEVSLAM_SOURCE_DIR) + "/data/tum/fr1_xyz_first37", dir / "seq",
             fs::copy_options::recursive);
    {
        std::ifstream in(dir / "seq" / "groundtruth.txt");
        std::ostringstream shifted;
        for (std::string line; std::getline(in, line);) {
            if (line.empty() || line[0] == '#') {
                shifted << line << "\n";
                continue;
            }
            const auto space = line.find(' ');
            shifted << std::fixed << std::setprecision(4) << std::stod(line.substr(0, space)) + 1000
                    << line.substr(space) << "\n";
        }
        in.close();
        std::ofstream(dir / "seq" / "groundtruth.txt") << shifted.str();
    }
    const auto r = run("--input " + (dir / "seq").string() + " --mode none --max-frames 8 --out " +
                       (dir / "run").string());
    EXPECT_EQ(r.rc, 0) << r.out;
    const std::string why = "only 0 of 8 estimated poses associate with the ground truth";
    EXPECT_NE(r.out.find("ATE        : not computed (ATE: " + why), std::string::npos) << r.out;
    const std::string js = readText(dir / "run" / "run.json");
    EXPECT_NE(js.find("\"ate_missing\": \"ATE: " + why), std::string::npos) << js;
    EXPECT_EQ(js.find("\"ate\":"), std::string::npos) << js;
    // Nor is there an ATE when no frame was tracked (depth read in the wrong units, all of it
    // under 6.6 cm: no keypoint has depth): it scored the untracked identity poses against the truth (0.12 m).
    // Each lost frame says why, in the summary, lost_frames.txt and run.json.
    const auto lost = run("--mode none --max-frames 5 --set dataset.tum_depth_scale=1e6 --out " +
                          (dir / "lost").string());
    // The run is whole, its outputs written, but a script must not go on to score it.
    EXPECT_EQ(lost.rc, devslam::core::kExitNoPose) << lost.out;
    EXPECT_NE(lost.out.find("devslam-run: no frame took a pose: all 5 frames were lost; the "
                            "first: not initialized: 0 of "),
              std::string::npos)
        << lost.out;
    EXPECT_NE(lost.out.find("ATE        : not computed (0 of 5 frames tracked (the ATE needs 3))"),
              std::string::npos)
        << lost.out;
    EXPECT_NE(lost.out.find("first (0): not initialized: 0 of "), std::string::npos) << lost.out;
    EXPECT_NE(lost.out.find(" keypoints with depth"),
              std::string::npos)
        << lost.out;
    EXPECT_EQ(lost.out.find("RPE"), std::string::npos) << lost.out;
    EXPECT_NE(readText(dir / "lost" / "lost_frames.txt")
                  .find(" not initialized: 0 of "),
              std::string::npos);
    const std::string lost_js = readText(dir / "lost" / "run.json");
    EXPECT_NE(lost_js.find("\"reason\": \"not initialized: 0 of "),
              std::string::npos);
    EXPECT_NE(lost_js.find("\"ate_missing\": \"0 of 5 frames tracked"), std::string::npos);
    // No map to localize in: none written, said so.
    EXPECT_NE(lost.out.find("slam_map.yml not written: the map has no keyframe"), std::string::npos)
        << lost.out;
    EXPECT_FALSE(fs::exists(dir / "lost" / "slam_map.yml"));
    fs::remove_all(dir);
}

// A frame the dynamic filter refuses (smaller than its flow window) names the input, as a
// reader's error does ("devslam-run: dynamic filter: frame 0 is 16x12 px" named none).
TEST(DevslamRun, AFrameTheFilterRefusesNamesTheInput) {
    const fs::path dir = devslam::test::scratchPath("devslam_run_tiny");
    fs::remove_all(dir);
    {
        devslam::io::TumWriter w((dir / "seq").string());
        for (std::size_t i = 0; i < 2; ++i) {
            devslam::core::Frame f;
            f.index = i;
            f.timestamp = 100.0 + 0.1 * static_cast<double>(i);
            f.bgr = cv::Mat(12, 16, CV_8UC3, cv::Scalar(40, 90, 160));
            f.depth = cv::Mat(12, 16, CV_32FC1, cv::Scalar(2.0f));
            f.K = {13.0, 13.0, 7.5, 5.5, 16, 12};
            w.write(f);
        }
        w.close();
    }
    const auto r = run("--input " + (dir / "seq").string() +
                       " --mode dynamic --set dataset.camera=auto --quiet --out ''");
    EXPECT_EQ(r.rc, 1) << r.out;
    EXPECT_NE(r.out.find("devslam-run: " + (dir / "seq").string() +
                         ": dynamic filter: frame 0 is 16x12 px"),
              std::string::npos)
        << r.out;
    fs::remove_all(dir);
}

TEST(DevslamRun, AnUndecodableFrameMidRunKeepsTheFramesBeforeIt) {
    const fs::path dir = devslam::test::scratchPath("devslam_run_undecodable");
    fs::remove_all(dir);
    const std::string convert = std::string(DEVSLAM_BIN_DIR) + "/devslam-convert " +
                                DEVSLAM_SOURCE_DIR + "/data/tum/fr1_xyz_first37 " +
                                (dir / "seq").string() + " --max-frames 8 > /dev/null 2>&1";
    ASSERT_EQ(std::system(convert.c_str()), 0) << convert;
    std::ifstream list(dir / "seq" / "rgb.txt");
    std::string line, image;
    for (int k = 0; k <= 5 && std::getline(list, line);)
        if (!line.empty() && line[0] != '#' && k++ == 5) image = line.substr(line.find(' ') + 1);
    ASSERT_FALSE(image.empty());
    std::ofstream(dir / "seq" / image) << "not a png";

    const auto r = run("--input " + (dir / "seq").string() + " --mode dynamic --quiet --out " +
                       (dir / "run").string());
    EXPECT_EQ(r.rc, 1) << r.out;
    EXPECT_NE(r.out.find(image + ": cannot decode colour image"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("stopped after 5 frames; " + (dir / "run").string() + " holds their"),
              std::string::npos)
        << r.out;
    EXPECT_NE(r.out.find("STOPPED    : after 5 frames"), std::string::npos) << r.out;
    EXPECT_EQ(lines(dir / "run" / "trajectory.txt"), 5u);
    std::ifstream js(dir / "run" / "run.json");
    std::stringstream ss;
    ss << js.rdbuf();
    EXPECT_NE(ss.str().find("\"read_error\": \"" + (dir / "seq" / image).string()),
              std::string::npos)
        << ss.str().substr(0, 400);
    // With --allow-damaged, as devslam-convert: that frame left out, the others run.
    const auto all = run("--input " + (dir / "seq").string() +
                         " --mode dynamic --quiet --allow-damaged --out " + (dir / "all").string());
    EXPECT_EQ(all.rc, 0) << all.out;
    // --replay reads every frame first: the error comes before any frame is run, with the
    // hint; with --allow-damaged the replay leaves that frame out and says so (it lost the
    // whole run and ignored the flag before).
    const auto replay = run("--input " + (dir / "seq").string() +
                            " --mode none --quiet --replay 2 --out " + (dir / "replay").string());
    EXPECT_EQ(replay.rc, 1) << replay.out;
    EXPECT_NE(replay.out.find(image + ": cannot decode colour image (--replay reads every frame "
                                      "before the first is run; --allow-damaged leaves such "
                                      "frames out)"),
              std::string::npos)
        << replay.out;
    const auto replay_all =
        run("--input " + (dir / "seq").string() + " --mode none --quiet --replay 2 " +
            "--allow-damaged --out " + (dir / "replay").string());
    EXPECT_EQ(replay_all.rc, 0) << replay_all.out;
    EXPECT_NE(replay_all.out.find("1 frame(s) that do not decode left out of the replay, the "
                                  "first: " +
                                  (dir / "seq" / image).string()),
              std::string::npos)
        << replay_all.out;
    EXPECT_EQ(lines(dir / "replay" / "trajectory.txt"), 13u);  // 7 forward, 6 back
    // A run that stops early where a whole run's outputs are goes beside them: the whole run
    // of 7 frames was replaced by the 5 frames of the stopped one.
    const auto stopped = run("--input " + (dir / "seq").string() +
                             " --mode dynamic --quiet --out " + (dir / "all").string());
    EXPECT_EQ(stopped.rc, 1) << stopped.out;
    EXPECT_NE(stopped.out.find("stopped after 5 frames; " + (dir / "all" / "stopped_run").string() +
                               " holds their results (" + (dir / "all").string() +
                               " keeps the whole run that was there)"),
              std::string::npos)
        << stopped.out;
    EXPECT_EQ(lines(dir / "all" / "trajectory.txt"), 7u);
    EXPECT_EQ(lines(dir / "all" / "stopped_run" / "trajectory.txt"), 5u);
    // A whole run into that folder again: the stopped one stays, said to be an earlier run's
    // (it stayed unmentioned).
    const auto again = run("--input " + (dir / "seq").string() +
                           " --mode dynamic --quiet --allow-damaged --out " + (dir / "all").string());
    EXPECT_EQ(again.rc, 0) << again.out;
    EXPECT_NE(again.out.find("devslam-run: note: " + (dir / "all" / "stopped_run").string() +
                             " holds an earlier run that stopped early, not this one"),
              std::string::npos)
        << again.out;
    EXPECT_EQ(lines(dir / "all" / "stopped_run" / "trajectory.txt"), 5u);
    EXPECT_EQ(all.out.find("holds an earlier run"), std::string::npos) << all.out;
    // A file where stopped_run would go: nothing of the stopped run is written, the whole run
    // is kept, and the summary is still printed (the folder's error escaped the run before).
    fs::remove_all(dir / "all" / "stopped_run");
    std::ofstream(dir / "all" / "stopped_run") << "in the way";
    const auto blocked = run("--input " + (dir / "seq").string() +
                             " --mode dynamic --quiet --out " + (dir / "all").string());
    EXPECT_EQ(blocked.rc, 1) << blocked.out;
    EXPECT_NE(blocked.out.find("STOPPED    : after 5 frames"), std::string::npos) << blocked.out;
    EXPECT_NE(blocked.out.find("is not a folder: the stopped run's outputs go there"),
              std::string::npos)
        << blocked.out;
    EXPECT_NE(blocked.out.find("nothing of this run was written; " + (dir / "all").string() +
                               " keeps the whole run that was there"),
              std::string::npos)
        << blocked.out;
    EXPECT_EQ(lines(dir / "all" / "trajectory.txt"), 7u);
    EXPECT_NE(all.out.find("left out   : 1 frames that do not decode (--allow-damaged), the "
                           "first: " +
                           (dir / "seq" / image).string() + ": cannot decode colour image"),
              std::string::npos)
        << all.out;
    EXPECT_EQ(lines(dir / "all" / "trajectory.txt"), 7u);

    // devslam-convert keeps the frames before it, or with --allow-damaged all but that one.
    auto c = devslam::test::runApp("devslam-convert",
                                   (dir / "seq").string() + " " + (dir / "part").string());
    EXPECT_EQ(c.rc, 1) << c.out;
    EXPECT_NE(c.out.find("holds the 5 frames before it"), std::string::npos) << c.out;
    EXPECT_EQ(lines(dir / "part" / "rgb.txt"), 5u);
    c = devslam::test::runApp(
        "devslam-convert",
        (dir / "seq").string() + " " + (dir / "rest.rawlog").string() + " --allow-damaged");
    EXPECT_EQ(c.rc, 0) << c.out;
    EXPECT_NE(c.out.find("left out (frames that do not decode): 1, the first: " +
                         (dir / "seq" / image).string()),
              std::string::npos)
        << c.out;
    EXPECT_NE(c.out.find("wrote 7 frames"), std::string::npos) << c.out;

    // An output that is the input, or a folder that holds a sequence, is refused before
    // anything is written: the writers would empty them before they were read.
    const auto size = fs::file_size(dir / "rest.rawlog");
    c = devslam::test::runApp(
        "devslam-convert", (dir / "rest.rawlog").string() + " " + (dir / "rest.rawlog").string());
    EXPECT_EQ(c.rc, 1) << c.out;
    EXPECT_NE(c.out.find("is the input"), std::string::npos) << c.out;
    EXPECT_EQ(fs::file_size(dir / "rest.rawlog"), size);
    for (const char* out : {"seq", "part"}) {
        c = devslam::test::runApp("devslam-convert",
                                  (dir / "rest.rawlog").string() + " " + (dir / out).string());
        EXPECT_EQ(c.rc, 1) << c.out;
        EXPECT_NE(c.out.find("already holds a TUM sequence (rgb.txt)"), std::string::npos) << c.out;
    }
    EXPECT_EQ(lines(dir / "part" / "rgb.txt"), 5u);
    // An empty label (or one with a line break) for the observations is refused.
    c = devslam::test::runApp("devslam-convert", (dir / "rest.rawlog").string() + " " +
                                                     (dir / "lbl.rawlog").string() + " --label ''");
    EXPECT_EQ(c.rc, 1) << c.out;
    EXPECT_NE(c.out.find("--label must not be empty or hold a line break"), std::string::npos)
        << c.out;
    EXPECT_FALSE(fs::exists(dir / "lbl.rawlog"));
    // Nor a folder without rgb.txt that holds what the TUM writer writes: its ground truth and
    // images were replaced without a word.
    fs::create_directories(dir / "other" / "rgb");
    std::ofstream(dir / "other" / "groundtruth.txt") << "# mine\n";
    c = devslam::test::runApp("devslam-convert",
                              (dir / "rest.rawlog").string() + " " + (dir / "other").string());
    EXPECT_EQ(c.rc, 1) << c.out;
    EXPECT_NE(c.out.find("OUTPUT '" + (dir / "other").string() +
                         "' already holds groundtruth.txt, which the conversion would write over"),
              std::string::npos)
        << c.out;
    EXPECT_EQ(fs::file_size(dir / "other" / "groundtruth.txt"), 7u);  // "# mine\n", kept
    // ... nor a rawlog's images folder that holds images: they were replaced, an older
    // conversion's extra frames left beside the new ones. An empty one is taken.
    fs::create_directories(dir / "ext_Images");
    std::ofstream(dir / "ext_Images" / "frame_0_rgb.png") << "mine";
    c = devslam::test::runApp("devslam-convert", (dir / "rest.rawlog").string() + " " +
                                                     (dir / "ext.rawlog").string() + " --external");
    EXPECT_EQ(c.rc, 1) << c.out;
    EXPECT_NE(c.out.find("its images' folder '" + (dir / "ext_Images").string() +
                         "' is already there and not empty"),
              std::string::npos)
        << c.out;
    EXPECT_FALSE(fs::exists(dir / "ext.rawlog"));
    EXPECT_EQ(fs::file_size(dir / "ext_Images" / "frame_0_rgb.png"), 4u);
    fs::remove_all(dir / "ext_Images");
    fs::create_directories(dir / "ext_Images");
    c = devslam::test::runApp("devslam-convert", (dir / "rest.rawlog").string() + " " +
                                                     (dir / "ext.rawlog").string() + " --external");
    EXPECT_EQ(c.rc, 0) << c.out;
    EXPECT_TRUE(fs::exists(dir / "ext_Images" / "frame_0_rgb.png"));
    fs::remove_all(dir);
}

// The filter one frame ahead in a second thread (async_filter, the shipped setting) must
// give the sequential run's result: its ego-motion prior is the constant-velocity
// prediction instead of the tracker's, which on these slow real frames changes nothing.
TEST(DevslamRun, FilterInASecondThreadKeepsTheSequentialAccuracy) {
    auto ate = [](const std::string& out) {
        const std::string key = "ATE        : RMSE ";
        const auto at = out.find(key);
        return at == std::string::npos ? -1.0 : std::stod(out.substr(at + key.size()));
    };
    const auto seq = run("--mode dynamic --quiet --out '' --set run.async_filter=false");
    const auto par = run("--mode dynamic --quiet --out '' --set run.async_filter=true");
    ASSERT_EQ(seq.rc, 0) << seq.out;
    ASSERT_EQ(par.rc, 0) << par.out;
    EXPECT_EQ(seq.out.find("second thread"), std::string::npos) << seq.out;
    EXPECT_NE(par.out.find("filter one frame ahead in a second thread"), std::string::npos)
        << par.out;
    for (const auto* r : {&seq, &par}) {
        EXPECT_NE(r->out.find("frames     : 32"), std::string::npos) << r->out;
        EXPECT_NE(r->out.find("lost frames: 0"), std::string::npos) << r->out;
    }
    ASSERT_GT(ate(seq.out), 0.0) << seq.out;
    ASSERT_GT(ate(par.out), 0.0) << par.out;
    EXPECT_LT(ate(par.out), 0.01);
    EXPECT_NEAR(ate(par.out), ate(seq.out), 0.001);
}

// --bench's section names the command that makes it again: the options that are not their
// defaults, a path outside the repository as given, the default config left out.
TEST(DevslamRun, BenchSectionNamesTheCommandThatMakesIt) {
    const fs::path tmp = devslam::test::scratchPath("devslam_run_bench_section");
    fs::remove_all(tmp);
    fs::create_directories(tmp);
    const std::string root = DEVSLAM_SOURCE_DIR;
    fs::create_directory_symlink(root + "/data/tum/fr1_xyz_first37", tmp / "fr1");
    std::ofstream(tmp / "R.md") << "# R\n";
    const auto r =
        run("--bench 1 --modes-only --config " + root + "/config_ini/slam_tum_fr1.ini --input " +
            (tmp / "fr1").string() + " --results " + (tmp / "R.md").string());
    ASSERT_EQ(r.rc, 0) << r.out;
    std::ifstream in(tmp / "R.md");
    const std::string md((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_NE(md.find("## SLAM (`devslam-run --bench 1 --modes-only --input " +
                      (tmp / "fr1").string() + "`)\n\nSequence `fr1`, config `slam_tum_fr1.ini`"),
              std::string::npos)
        << md;
    EXPECT_NE(md.find("| dynamic | "), std::string::npos) << md;
    fs::remove_all(tmp);
}

// A rendered folder whose person truth lacks a frame: the run stops at that frame and keeps
// the frames done (it lost the whole run, writing nothing). Scoring the masks (any mode) needs
// the truth after the frame's SLAM step, so that frame is the last; mode truth needs it for
// the mask, before the frame. (The folder's name holds a tab, which run.json escapes.)
TEST(DevslamRun, MissingPersonTruthStopsTheRunAndKeepsTheFramesDone) {
    const fs::path dir = devslam::test::scratchPath("devslam_run_no_truth");
    fs::remove_all(dir);
    const fs::path seq = dir / "se\tq";
    const auto [synth, synth_rc] = renderShortWalking(seq, 8);
    ASSERT_EQ(synth_rc, 0) << synth;
    std::ifstream list(seq / "rgb.txt");
    std::string line, stamp;
    for (int k = 0; k <= 5 && std::getline(list, line);)
        if (!line.empty() && line[0] != '#' && k++ == 5) stamp = line.substr(0, line.find(' '));
    ASSERT_FALSE(stamp.empty());
    std::ifstream in(seq / "persons.txt");
    std::string kept;
    std::size_t dropped = 0;
    for (std::string l; std::getline(in, l);) {
        if (l.rfind(stamp + " ", 0) == 0)
            ++dropped;
        else
            kept += l + "\n";
    }
    in.close();
    ASSERT_GT(dropped, 0u);
    std::ofstream(seq / "persons.txt") << kept;

    for (const auto& [mode, frames] : {std::pair{"none", 6u}, {"truth", 5u}}) {
        const fs::path out = dir / (std::string("run_") + mode);
        const auto r = runSynthetic(seq, mode, out);
        EXPECT_EQ(r.rc, 1) << r.out;
        EXPECT_NE(r.out.find("persons.txt: no entry for frame " + stamp), std::string::npos)
            << r.out;
        EXPECT_NE(r.out.find("stopped after " + std::to_string(frames) + " frames; " +
                             out.string() + " holds their"),
                  std::string::npos)
            << r.out;
        EXPECT_EQ(lines(out / "trajectory.txt"), frames) << mode;
        const std::string json = readText(out / "run.json");
        EXPECT_NE(json.find("\"input\": \"" + dir.string() + "/se\\u0009q\""), std::string::npos)
            << json.substr(0, 300);
        EXPECT_EQ(json.find('\t'), std::string::npos);
    }
    fs::remove_all(dir);
}

// Per frame, with the renderer's truth: the walking people's visible pixels and those the
// mask left open (per_frame walker_px, walker_px_unmasked). The per-person recall counts a
// walker masked from half their area, so a walker partly outside a carried box (one coming
// out from behind another) showed nowhere. No mask leaves every walker pixel open; the
// renderer's own walker mask leaves none.
TEST(DevslamRun, PerFrameWalkerPixelsLeftUnmasked) {
    const fs::path dir = devslam::test::scratchPath("devslam_run_walker_px");
    fs::remove_all(dir);
    const fs::path seq = dir / "seq";
    const auto [synth, synth_rc] = renderShortWalking(seq, 6);
    ASSERT_EQ(synth_rc, 0) << synth;
    const std::regex entry(R"re("walker_px": (\d+), "walker_px_unmasked": (-?\d+))re");
    for (const std::string mode : {"none", "truth"}) {
        const fs::path out = dir / ("run_" + mode);
        const auto r = runSynthetic(seq, mode, out);
        ASSERT_EQ(r.rc, 0) << r.out;
        const std::string json = readText(out / "run.json");
        int frames = 0;
        double walker = 0, unmasked = 0;
        for (std::sregex_iterator it(json.begin(), json.end(), entry), end; it != end; ++it) {
            ++frames;
            const double w = std::stod((*it)[1]), u = std::stod((*it)[2]);
            EXPECT_GE(u, 0) << mode;
            EXPECT_LE(u, w) << mode;
            if (mode == "none") {
                EXPECT_EQ(u, w);
            }
            walker += w;
            unmasked += u;
        }
        EXPECT_EQ(frames, 6) << mode;
        EXPECT_GT(walker, 1000) << mode << ": short_walking's walker is in view";
        if (mode == "truth") {
            EXPECT_EQ(unmasked, 0);
        }
    }
    fs::remove_all(dir);
}
