// Smoke tests of the filter's apps: devslam-overlay writes overlays for a synthetic and a
// real sequence; both it and devslam-filter-bench report bad arguments and INIs, naming the
// file and field. (devslam-filter-bench's full run takes minutes: docs/RESULTS.md `detect`.)
#include <gtest/gtest.h>

#include "Command.h"
#include "Scratch.h"

#include <opencv2/imgcodecs.hpp>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <regex>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using devslam::test::runApp;

namespace {
int pngsIn(const std::string& dir) {
    int n = 0;
    for (const auto& e : fs::directory_iterator(dir)) n += e.path().extension() == ".png";
    return n;
}
/// A TUM folder `in` of `stamps.size()` frames, `side` x `side` px: grey 9 colour, depth
/// 1 m (5000 in TUM's units), intrinsics f = 50 with the principal point in the middle.
void writeUniformTum(const std::string& in, int side, const std::vector<const char*>& stamps) {
    fs::create_directories(in + "/rgb");
    fs::create_directories(in + "/depth");
    std::ofstream(in + "/camera.ini")
        << "[camera]\nfx = 50\nfy = 50\ncx = " << side / 2 << "\ncy = " << side / 2
        << "\nwidth = " << side << "\nheight = " << side << "\ndist = [0 0 0 0 0]\n";
    std::ofstream rgb(in + "/rgb.txt"), depth(in + "/depth.txt");
    for (const char* t : stamps) {
        ASSERT_TRUE(
            cv::imwrite(in + "/rgb/" + t + ".png", cv::Mat(side, side, CV_8UC3, cv::Scalar(9))));
        ASSERT_TRUE(cv::imwrite(in + "/depth/" + t + ".png",
                                cv::Mat(side, side, CV_16UC1, cv::Scalar(5000))));
        rgb << t << " rgb/" << t << ".png\n";
        depth << t << " depth/" << t << ".png\n";
    }
}
}  // namespace

// The built-in synthetic walker: one overlay per frame (every 2nd with --every 2), each the
// size of the input image.
TEST(DevslamOverlay, WritesOneOverlayPerFrame) {
    devslam::test::TempDir d("devslam_overlay_");
    auto r = runApp("devslam-overlay", "--input synthetic:walking --frames 6 --out " + d.str("a"));
    ASSERT_EQ(r.rc, 0) << r.out;
    EXPECT_NE(r.out.find("wrote 6 overlays"), std::string::npos) << r.out;
    EXPECT_EQ(pngsIn(d.str("a")), 6);
    const cv::Mat img = cv::imread(d.str("a/overlay_00005.png"));
    ASSERT_FALSE(img.empty());
    EXPECT_EQ(img.cols, 640);
    EXPECT_EQ(img.rows, 480);

    r = runApp("devslam-overlay",
               "--input synthetic:static --frames 6 --every 2 --out " + d.str("b"));
    ASSERT_EQ(r.rc, 0) << r.out;
    EXPECT_EQ(pngsIn(d.str("b")), 3);
    // Again into a: the first run's overlays past this one's are removed (they passed for
    // this run's); other files stay.
    std::ofstream(d.str("a/notes.png")) << "mine";
    r = runApp("devslam-overlay", "--input synthetic:walking --frames 3 --out " + d.str("a"));
    ASSERT_EQ(r.rc, 0) << r.out;
    EXPECT_NE(r.out.find("wrote 3 overlays to " + d.str("a") + " (removed 3 of an earlier run)"),
              std::string::npos)
        << r.out;
    EXPECT_EQ(pngsIn(d.str("a")), 4);
    EXPECT_FALSE(fs::exists(d.str("a/overlay_00003.png")));
    EXPECT_TRUE(fs::exists(d.str("a/notes.png")));
    // Its summary onto a full disk: an error, not 0 (the overlays are written all the same).
    r = devslam::test::runAppOntoFullDisk(
        "devslam-overlay", "--input synthetic:walking --frames 2 --out " + d.str("c"));
    EXPECT_EQ(r.rc, 1) << r.out;
    EXPECT_NE(
        r.out.find("devslam-overlay: cannot write the standard output (No space left on device)\n"),
        std::string::npos)
        << r.out;
    EXPECT_EQ(pngsIn(d.str("c")), 2);
    // A disk that fills under an overlay: the error names it and why, and no cut PNG is left.
    r = devslam::test::runAppWithFileLimit(
        "devslam-overlay", "--input synthetic:walking --frames 2 --out " + d.str("e"), 4096);
    EXPECT_NE(r.rc, 0) << r.out;
    EXPECT_NE(r.out.find("devslam-overlay: cannot write '" + d.str("e/overlay_00000.png") +
                         "': File too large (0 overlays written before it)"),
              std::string::npos)
        << r.out;
    EXPECT_FALSE(fs::exists(d.str("e/overlay_00000.png")));
    EXPECT_FALSE(fs::exists(d.str("e/overlay_00000.png.part")));
}

// The shipped real frames through a SLAM INI, whose [run] filter_config names the filter INI.
TEST(DevslamOverlay, RunsOnTheShippedTumFramesThroughASlamIni) {
    devslam::test::TempDir d("devslam_overlay_");
    const std::string root = DEVSLAM_SOURCE_DIR;
    const auto r = runApp("devslam-overlay",
                          "--input " + root + "/data/tum/fr1_xyz_first37 --frames 3 --config " +
                              root + "/config_ini/slam_tum_fr1.ini --out " + d.str());
    ASSERT_EQ(r.rc, 0) << r.out;
    EXPECT_EQ(pngsIn(d.str()), 3);
}

// A 1x1 TUM folder in mode none: one overlay per frame (cv::ORB, for the dropped keypoints,
// asserted inside cv::resize on an image that small).
TEST(DevslamOverlay, ATinyFrameGetsItsOverlay) {
    devslam::test::TempDir d("devslam_overlay_");
    const std::string in = d.str("tiny");
    writeUniformTum(in, 1, {"100.0", "100.1"});
    ASSERT_FALSE(HasFatalFailure());
    const auto r = runApp("devslam-overlay", "--input " + in + " --mode none --out " + d.str("o"));
    ASSERT_EQ(r.rc, 0) << r.out;
    EXPECT_EQ(pngsIn(d.str("o")), 2);
    EXPECT_EQ(cv::imread(d.str("o/overlay_00001.png")).size(), cv::Size(1, 1));
}

// A frame that does not decode stops the run naming it, and says how far it got: the
// overlays it wrote replaced an earlier run's, whose later ones are still there (it named
// only the image, as if the folder were all of one run or untouched).
TEST(DevslamOverlay, AnUndecodableFrameSaysWhichOverlaysAreThisRuns) {
    devslam::test::TempDir d("devslam_overlay_");
    const std::string in = d.str("tum");
    writeUniformTum(in, 8, {"100.0", "100.1", "100.2"});
    ASSERT_FALSE(HasFatalFailure());
    const std::string args = "--input " + in + " --mode none --out " + d.str("o");
    auto r = runApp("devslam-overlay", args);
    ASSERT_EQ(r.rc, 0) << r.out;
    ASSERT_EQ(pngsIn(d.str("o")), 3);
    std::ofstream(in + "/rgb/100.1.png") << "not a png";
    r = runApp("devslam-overlay", args);
    EXPECT_EQ(r.rc, 1) << r.out;
    EXPECT_NE(r.out.find(in + "/rgb/100.1.png"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("; stopped after 1 frames: wrote 1 overlays to " + d.str("o") +
                         "; overlays there of later frames are an earlier run's"),
              std::string::npos)
        << r.out;
    EXPECT_EQ(pngsIn(d.str("o")), 3);  // the earlier run's later overlays are not removed
    // Into a fresh folder there is no earlier run to speak of (it was said all the same).
    r = runApp("devslam-overlay", "--input " + in + " --mode none --out " + d.str("fresh"));
    EXPECT_EQ(r.rc, 1) << r.out;
    EXPECT_NE(r.out.find("; stopped after 1 frames: wrote 1 overlays to " + d.str("fresh") + "\n"),
              std::string::npos)
        << r.out;
}

// Ctrl-C: the overlay being written is finished, the run stops there, says how far it got and
// exits 130. It stopped at once, silent, and left the overlay it was writing empty.
TEST(DevslamOverlay, CtrlCStopsAfterAWholeOverlay) {
    devslam::test::TempDir d("devslam_overlay_");
    // 400 frames (tens of seconds); the signal once the progress shows frames done.
    const auto r = devslam::test::signalAppWhen(
        "devslam-overlay", "--input synthetic:walking --frames 400 --out " + d.str("o"), "/s",
        SIGINT, d.str("log.txt"));
    ASSERT_TRUE(r.signalled) << "it ended before the signal:\n" << r.out;
    EXPECT_EQ(r.rc, 130) << r.out;
    std::smatch m;
    ASSERT_TRUE(std::regex_search(
        r.out, m,
        std::regex(R"(devslam-overlay: interrupted \(SIGINT\) after (\d+) frames: wrote (\d+) )"
                   R"(overlays to )")))
        << r.out;
    const int done = std::stoi(m[1]);
    EXPECT_EQ(std::stoi(m[2]), done);
    EXPECT_GT(done, 0);
    EXPECT_LT(done, 400);
    EXPECT_EQ(pngsIn(d.str("o")), done);
    for (const auto& e : fs::directory_iterator(d.str("o")))
        EXPECT_GT(fs::file_size(e.path()), 0u) << e.path();
}

TEST(DevslamOverlay, BadInputIsNamed) {
    devslam::test::TempDir d("devslam_overlay_");
    const std::string out = " --out " + d.str("o");
    // A mistyped section of a filter INI given directly.
    const std::string ini = d.str("filter.ini");
    std::ofstream(ini) << "[detector]\ndetector = hog\n[dynamic_filtr]\nthreshold1 = 2\n";
    auto r = runApp("devslam-overlay", "--input synthetic:walking --config " + ini + out);
    EXPECT_EQ(r.rc, 1) << r.out;
    EXPECT_NE(r.out.find(ini + ": unknown section [dynamic_filtr]"), std::string::npos) << r.out;
    // A bad value names the file it came from.
    std::ofstream(ini) << "[detector]\ndetector = hog\n[dynamic_filter]\nlk_window = 4\n";
    r = runApp("devslam-overlay", "--input synthetic:walking --config " + ini + out);
    EXPECT_EQ(r.rc, 1) << r.out;
    EXPECT_NE(r.out.find(ini + " [dynamic_filter] lk_window: must be odd"), std::string::npos)
        << r.out;

    r = runApp("devslam-overlay", "--input synthetic:walking --mode moving" + out);
    EXPECT_EQ(r.rc, 2) << r.out;  // a bad option, as --every 0
    EXPECT_NE(r.out.find("--mode: unknown mask mode 'moving'"), std::string::npos) << r.out;

    // An overlay that cannot be written stops it, naming the file (it said "wrote 3").
    std::filesystem::create_directories(d.str("o") + "/overlay_00002.png");
    r = runApp("devslam-overlay", "--input synthetic:walking --frames 4" + out);
    EXPECT_EQ(r.rc, 1) << r.out;
    EXPECT_NE(r.out.find("cannot write '" + d.str("o") +
                         "/overlay_00002.png': a folder (2 overlays written before it)"),
              std::string::npos)
        << r.out;

    r = runApp("devslam-overlay", "--input synthetic:running" + out);
    EXPECT_EQ(r.rc, 1) << r.out;
    EXPECT_NE(r.out.find("unknown synthetic sequence 'running'"), std::string::npos) << r.out;

    r = runApp("devslam-overlay", "--input " + d.str("nowhere") + out);
    EXPECT_EQ(r.rc, 1) << r.out;
    EXPECT_NE(r.out.find("nowhere"), std::string::npos) << r.out;

    r = runApp("devslam-overlay", "--input synthetic:walking --frames 5000" + out);
    EXPECT_EQ(r.rc, 1) << r.out;
    EXPECT_NE(r.out.find("--frames: a synthetic sequence has at most 1000 frames"),
              std::string::npos)
        << r.out;

    r = runApp("devslam-overlay", "--input synthetic:walking --every 0" + out);
    EXPECT_EQ(r.rc, 2) << r.out;
    EXPECT_NE(r.out.find("--every"), std::string::npos) << r.out;

    // A missing or empty --input or --out is named (the usage alone named neither).
    for (const auto& [args, says] : std::vector<std::pair<std::string, std::string>>{
             {"--input synthetic:walking", "devslam-overlay: --out is required (and not empty)"},
             {"--input synthetic:walking --out ''", "devslam-overlay: --out is required"},
             {"--input ''" + out, "devslam-overlay: --input is required (and not empty)"}}) {
        r = runApp("devslam-overlay", args);
        EXPECT_EQ(r.rc, 2) << args << "\n" << r.out;
        EXPECT_EQ(r.out.rfind(says, 0), 0u) << args << "\n" << r.out;
    }
}

// The bench reads its filter INI before the detectors' minutes of work: a bad one stops it at
// once, and the results file is left as it was.
TEST(DevslamFilterBench, BadConfigStopsItBeforeAnyWork) {
    devslam::test::TempDir d("devslam_filter_bench_");
    const std::string ini = d.str("filter.ini"), results = d.str("R.md");
    std::ofstream(ini) << "[dynamic_filter]\nthreshold1 = 2\n[detectr]\ndetector = hog\n";
    std::ofstream(results) << "# Results\n";
    auto r = runApp("devslam-filter-bench", "--config " + ini + " --results " + results);
    EXPECT_EQ(r.rc, 1) << r.out;
    EXPECT_NE(r.out.find(ini + ": unknown section [detectr]"), std::string::npos) << r.out;
    std::ifstream in(results);
    EXPECT_EQ(std::string(std::istreambuf_iterator<char>(in), {}), "# Results\n");
    // So does a bad value, named with its file.
    std::ofstream(ini) << "[detector]\ndetector = hog\n[dynamic_filter]\nlk_window = 4\n";
    r = runApp("devslam-filter-bench", "--config " + ini + " --results " + results);
    EXPECT_EQ(r.rc, 1) << r.out;
    EXPECT_NE(r.out.find(ini + " [dynamic_filter] lk_window: must be odd"), std::string::npos)
        << r.out;
    std::ifstream in2(results);
    EXPECT_EQ(std::string(std::istreambuf_iterator<char>(in2), {}), "# Results\n");

    // The detector is checked before the work in mode none too (the filter makes none there;
    // it failed after the timing runs, without naming the file).
    std::ofstream(ini) << "[detector]\nweights = models/missing.weights\n[dynamic_filter]\n"
                          "mode = none\n";
    r = runApp("devslam-filter-bench", "--config " + ini + " --results none");
    EXPECT_EQ(r.rc, 1) << r.out;
    EXPECT_NE(r.out.find(ini + " [detector] yolo weights: file not found"), std::string::npos)
        << r.out;
    // --results none in each: a refusal that broke would run the bench, whose default results
    // file is the repository's docs/RESULTS.md.
    std::ofstream(ini) << "[run]\nfilter_config = nowhere.ini\n";
    r = runApp("devslam-filter-bench", "--config " + ini + " --results none");
    EXPECT_EQ(r.rc, 1) << r.out;
    EXPECT_NE(r.out.find("nowhere.ini"), std::string::npos) << r.out;

    r = runApp("devslam-filter-bench", "--frames 1 --results none");
    EXPECT_EQ(r.rc, 2) << r.out;
    EXPECT_NE(r.out.find("--frames"), std::string::npos) << r.out;
    r = runApp("devslam-filter-bench", "--results none --threads");
    EXPECT_EQ(r.rc, 2) << r.out;
    EXPECT_NE(r.out.find("devslam-filter-bench: --threads needs a value"), std::string::npos)
        << r.out;
    // A results file whose markers are broken is found before the detectors' work.
    std::ofstream(results) << "# Results\n<!-- END detect -->\n";
    r = runApp("devslam-filter-bench", "--results " + results);
    EXPECT_EQ(r.rc, 1) << r.out;
    EXPECT_NE(r.out.find("section 'detect' needs"), std::string::npos) << r.out;
    r = runApp("devslam-filter-bench", "--help");
    EXPECT_EQ(r.rc, 0) << r.out;
    EXPECT_NE(r.out.find("usage: devslam-filter-bench"), std::string::npos) << r.out;
    // A standard output that cannot be written is an error (the quickest output is the usage:
    // the tables take half a minute).
    r = devslam::test::runAppOntoFullDisk("devslam-filter-bench", "--help");
    EXPECT_EQ(r.rc, 1) << r.out;
    EXPECT_EQ(r.out,
              "devslam-filter-bench: cannot write the standard output (No space left on device)\n")
        << r.out;
}
