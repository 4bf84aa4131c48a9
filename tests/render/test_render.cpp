// Tests of devslam::render: exact depth of a known plane from a known pose (which also pins
// the intrinsics and the pixel-centre convention), ground truth = poses used, determinism,
// person truth, depth noise, trajectories and scenario files.
#include <devslam/core/Config.h>
#include <devslam/core/Pose.h>
#include <devslam/core/Results.h>
#include <devslam/io/Rawlog.h>
#include <devslam/io/RgbdReader.h>
#include <devslam/io/TrajectoryIO.h>
#include <devslam/render/DepthNoise.h>
#include <devslam/render/PersonTexture.h>
#include <devslam/render/Scenario.h>
#include <devslam/render/SequenceRenderer.h>
#include <devslam/render/SequenceWriter.h>

#include <opencv2/features2d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <gtest/gtest.h>

#include "Command.h"
#include "Scratch.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <utility>
#include <vector>

namespace fs = std::filesystem;
using namespace devslam;
using namespace devslam::render;

namespace {

const std::string kRoot = DEVSLAM_SOURCE_DIR;
const std::string kSynth = kRoot + "/sim_worlds/synth";
constexpr double kPi = 3.14159265358979323846;

struct TempDir : devslam::test::TempDir {  // a fresh scratch folder per test
    TempDir() : devslam::test::TempDir("devslam_render_") {}
};

std::string readFile(const std::string& p) {
    std::ifstream in(p, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

/// The shipped short scenario at a quarter resolution (160x120) for speed.
Scenario smallShort() {
    Scenario sc = loadScenario(kSynth + "/short_walking.ini");
    sc.K = sc.K.scaled(0.25);
    return sc;
}

/// smallShort's first `frames` frames rendered into tmp/seq: the options that made them.
WriteOptions renderedSeq(const TempDir& tmp, std::size_t frames) {
    WriteOptions o;
    o.out_dir = tmp.str("seq");
    o.max_frames = frames;
    (void)writeSequence(smallShort(), o);
    return o;
}

/// An empty 4 x 4 x 3 m room and a camera that does not move.
Scenario bareRoom(const Eigen::Vector3d& eye, const Eigen::Vector3d& target) {
    Scenario sc;
    sc.name = "bare";
    sc.K = core::CameraIntrinsics::fromPreset("freiburg3").scaled(0.25);
    sc.n_frames = 1;
    sc.rgb_noise_sigma = 0;
    sc.depth_noise.enabled = false;
    sc.room.size = {4, 4, 3};
    sc.room.wall_textures = {kRoot + "/data/images/dog.jpg"};
    sc.room.floor_textures = {kRoot + "/data/images/dog.jpg"};
    sc.trajectory.setDefaultsFor(TrajectoryType::Static);
    sc.trajectory.amplitude.setZero();
    sc.trajectory.rot_amplitude_deg.setZero();
    sc.trajectory.position = eye;
    sc.trajectory.look_at = target;
    return sc;
}

/// FAST corners (threshold 20) of a colour image: how much texture ORB would find.
std::size_t fastCorners(const cv::Mat& bgr) {
    cv::Mat grey;
    cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
    std::vector<cv::KeyPoint> kp;
    cv::FAST(grey, kp, 20);
    return kp.size();
}

/// Two renders of one view that differ only in texture sampling or blur: the same mean
/// colour (within `tol` grey levels per channel) and the very same depth.
void expectSameColourAndDepth(const RenderedFrame& a, const RenderedFrame& b, double tol) {
    const cv::Scalar ma = cv::mean(a.frame.bgr), mb = cv::mean(b.frame.bgr);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(ma[c], mb[c], tol) << "channel " << c;
    EXPECT_EQ(cv::norm(a.frame.depth, b.frame.depth, cv::NORM_INF), 0.0);
}

/// Runs f and expects an exception whose message contains `needle`.
template <class F>
void expectMessage(F&& f, const std::string& needle) {
    try {
        f();
        ADD_FAILURE() << "no error, expected one containing: " << needle;
    } catch (const std::exception& e) {
        EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
}

}  // namespace

// The wall x = 4 and the floor seen from a known, oblique pose: every pixel that sees them
// must hold the analytic depth z = n.(p0 - o) / n.(R K^-1 [u v 1]) with fr3 intrinsics
// (scaled to 160x120). The best-fitting principal point must be the declared one, which
// checks that the GL camera reproduces the OpenCV pixel-centre convention exactly.
TEST(RenderGeometry, KnownPlaneGivesAnalyticDepth) {
    const Eigen::Vector3d eye(1.0, 1.7, 1.9), target(4.0, 2.9, 0.6);
    SequenceRenderer r(bareRoom(eye, target));
    const auto f = r.render(0);
    const auto& K = f.frame.K;
    ASSERT_EQ(f.frame.depth.cols, 160);
    ASSERT_EQ(f.frame.depth.rows, 120);
    const auto R = f.T_wc.getRotationMatrix();
    EXPECT_NEAR(f.T_wc.x(), eye.x(), 1e-12);
    // Mean and max |rendered - analytic| over pixels well inside the wall x = 4, for a
    // principal point shifted by (dx, dy) px from the declared one.
    const auto error = [&](double dx, double dy, double& worst) {
        int n = 0;
        double sum = 0;
        worst = 0;
        for (int v = 5; v < K.height - 5; v += 2)
            for (int u = 5; u < K.width - 5; u += 2) {
                const Eigen::Vector3d dc((u - K.cx - dx) / K.fx, (v - K.cy - dy) / K.fy, 1.0);
                Eigen::Vector3d dw;
                for (int i = 0; i < 3; ++i)
                    dw[i] = R(i, 0) * dc[0] + R(i, 1) * dc[1] + R(i, 2) * dc[2];
                // Ray parameter = optical depth, on the wall x = 4 or on the floor z = 0,
                // away from the room's edges.
                double s = 0;
                const double s_wall = dw.x() > 0 ? (4.0 - eye.x()) / dw.x() : 1e9;
                const double s_floor = dw.z() < 0 ? -eye.z() / dw.z() : 1e9;
                const Eigen::Vector3d hw = eye + s_wall * dw, hf = eye + s_floor * dw;
                if (s_wall < s_floor && hw.y() > 0.2 && hw.y() < 3.8 && hw.z() > 0.2 &&
                    hw.z() < 2.8)
                    s = s_wall;
                else if (s_floor < s_wall && hf.x() > 0.2 && hf.x() < 3.8 && hf.y() > 0.2 &&
                         hf.y() < 3.8)
                    s = s_floor;
                else
                    continue;
                const double e = std::abs(f.frame.depth.at<float>(v, u) - s);
                worst = std::max(worst, e);
                sum += e;
                ++n;
            }
        EXPECT_GT(n, 1000);
        return sum / std::max(n, 1);
    };
    double worst = 0;
    const double at_declared = error(0, 0, worst);
    EXPECT_LT(at_declared, 1e-3) << "mean depth error on the known plane [m]";
    EXPECT_LT(worst, 3e-3) << "max depth error on the known plane [m]";
    // The best principal point is the declared one (within 0.1 px), not the GL pixel corner.
    double best = 1e9, best_dx = 0, best_dy = 0, w = 0;
    for (double dx = -0.6; dx <= 0.6; dx += 0.05)
        for (double dy = -0.6; dy <= 0.6; dy += 0.05) {
            const double e = error(dx, dy, w);
            if (e < best) best = e, best_dx = dx, best_dy = dy;
        }
    EXPECT_LE(std::abs(best_dx), 0.1 + 1e-9);
    EXPECT_LE(std::abs(best_dy), 0.1 + 1e-9);
    EXPECT_GT(error(0.5, 0.5, w), 3 * at_declared) << "a half-pixel shift must be clearly worse";
    std::cout << "plane depth error: mean " << at_declared << " m, max " << worst
              << " m; best principal-point offset (" << best_dx << ", " << best_dy << ") px\n";
}

// Looking straight at the wall from 3 m: centre pixel depth 3 m, colour comes from the photo.
TEST(RenderGeometry, FrontalWallDepthAndColour) {
    SequenceRenderer r(bareRoom({1.0, 2.0, 1.5}, {4.0, 2.0, 1.5}));
    const auto f = r.render(0);
    for (int v : {10, 60, 110})
        for (int u : {10, 80, 150})
            EXPECT_NEAR(f.frame.depth.at<float>(v, u), 3.0, 1e-3) << u << "," << v;
    cv::Scalar mean = cv::mean(f.frame.bgr);
    EXPECT_GT(mean[0] + mean[1] + mean[2], 60.0) << "walls must be textured, not black";
    EXPECT_EQ(cv::countNonZero(f.labels), 0);
}

// `wall_blur` softens the wall photos: the same wall, seen from the same pose, keeps its
// colours but loses most of its corners (the synthetic office's painted walls, docs/render.md).
TEST(RenderGeometry, WallBlurKeepsTheColoursAndRemovesCorners) {
    Scenario sc = bareRoom({2.5, 2.0, 1.5}, {4.0, 2.0, 1.5});
    sc.K = core::CameraIntrinsics::fromPreset("freiburg3");
    const auto sharp = SequenceRenderer(sc).render(0);
    sc.room.wall_blur = 10;
    const auto soft = SequenceRenderer(sc).render(0);
    const auto n_sharp = fastCorners(sharp.frame.bgr), n_soft = fastCorners(soft.frame.bgr);
    EXPECT_GT(n_sharp, 500u);
    EXPECT_LT(n_soft * 5, n_sharp) << n_soft << " corners blurred, " << n_sharp << " sharp";
    expectSameColourAndDepth(sharp, soft, 8.0);
}

// A box's `blur` softens its own photos only: with blurred walls, the sharp corners are the
// box's, and blurring it removes most of them; colours and depth stay.
TEST(RenderGeometry, BoxBlurSoftensTheBoxPhotos) {
    Scenario sc = bareRoom({1.0, 2.0, 1.2}, {3.0, 2.0, 0.4});
    sc.K = core::CameraIntrinsics::fromPreset("freiburg3");
    sc.room.wall_blur = sc.room.floor_blur = 10;
    BoxSpec box;
    box.name = "box_test";
    box.base = {2.6, 2.0, 0.0};
    box.size = {0.8, 1.6, 0.8};
    box.textures = {kRoot + "/data/images/dog.jpg"};
    sc.room.boxes.push_back(box);
    const auto sharp = SequenceRenderer(sc).render(0);
    sc.room.boxes.back().blur = 10;
    const auto soft = SequenceRenderer(sc).render(0);
    const auto n_sharp = fastCorners(sharp.frame.bgr), n_soft = fastCorners(soft.frame.bgr);
    EXPECT_GT(n_sharp, 300u);
    EXPECT_LT(n_soft * 3, n_sharp) << n_soft << " corners blurred, " << n_sharp << " sharp";
    expectSameColourAndDepth(sharp, soft, 8.0);
    std::printf("FAST corners: sharp box %zu, blurred box %zu\n", n_sharp, n_soft);
}

// `texture_filter`: a wall photo seen from 0.5 m is magnified several times. Sampled at the
// nearest texel it becomes blocks of equal pixels (whose corners ORB would track); sampled
// bilinearly, neighbouring pixels differ as in a camera image (except where the photo
// itself is flat or saturated). Depth does not change.
TEST(RenderGeometry, BilinearTexturesHaveNoTexelBlocks) {
    Scenario sc = bareRoom({3.5, 2.0, 1.5}, {4.0, 2.0, 1.5});
    sc.K = core::CameraIntrinsics::fromPreset("freiburg3");
    // Fraction of horizontally adjacent pixel pairs with the very same colour.
    const auto equalNeighbours = [](const cv::Mat& bgr) {
        cv::Mat diff;
        cv::absdiff(bgr.colRange(1, bgr.cols), bgr.colRange(0, bgr.cols - 1), diff);
        cv::Mat grey;
        cv::cvtColor(diff, grey, cv::COLOR_BGR2GRAY);
        return 1.0 - double(cv::countNonZero(grey)) / double(grey.total());
    };
    sc.texture_linear = false;
    const auto nearest = SequenceRenderer(sc).render(0);
    sc.texture_linear = true;
    const auto linear = SequenceRenderer(sc).render(0);
    const double f_nearest = equalNeighbours(nearest.frame.bgr);
    const double f_linear = equalNeighbours(linear.frame.bgr);
    EXPECT_GT(f_nearest, 0.4) << "nearest-texel sampling should give blocks";
    EXPECT_LT(2 * f_linear, f_nearest) << "bilinear sampling should not";
    expectSameColourAndDepth(nearest, linear, 3.0);
    std::printf("equal neighbouring pixels: nearest %.3f, bilinear %.3f\n", f_nearest, f_linear);
    EXPECT_TRUE(loadScenario(kSynth + "/short_walking.ini").texture_linear)
        << "bilinear is the default";
}

TEST(RenderSequence, GroundTruthMatchesPosesUsed) {
    TempDir tmp;
    const Scenario sc = smallShort();
    WriteOptions o;
    o.out_dir = tmp.str("seq");
    o.rawlog_path = tmp.str("seq.rawlog");
    o.max_frames = 6;
    const auto sum = writeSequence(sc, o);
    EXPECT_EQ(sum.n_frames, 6u);
    EXPECT_EQ(sum.frames_without_depth, 0u);
    EXPECT_GT(sum.depth_fraction_median, 0.8);
    // A sensor that measures nothing (a noise of 1e300 m leaves every value out of range) is
    // counted, for devslam-synth's warning: it wrote depth of zeros and said nothing.
    Scenario deaf = sc;
    deaf.depth_noise.sigma_a = 1e300;
    WriteOptions od;
    od.out_dir = tmp.str("deaf");
    od.max_frames = 2;
    const auto none = writeSequence(deaf, od);
    EXPECT_EQ(none.frames_without_depth, 2u);
    EXPECT_EQ(none.depth_fraction_median, 0.0);
    // The rawlog holds the same frames as the TUM folder.
    auto tum = io::openRgbd(o.out_dir, {});
    io::RawlogReader rawlog(o.rawlog_path);
    ASSERT_EQ(rawlog.size(), std::optional<std::size_t>(6));
    for (int i = 0; i < 6; ++i) {
        const auto a = tum->next(), b = rawlog.next();
        ASSERT_TRUE(a && b);
        EXPECT_NEAR(a->timestamp, b->timestamp, 1e-6);
        EXPECT_EQ(cv::norm(a->bgr, b->bgr, cv::NORM_INF), 0.0);
        EXPECT_LT(cv::norm(a->depth, b->depth, cv::NORM_INF), 1e-3);
    }
    const auto gt = io::readTumTrajectory(o.out_dir + "/groundtruth.txt");
    ASSERT_EQ(gt.size(), 6u);
    for (std::size_t i = 0; i < gt.size(); ++i) {
        EXPECT_NEAR(gt[i].t, sc.timeOf(i), 1e-6);
        const auto expected = cameraPoseAt(sc.trajectory, sc.elapsed(i));
        const auto d = expected - gt[i].pose;
        EXPECT_LT(d.norm(), 1e-8);
        EXPECT_LT(core::rotationAngle(d), 1e-7);
    }
    for (const char* f : {"rgb.txt", "depth.txt", "persons.txt", "camera.ini"})
        EXPECT_TRUE(fs::exists(o.out_dir + "/" + f)) << f;
    EXPECT_EQ(std::distance(fs::directory_iterator(o.out_dir + "/rgb"), fs::directory_iterator{}),
              6);
    EXPECT_EQ(
        std::distance(fs::directory_iterator(o.out_dir + "/labels"), fs::directory_iterator{}), 6);
    // camera.ini holds the exact intrinsics.
    const auto K =
        core::CameraIntrinsics::fromConfig(*core::loadIni(o.out_dir + "/camera.ini"), "camera");
    EXPECT_EQ(K, sc.K);
}

TEST(RenderSequence, SameSeedSameFilesOtherSeedOtherNoise) {
    TempDir tmp;
    Scenario sc = smallShort();
    WriteOptions o;
    o.max_frames = 3;
    o.out_dir = tmp.str("a");
    (void)writeSequence(sc, o);
    o.out_dir = tmp.str("b");
    (void)writeSequence(sc, o);
    sc.seed += 1;
    o.out_dir = tmp.str("c");
    (void)writeSequence(sc, o);
    std::size_t compared = 0, differ_c = 0;
    for (const auto& e : fs::recursive_directory_iterator(tmp.str("a"))) {
        if (!e.is_regular_file()) continue;
        const auto rel = fs::relative(e.path(), tmp.str("a")).string();
        EXPECT_EQ(readFile(e.path().string()), readFile(tmp.str("b/" + rel))) << rel;
        if (rel.rfind("depth/", 0) == 0 || rel.rfind("rgb/", 0) == 0)
            differ_c += readFile(e.path().string()) != readFile(tmp.str("c/" + rel));
        ++compared;
    }
    EXPECT_EQ(compared, 15u);  // 3 x (rgb, depth, labels) + 4 lists + camera.ini + render.txt
    EXPECT_EQ(differ_c, 6u) << "another seed must change the noise of every image";
}

// render.txt, written after the last frame, says what a folder holds: the bench renders a
// sequence again when its scenario, room, seed or length changed, or when a render stopped.
TEST(RenderSequence, RenderTxtTellsWhetherAFolderHoldsThisRender) {
    TempDir tmp;
    Scenario sc = smallShort();
    const std::string room = tmp.str("room.ini");
    std::ofstream(room) << "[room]\nsize = [5 5 3]\n";
    sc.room.source = room;
    WriteOptions o;
    o.out_dir = tmp.str("seq");
    o.max_frames = 2;
    EXPECT_FALSE(isRenderCurrent(sc, o)) << "no folder yet";
    (void)writeSequence(sc, o);
    EXPECT_TRUE(isRenderCurrent(sc, o));
    const std::string sig = readFile(o.out_dir + "/render.txt");
    EXPECT_NE(sig.find("size = [5 5 3]"), std::string::npos) << sig;
    EXPECT_NE(sig.find("short_walking.ini"), std::string::npos) << sig;

    Scenario other = sc;
    other.seed += 1;
    EXPECT_FALSE(isRenderCurrent(other, o)) << "another seed";
    WriteOptions longer = o;
    longer.max_frames = 3;
    EXPECT_FALSE(isRenderCurrent(sc, longer)) << "another length";
    std::ofstream(room) << "[room]\nsize = [5 5 3]\nwall_blur = 10\n";
    EXPECT_FALSE(isRenderCurrent(sc, o)) << "the room file changed";
    std::ofstream(room) << "# another comment\n[room]\nsize = [5 5 3]   // [m]\n\n";
    EXPECT_TRUE(isRenderCurrent(sc, o)) << "comments and blank lines do not count";
    Scenario set = sc;  // devslam-synth --set
    set.overrides = {"person_1.speed=0.9"};
    EXPECT_FALSE(isRenderCurrent(set, o)) << "an override";
    EXPECT_NE(renderSignature(set, o).find("set person_1.speed=0.9\n"), std::string::npos);

    // A render that stops half-way leaves no render.txt, so the folder is not current.
    EXPECT_THROW((void)writeSequence(sc, o,
                                     [](std::size_t done, std::size_t) {
                                         if (done == 1) throw std::runtime_error("stopped");
                                     }),
                 std::runtime_error);
    EXPECT_FALSE(fs::exists(o.out_dir + "/render.txt"));
    EXPECT_FALSE(isRenderCurrent(sc, o));

    // A rawlog is part of the render: asked for and not there (or into another file), the
    // folder is not current; made with it, it is.
    (void)writeSequence(sc, o);
    WriteOptions with_rawlog = o;
    with_rawlog.rawlog_path = tmp.str("seq.rawlog");
    EXPECT_FALSE(isRenderCurrent(sc, with_rawlog)) << "no rawlog yet";
    (void)writeSequence(sc, with_rawlog);
    EXPECT_TRUE(isRenderCurrent(sc, with_rawlog));
    EXPECT_FALSE(isRenderCurrent(sc, o)) << "rendered with a rawlog: another render.txt";
    // Rendered again without labels: the labels of the render before are gone, not left to
    // pass for this render's truth.
    ASSERT_TRUE(fs::is_directory(o.out_dir + "/labels"));
    WriteOptions no_labels = o;
    no_labels.write_labels = false;
    (void)writeSequence(sc, no_labels);
    EXPECT_FALSE(fs::exists(o.out_dir + "/labels"));
}

// Ctrl-C (WriteOptions::stop) ends a render at a frame: the frames before it are a whole TUM
// folder with their ground truth, rawlog and person truth, but not a current render.
TEST(RenderSequence, StopEndsTheRenderWithTheFramesBeforeItWritten) {
    TempDir tmp;
    const Scenario sc = smallShort();
    WriteOptions o;
    o.out_dir = tmp.str("seq");
    o.rawlog_path = tmp.str("seq.rawlog");
    o.max_frames = 5;
    int asked = 0;
    // Asked first, then before frames 1, 2 and 3: not before frame 0, when the old outputs
    // are gone already (a stop there left a folder that was neither render, and devslam-synth
    // said it was "left as it was").
    o.stop = [&] { return ++asked == 4; };
    const auto sum = writeSequence(sc, o);
    EXPECT_TRUE(sum.stopped);
    EXPECT_EQ(sum.n_frames, 3u);
    EXPECT_EQ(asked, 4);
    EXPECT_FALSE(fs::exists(o.out_dir + "/render.txt"));
    EXPECT_FALSE(isRenderCurrent(sc, o));
    auto tum = io::openRgbd(o.out_dir, {});
    EXPECT_EQ(tum->size(), std::optional<std::size_t>(3));
    EXPECT_EQ(io::readTumTrajectory(o.out_dir + "/groundtruth.txt").size(), 3u);
    EXPECT_EQ(io::RawlogReader(o.rawlog_path).size(), std::optional<std::size_t>(3));
    EXPECT_TRUE(fs::exists(o.out_dir + "/camera.ini"));
    std::size_t person_rows = 0;
    std::istringstream persons(readFile(o.out_dir + "/persons.txt"));
    for (std::string line; std::getline(persons, line);)
        person_rows += !line.empty() && line[0] != '#';
    EXPECT_EQ(person_rows, 3 * sc.people.size());
    // A stop asked right after the first check: the first frame is written all the same.
    asked = 0;
    o.stop = [&] { return ++asked >= 2; };
    const auto one = writeSequence(sc, o);
    EXPECT_TRUE(one.stopped);
    EXPECT_EQ(one.n_frames, 1u);
    EXPECT_EQ(io::readTumTrajectory(o.out_dir + "/groundtruth.txt").size(), 1u);

    // Not stopped: the whole render, and render.txt.
    o.stop = [] { return false; };
    const auto whole = writeSequence(sc, o);
    EXPECT_FALSE(whole.stopped);
    EXPECT_EQ(whole.n_frames, 5u);
    EXPECT_TRUE(isRenderCurrent(sc, o));
    // Stopped before the first frame: that whole render is left as it was.
    const std::string list = readFile(o.out_dir + "/rgb.txt");
    o.stop = [] { return true; };
    const auto none = writeSequence(sc, o);
    EXPECT_TRUE(none.stopped);
    EXPECT_EQ(none.n_frames, 0u);
    o.stop = nullptr;
    EXPECT_TRUE(isRenderCurrent(sc, o));
    EXPECT_EQ(readFile(o.out_dir + "/rgb.txt"), list);
}

// A render that dies half-way (killed, a write error) leaves no ground truth: the earlier
// render's groundtruth.txt stayed beside the new frames, and passed for theirs.
TEST(RenderSequence, ARenderThatDiesHalfWayLeavesNoOldGroundTruth) {
    TempDir tmp;
    const Scenario sc = smallShort();
    WriteOptions o = renderedSeq(tmp, 4);
    ASSERT_TRUE(fs::exists(o.out_dir + "/groundtruth.txt"));
    const auto dies = [](std::size_t done, std::size_t) {
        if (done == 2) throw std::runtime_error("killed");
    };
    EXPECT_THROW((void)writeSequence(sc, o, dies), std::runtime_error);
    EXPECT_FALSE(fs::exists(o.out_dir + "/render.txt"));
    EXPECT_FALSE(fs::exists(o.out_dir + "/groundtruth.txt"));
}

// A shorter render into the folder of a longer one: the longer one's images past the last
// frame went unlisted but stayed, and passed for this render's beside its lists.
TEST(RenderSequence, AShorterRenderLeavesNoImagesOfTheLongerOne) {
    TempDir tmp;
    const Scenario sc = smallShort();
    WriteOptions o = renderedSeq(tmp, 4);
    const auto count = [&](const char* sub) {
        return std::distance(fs::directory_iterator(o.out_dir + "/" + sub),
                             fs::directory_iterator{});
    };
    ASSERT_EQ(count("rgb"), 4);
    o.max_frames = 2;
    (void)writeSequence(sc, o);
    EXPECT_EQ(count("rgb"), 2);
    EXPECT_EQ(count("depth"), 2);
    EXPECT_EQ(io::openRgbd(o.out_dir, {})->size(), std::optional<std::size_t>(2));
}

// A --rawlog that cannot be written, or that is not this folder's, is refused before the
// folder is touched: an unwritable one cost the earlier render its ground truth and lists,
// and a rawlog of someone else's was written over.
TEST(RenderSequence, ARawlogItCannotOrMayNotWriteLeavesTheEarlierRenderAsItWas) {
    TempDir tmp;
    const Scenario sc = smallShort();
    WriteOptions o = renderedSeq(tmp, 2);
    ASSERT_TRUE(isRenderCurrent(sc, o));
    const std::string list = readFile(o.out_dir + "/rgb.txt");
    const std::string gt = readFile(o.out_dir + "/groundtruth.txt");
    const std::string file = tmp.str("f.txt");
    std::ofstream(file) << "a file\n";
    const std::string theirs = tmp.str("theirs.rawlog");
    std::ofstream(theirs) << "their data\n";
    fs::create_directories(tmp.str("dir.rawlog"));
    for (const auto& [rawlog, says] : std::vector<std::pair<std::string, std::string>>{
             {file + "/x.rawlog", "rawlog '" + file + "/x.rawlog': cannot write in '" + file},
             {tmp.str("dir.rawlog"), "rawlog '" + tmp.str("dir.rawlog") + "' is a folder"},
             {theirs, "rawlog '" + theirs + "' exists and is not one that a render into '" +
                          o.out_dir + "' wrote"}}) {
        WriteOptions w = o;
        w.rawlog_path = rawlog;
        expectMessage([&] { (void)writeSequence(sc, w); }, says);
        EXPECT_TRUE(isRenderCurrent(sc, o)) << rawlog;
        EXPECT_EQ(readFile(o.out_dir + "/rgb.txt"), list) << rawlog;
        EXPECT_EQ(readFile(o.out_dir + "/groundtruth.txt"), gt) << rawlog;
    }
    EXPECT_EQ(readFile(theirs), "their data\n");
    EXPECT_EQ(readFile(file), "a file\n");
    // A folder under the name of a file the render writes is refused before the first frame
    // (render.txt, groundtruth.txt and camera.ini failed after the last one, and the render
    // was lost; preview.png half-way, with a bare filesystem error).
    for (const char* name : {"render.txt", "groundtruth.txt", "camera.ini", "persons.txt",
                             "rgb.txt", "depth.txt", "preview.png"}) {
        const std::string path = o.out_dir + "/" + name, aside = tmp.str("aside");
        if (fs::exists(path)) fs::rename(path, aside);
        fs::create_directories(path + "/x");
        expectMessage([&] { (void)writeSequence(sc, o); },
                      "'" + path + "' is not a file: the render writes its " + name +
                          " there; move it or name another folder");
        EXPECT_TRUE(fs::is_directory(path + "/x")) << name;
        if (std::string(name) != "rgb.txt") {
            EXPECT_EQ(readFile(o.out_dir + "/rgb.txt"), list);
        }
        if (std::string(name) != "groundtruth.txt") {
            EXPECT_EQ(readFile(o.out_dir + "/groundtruth.txt"), gt);
        }
        fs::remove_all(path);
        if (fs::exists(aside)) fs::rename(aside, path);
    }
    ASSERT_TRUE(isRenderCurrent(sc, o));
    // The rawlog a render into the folder wrote is written again, whole or stopped (resumed).
    WriteOptions w = o;
    w.rawlog_path = tmp.str("mine.rawlog");
    (void)writeSequence(sc, w);
    EXPECT_NO_THROW((void)writeSequence(sc, w));
    EXPECT_EQ(io::RawlogReader(w.rawlog_path).size(), std::optional<std::size_t>(2));
    // Not into another folder's render, though.
    WriteOptions other = w;
    other.out_dir = tmp.str("other");
    expectMessage([&] { checkOutputs(sc, other); }, "exists and is not one that a render into");
}

// A real TUM folder (rgb.txt, no render.txt or persons.txt) is not written over, and a
// rawlog that is not named .rawlog, or is the scenario file, is refused (fuzz: both were
// overwritten with rc 0); a render's own folder, whole or stopped, is rendered again.
TEST(RenderSequence, RefusesToOverwriteWhatItDidNotRender) {
    TempDir tmp;
    Scenario sc = smallShort();
    WriteOptions o;
    o.out_dir = tmp.str("tum");
    o.max_frames = 1;
    fs::create_directories(o.out_dir);
    const std::string list = "# color images\n1305031102.175304 rgb/1305031102.175304.png\n";
    std::ofstream(o.out_dir + "/rgb.txt") << list;
    expectMessage([&] { (void)writeSequence(sc, o); },
                  "output folder '" + o.out_dir + "' already holds a TUM sequence (rgb.txt)");
    EXPECT_EQ(readFile(o.out_dir + "/rgb.txt"), list);
    EXPECT_FALSE(fs::exists(o.out_dir + "/persons.txt"));
    // A stopped render of ours (persons.txt, no render.txt), and a whole one: rendered again.
    std::ofstream(o.out_dir + "/persons.txt") << "# person truth\n";
    EXPECT_NO_THROW(checkOutputs(sc, o));
    EXPECT_EQ(writeSequence(sc, o).n_frames, 1u);
    EXPECT_TRUE(isRenderCurrent(sc, o));
    fs::remove(o.out_dir + "/persons.txt");
    EXPECT_NO_THROW(checkOutputs(sc, o));  // render.txt
    EXPECT_EQ(writeSequence(sc, o).n_frames, 1u);

    // Another folder's labels/ (a YOLO dataset), ground truth or preview are not ours to
    // replace: they went without a word.
    for (const char* name : {"labels/0001.txt", "groundtruth.txt", "camera.ini", "preview.png",
                             "rgb/1.png", "depth/1.png"}) {
        const std::string other = tmp.str("other");
        fs::remove_all(other);
        fs::create_directories(fs::path(other + "/" + name).parent_path());
        std::ofstream(other + "/" + name) << "theirs\n";
        WriteOptions w = o;
        w.out_dir = other;
        const std::string top = fs::path(name).begin()->string();
        expectMessage(
            [&] { (void)writeSequence(sc, w); },
            "output folder '" + other + "' holds " + top + ", not of a devslam-synth render");
        EXPECT_EQ(readFile(other + "/" + name), "theirs\n");
    }

    const std::string ini = tmp.str("s.ini");
    std::ofstream(ini) << "[scenario]\n";
    o.rawlog_path = ini;
    expectMessage([&] { (void)writeSequence(sc, o); },
                  "rawlog '" + ini + "': the name must end in .rawlog");
    EXPECT_EQ(readFile(ini), "[scenario]\n");
    sc.source = tmp.str("s.rawlog");  // a scenario of that name is not written over either
    std::ofstream(sc.source) << "[scenario]\n";
    o.rawlog_path = tmp.str("./s.rawlog");
    expectMessage([&] { checkOutputs(sc, o); }, "is the scenario file");
    EXPECT_EQ(readFile(sc.source), "[scenario]\n");
}

// devslam-synth refuses, before it writes anything (no preview.png either), outputs that
// would destroy what it did not make, and an option whose value is missing (fuzz: a real TUM
// folder's lists, the scenario INI given as --rawlog, the photo given as --cut-texture OUT).
TEST(DevslamSynth, RefusesOutputsThatAreNotItsOwnAndMissingValues) {
    TempDir tmp;
    const std::string tum = tmp.str("tum"), list = "# color images\n";
    fs::create_directories(tum);
    std::ofstream(tum + "/rgb.txt") << list;
    const std::string photo = tmp.str("p.png");
    cv::imwrite(photo, cv::imread(kRoot + "/data/images/dog.jpg"));
    const std::string photo_text = readFile(photo);
    const std::string ini = tmp.str("s.ini");
    std::ofstream(ini) << "[scenario]\n";
    for (const auto& [args, says] : std::vector<std::pair<std::string, std::string>>{
             {"short_walking -o " + tum + " --frames 2",
              "output folder '" + tum +
                  "' already holds a TUM sequence (rgb.txt) that "
                  "devslam-synth did not render"},
             {"short_walking -o " + tmp.str("so") + " --frames 2 --rawlog " + ini,
              "rawlog '" + ini + "': the name must end in .rawlog"},
             {"--cut-texture " + photo + " 178,88,102,292 " + photo,
              "--cut-texture OUT '" + photo + "' is the IMAGE"},
             {"--cut-texture " + photo + " 178,88,102,292 " + tmp.str("out.txt"),
              "--cut-texture OUT '" + tmp.str("out.txt") + "': the name must end in .png"},
             {"--cut-texture " + photo + " 178.5,88,102,292 " + tmp.str("out.png"),
              "--cut-texture box '178.5,88,102,292': X,Y,W,H must be whole pixels"},
             {"--cut-texture " + photo + " 178,88,1e10,292 " + tmp.str("out.png"),
              "--cut-texture box '178,88,1e10,292': X,Y,W,H must be whole pixels"},
             {"short_walking -o --frames 2", "devslam-synth: -o needs a value"},
             {"short_walking --rawlog --frames 2", "devslam-synth: --rawlog needs a value"},
             // (an unset variable: it rendered into out/synth/short_walking, or no rawlog)
             {"short_walking -o '' --frames 2", "devslam-synth: -o: the name is empty"},
             {"short_walking -o " + tmp.str("so") + " --rawlog '' --frames 2",
              "devslam-synth: --rawlog: the name is empty"}}) {
        const auto r = devslam::test::runApp("devslam-synth", args);
        EXPECT_EQ(r.rc, 1) << args << "\n" << r.out;
        EXPECT_NE(r.out.find(says), std::string::npos) << args << "\n" << r.out;
    }
    EXPECT_EQ(readFile(tum + "/rgb.txt"), list);
    {
        // A folder another render is writing (two at once mixed their images and truth).
        const devslam::core::FolderClaim busy(tmp.str("busy"));
        const auto r = devslam::test::runApp("devslam-synth",
                                             "short_walking -o " + tmp.str("busy") + " --frames 2");
        EXPECT_EQ(r.rc, 1) << r.out;
        EXPECT_NE(r.out.find("devslam-synth: '" + tmp.str("busy") +
                             "' is being written by another run at the moment"),
                  std::string::npos)
            << r.out;
        EXPECT_TRUE(std::filesystem::is_empty(tmp.str("busy")));
    }
    EXPECT_FALSE(fs::exists(tum + "/preview.png"));
    EXPECT_EQ(readFile(ini), "[scenario]\n");
    EXPECT_FALSE(fs::exists(tmp.str("so")));
    EXPECT_EQ(readFile(photo), photo_text);
    EXPECT_FALSE(fs::exists(tmp.str("out.txt")));
    EXPECT_FALSE(fs::exists(tmp.str("out.png")));
    EXPECT_FALSE(fs::exists("--frames"));
}

// --check reads the scenario, its room and photos with the --set items, says what it would
// render and writes nothing (devslam-bench asks it of each synthetic sequence before any
// render); what a render would refuse it refuses, and it takes no output option.
TEST(DevslamSynth, CheckReadsTheScenarioAndRendersNothing) {
    TempDir tmp;
    auto r = devslam::test::runApp("devslam-synth", "sitting_xyz --check --frames 10 --seed 3");
    ASSERT_EQ(r.rc, 0) << r.out;
    EXPECT_NE(r.out.find("scenario sitting_xyz (" + kRoot +
                         "/sim_worlds/synth/sitting_xyz.ini): 10 frames at 30 Hz, trajectory "
                         "xyz, 2 people; checked, nothing rendered"),
              std::string::npos)
        << r.out;
    EXPECT_EQ(r.out.find("--frames 10:"), std::string::npos) << r.out;
    // --frames is a cap: more than the scenario has renders its frames, and says so (it
    // rendered 60 without a word on the 100 asked for).
    r = devslam::test::runApp("devslam-synth", "short_walking --check --frames 100");
    ASSERT_EQ(r.rc, 0) << r.out;
    EXPECT_NE(r.out.find(": 60 frames at 30 Hz"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("devslam-synth: --frames 100: scenario short_walking has 60 frames "
                         "([scenario] n_frames, or duration x rate_hz), and renders them all"),
              std::string::npos)
        << r.out;
    for (const auto& [args, says] : std::vector<std::pair<std::string, std::string>>{
             {"short_walking --check --set person_1.sped=1",
              "short_walking.ini with --set [person_1]: unknown key 'sped'"},
             {"no_such_scenario --check", "no scenario file 'no_such_scenario' and no '"},
             {"short_walking --check --set person_1.texture=" + tmp.str("nowhere.png"),
              tmp.str("nowhere.png")},
             {"short_walking --check -o " + tmp.str("o"),
              "-o does not go with --check (it renders nothing)"},
             {"short_walking --check --if-changed",
              "--if-changed does not go with --check (it renders nothing)"},
             // (the --check was ignored without a word)
             {"--list --check", "--list takes nothing more, got '--check'"}}) {
        r = devslam::test::runApp("devslam-synth", args);
        EXPECT_EQ(r.rc, 1) << args << "\n" << r.out;
        EXPECT_NE(r.out.find(says), std::string::npos) << args << "\n" << r.out;
    }
    EXPECT_FALSE(fs::exists(tmp.str("o")));
}

// A seated person who moves a hand: the labelled pixels follow the hand (they differ between
// the swing's two extremes only near the hand, and lie on the photo's plane), the person stays
// static in the truth, and a person whose gesture_deg is 0 renders exactly as one without.
TEST(RenderSequence, GesturingHandIsRenderedAndLabelled) {
    Scenario sc = bareRoom({0.6, 2, 1.3}, {3, 2, 1.0});
    sc.n_frames = 4;
    sc.rate_hz = 1.0;  // frame 1: the hand at +gesture_deg, frame 3: at -gesture_deg
    PersonSpec p;
    p.name = "person_1";
    p.kind = PersonKind::Sitting;
    p.texture = kRoot + "/data/textures/person_standing.png";
    p.path = {{3, 2}};
    p.sway_deg = 0;
    p.gesture_deg = 20;
    p.gesture_period = 4;
    p.gesture_region = {0.72, 0.18, 1.0, 0.62};
    p.gesture_pivot = {0.8, 0.2};
    sc.people = {p};
    SequenceRenderer r(sc);
    const auto a = r.render(1), b = r.render(3);
    ASSERT_EQ(a.persons.size(), 1u);
    ASSERT_EQ(b.persons.size(), 1u);
    EXPECT_FALSE(a.persons[0].moving);
    ASSERT_GT(a.persons[0].visible_pixels, 500);
    const cv::Mat la = a.labels == 1, lb = b.labels == 1, changed = la ^ lb;
    const int n_changed = cv::countNonZero(changed);
    EXPECT_GT(n_changed, 20) << "the hand moved";
    EXPECT_LT(n_changed, a.persons[0].visible_pixels / 3) << "the body did not";
    // Every changed pixel lies in the right third of the person's box (the hand's side as
    // the camera sees it: the texture's right columns), and within the gesture's rows.
    const cv::Rect box = a.persons[0].box | b.persons[0].box;
    const cv::Rect changed_box = cv::boundingRect(changed);
    EXPECT_GE(changed_box.x, box.x + box.width / 2) << changed_box << " in " << box;
    EXPECT_LE(changed_box.y + changed_box.height, box.y + int(0.7 * box.height));
    // Labels agree with the rendered colour: the hand's pixels show the photo, not the wall
    // (the depth of labelled pixels is the photo's, about 2.4 m away).
    for (const auto* f : {&a, &b}) {
        const cv::Scalar z = cv::mean(f->clean_depth, f->labels == 1);
        EXPECT_NEAR(z[0], 2.4, 0.1);
    }
    // No gesture: the very same images with or without the region keys.
    sc.people[0].gesture_deg = 0;
    SequenceRenderer still(sc);
    Scenario plain = sc;
    plain.people[0].gesture_region.setZero();
    plain.people[0].gesture_pivot.setZero();
    SequenceRenderer plain_r(plain);
    const auto s1 = still.render(1), s2 = plain_r.render(1);
    EXPECT_EQ(cv::norm(s1.frame.bgr, s2.frame.bgr, cv::NORM_INF), 0.0);
    EXPECT_EQ(cv::countNonZero(s1.labels != s2.labels), 0);
}

// The walking person of the short scenario: moving, visible, and the labelled pixels lie at
// the person's distance from the camera.
// A photo smaller than the 8 x 8 px panel crop failed in an OpenCV assertion naming no file.
TEST(RenderGeometry, ATinyTextureIsRefusedNamingTheFile) {
    TempDir tmp;
    const std::string tiny = tmp.str("tiny.png");
    ASSERT_TRUE(cv::imwrite(tiny, cv::Mat(4, 4, CV_8UC3, cv::Scalar(10, 200, 30))));
    auto sc = bareRoom({1.0, 2.0, 1.5}, {4.0, 2.0, 1.5});
    sc.room.wall_textures = {tiny};
    expectMessage([&] { SequenceRenderer r(sc); },
                  "render: texture '" + tiny + "' is 4x4 px; at least 8x8 needed");
}

// A 24 MP wall photo took 7.7 GB and 10 s a frame (each panel keeps its own crop), and a
// 144 MP one ran out of memory naming no file; a person photo that large, the same.
TEST(RenderGeometry, AHugeTextureIsRefusedNamingTheFile) {
    TempDir tmp;
    const std::string huge = tmp.str("huge.png");
    ASSERT_TRUE(cv::imwrite(huge, cv::Mat(8, kMaxTextureSide + 1, CV_8UC3, cv::Scalar(1, 2, 3))));
    auto sc = bareRoom({1.0, 2.0, 1.5}, {4.0, 2.0, 1.5});
    sc.room.floor_textures = {huge};
    expectMessage([&] { SequenceRenderer r(sc); },
                  "render: texture '" + huge + "' is 2049x8 px; at most 2048 px per side");
    const std::string person = tmp.str("person.png");
    ASSERT_TRUE(cv::imwrite(person, cv::Mat(kMaxTextureSide + 1, 8, CV_8UC4, cv::Scalar::all(255))));
    expectMessage([&] { (void)loadPersonTexture(person); },
                  "person texture '" + person + "' is 8x2049 px; at most 2048 px per side");
    // The largest allowed side still loads.
    ASSERT_TRUE(cv::imwrite(person, cv::Mat(kMaxTextureSide, 8, CV_8UC4, cv::Scalar::all(255))));
    EXPECT_EQ(loadPersonTexture(person).bgr.rows, kMaxTextureSide);
}

TEST(RenderSequence, PersonTruthIsConsistent) {
    SequenceRenderer r(smallShort());
    const auto f = r.render(30);
    ASSERT_EQ(f.persons.size(), 2u);
    const auto& walker = f.persons[0];
    EXPECT_TRUE(walker.moving);
    EXPECT_FALSE(f.persons[1].moving);
    ASSERT_GT(walker.visible_pixels, 200);
    EXPECT_EQ(cv::countNonZero(f.labels == walker.id), walker.visible_pixels);
    EXPECT_EQ(walker.box, cv::boundingRect(f.labels == walker.id));
    const auto s = personStateAt(r.scenario().people[0], r.scenario().elapsed(30));
    mrpt::math::TPoint3D c;
    f.T_wc.inverseComposePoint({s.position.x(), s.position.y(), 1.0}, c);
    const cv::Scalar mean_z = cv::mean(f.clean_depth, f.labels == walker.id);
    EXPECT_NEAR(mean_z[0], c.z, 0.25) << "person pixels at the person's depth";
}

TEST(DepthNoise, RangesEdgesNoiseAndSeed) {
    DepthNoiseOptions o;
    o.dropout = 0;
    cv::Mat d(100, 200, CV_32FC1, cv::Scalar(2.0f));
    d(cv::Rect(150, 0, 50, 100)).setTo(7.0f);  // beyond max_range
    d(cv::Rect(0, 0, 20, 100)).setTo(0.2f);    // closer than min_range
    const cv::Mat n = applyDepthNoise(d, o, 535.4, 7);
    EXPECT_EQ(cv::countNonZero(n(cv::Rect(160, 0, 40, 100))), 0);
    EXPECT_EQ(cv::countNonZero(n(cv::Rect(0, 0, 20, 100))), 0);
    // the discontinuity at u = 150 (2 m | 7 m) is missing on both sides within edge_dilate
    for (int v = 0; v < 100; v += 10) EXPECT_EQ(n.at<float>(v, 149), 0.f);
    const cv::Mat flat = n(cv::Rect(40, 10, 90, 80));
    cv::Scalar mean, sd;
    cv::meanStdDev(flat, mean, sd);
    const double q = 2.0 * 2.0 / (535.4 * o.baseline) * o.disparity_step;  // quantum at 2 m
    EXPECT_NEAR(mean[0], 2.0, 2e-3);
    EXPECT_GT(sd[0], 0.5 * depthSigma(o, 2.0));
    EXPECT_LT(sd[0], depthSigma(o, 2.0) + q);
    EXPECT_EQ(cv::norm(n, applyDepthNoise(d, o, 535.4, 7), cv::NORM_INF), 0.0);
    EXPECT_GT(cv::norm(n, applyDepthNoise(d, o, 535.4, 8), cv::NORM_INF), 0.0);
    o.enabled = false;
    EXPECT_EQ(cv::norm(d, applyDepthNoise(d, o, 535.4, 7), cv::NORM_INF), 0.0);
}

// The defaults' mean speeds over 25 s (meanSpeeds, which devslam-synth --list prints), and
// TUM fr3's published ones: translation like TUM's, rotation of xyz and halfsphere 2-3x
// below it (docs/render.md, "Camera speeds").
TEST(CameraTrajectory, SpeedsLikeTumFr3AndHalfsphereRadius) {
    const auto speeds = [](TrajectoryType t) {
        TrajectoryOptions o;
        o.setDefaultsFor(t);
        return meanSpeeds(o, 751, 30.0);
    };
    // The defaults: TUM fr3's published mean speeds (m/s, deg/s) within 10 %.
    const auto xyz = speeds(TrajectoryType::Xyz);
    EXPECT_NEAR(xyz.m_per_s, 0.208, 0.021);  // walking_xyz: 0.208, 5.49
    EXPECT_NEAR(xyz.deg_per_s, 5.49, 0.55);
    const auto still = speeds(TrajectoryType::Static);
    EXPECT_LT(still.m_per_s, 0.03);  // walking_static: 0.012, 1.39
    EXPECT_NEAR(still.deg_per_s, 1.39, 0.3);
    EXPECT_NEAR(speeds(TrajectoryType::Rpy).deg_per_s, 53.0, 5.3);         // walking_rpy
    EXPECT_NEAR(speeds(TrajectoryType::Halfsphere).deg_per_s, 18.3, 1.8);  // walking_halfsphere
    // The shipped scenarios, as rendered, against the TUM sequence each imitates.
    struct Tum {
        const char* scenario;
        double m_per_s, deg_per_s;  // < 0: not compared (walking_rpy's translation is a few cm)
    };
    for (const Tum& tum : {Tum{"walking_xyz", 0.208, 5.49}, Tum{"walking_towards", 0.208, 5.49},
                           Tum{"sitting_xyz", 0.132, 3.56}, Tum{"sitting_bare", 0.132, 3.56},
                           Tum{"walking_static", -1, 1.39}, Tum{"walking_halfsphere", 0.221, 18.3},
                           Tum{"walking_rpy", -1, 53.0}}) {
        const auto sc = loadScenario(kSynth + "/" + tum.scenario + ".ini");
        const auto v = meanSpeeds(sc.trajectory, sc.n_frames, sc.rate_hz);
        if (tum.m_per_s > 0) {
            EXPECT_NEAR(v.m_per_s, tum.m_per_s, 0.1 * tum.m_per_s) << tum.scenario;
        }
        EXPECT_NEAR(v.deg_per_s, tum.deg_per_s, std::max(0.3, 0.1 * tum.deg_per_s)) << tum.scenario;
    }
    // Two frames at 1 Hz: the one step's length and angle.
    TrajectoryOptions o;
    o.setDefaultsFor(TrajectoryType::Rpy);
    const auto d = cameraPoseAt(o, 1.0) - cameraPoseAt(o, 0.0);
    const auto one = meanSpeeds(o, 2, 1.0);
    EXPECT_NEAR(one.m_per_s, d.norm(), 1e-12);
    EXPECT_NEAR(one.deg_per_s, core::rotationAngle(d) * 180 / kPi, 1e-9);
    EXPECT_EQ(meanSpeeds(o, 1, 30.0).m_per_s, 0.0);
    o.setDefaultsFor(TrajectoryType::Halfsphere);
    const double r0 = (o.position - o.look_at).norm();
    for (double t : {0.0, 3.3, 7.1, 12.0}) {
        const auto p = cameraPoseAt(o, t);
        EXPECT_NEAR((Eigen::Vector3d(p.x(), p.y(), p.z()) - o.look_at).norm(), r0, 1e-9);
    }
    // lookAtPose: the optical axis points at the target, image "down" is world -z.
    const auto L = lookAtPose({0, 0, 1}, {3, 4, 1});
    const auto R = L.getRotationMatrix();
    EXPECT_NEAR(R(0, 2), 0.6, 1e-12);
    EXPECT_NEAR(R(1, 2), 0.8, 1e-12);
    EXPECT_NEAR(R(2, 1), -1.0, 1e-12);
    EXPECT_THROW((void)lookAtPose({0, 0, 0}, {0, 0, 2}), std::invalid_argument);
}

TEST(PersonMotion, PingPongAlongThePath) {
    PersonSpec p;
    p.kind = PersonKind::Walking;
    p.path = {{0, 0}, {2, 0}};
    p.speed = 1.0;
    p.bob = 0;
    EXPECT_NEAR(personStateAt(p, 0.5).position.x(), 0.5, 1e-12);
    EXPECT_NEAR(personStateAt(p, 2.5).position.x(), 1.5, 1e-12);  // on the way back
    EXPECT_NEAR(personStateAt(p, 2.5).velocity.x(), -1.0, 1e-12);
    EXPECT_TRUE(personStateAt(p, 1.0).moving);
    p.kind = PersonKind::Sitting;
    const auto s = personStateAt(p, p.sway_period / 4);
    EXPECT_FALSE(s.moving);
    EXPECT_NEAR(s.sway, p.sway_deg * kPi / 180, 1e-12);
    EXPECT_THROW((void)parsePersonKind("running"), std::invalid_argument);
}

TEST(PersonMotion, PhotoSwaysAboutItsPivotAndFacesTheCamera) {
    PersonSpec p;
    p.kind = PersonKind::Sitting;
    p.path = {{3, 2}};
    p.base_z = -0.3;
    p.sway_deg = 4;
    const Eigen::Vector3d eye(0, 2, 1.2);  // straight down -x from the person
    auto world = [](const mrpt::poses::CPose3D& P, double lx, double lz) {
        double x = 0, y = 0, z = 0;
        P.composePoint(lx, 0, lz, x, y, z);
        return Eigen::Vector3d(x, y, z);
    };
    for (double pivot : {0.0, 0.9}) {
        p.sway_pivot = pivot;
        const Eigen::Vector3d axis(3, 2, -0.3 + pivot);
        const auto still = personPhotoPose(p, personStateAt(p, 0.0), eye, eye);
        const auto swayed = personPhotoPose(p, personStateAt(p, p.sway_period / 4), eye, eye);
        // The pivot stays put; unswayed, the bottom centre is at the place, the photo upright.
        EXPECT_LT((world(swayed, 0, pivot) - axis).norm(), 1e-12) << pivot;
        EXPECT_LT((world(still, 0, 0) - Eigen::Vector3d(3, 2, -0.3)).norm(), 1e-12) << pivot;
        EXPECT_NEAR(world(still, 0, 1).z() - world(still, 0, 0).z(), 1.0, 1e-12);
        // The photo's normal (local y) points at the camera, and the sway stays in its plane.
        const auto R = swayed.getRotationMatrix();
        EXPECT_NEAR(std::abs(R(0, 1)), 1.0, 1e-12);
        EXPECT_NEAR(R(1, 1), 0.0, 1e-12);
        EXPECT_NEAR(R(2, 1), 0.0, 1e-12);
        // The head (1.7 m up the photo) moves sideways by (1.7 - pivot) * sin(sway).
        const double moved = (world(swayed, 0, 1.7) - world(still, 0, 1.7)).norm();
        EXPECT_NEAR(moved, 2 * (1.7 - pivot) * std::sin(2 * kPi / 180), 1e-9) << pivot;
    }
}

// The hand (the gesture region's cells) turns in the photo's plane about its pivot: the pivot
// stays where it is, a point 0.3 m below it moves by 2 * 0.3 * sin(amplitude) between the
// two extremes, and the hand's plane is the photo's, 5 mm towards the viewer.
TEST(PersonMotion, HandSwingsAboutItsPivotInThePhotosPlane) {
    PersonSpec p;
    p.kind = PersonKind::Sitting;
    p.path = {{3, 2}};
    p.height = 1.6;
    p.gesture_deg = 12;
    p.gesture_period = 2.0;
    p.gesture_region = {0.7, 0.2, 1.0, 0.6};
    p.gesture_pivot = {0.8, 0.25};
    const double width = 0.6;
    const Eigen::Vector3d pivot(width / 2 - 0.8 * width, 0.0, 1.6 - 0.25 * 1.6);
    const auto local = [](const mrpt::poses::CPose3D& P, const Eigen::Vector3d& q) {
        double x = 0, y = 0, z = 0;
        P.composePoint(q.x(), q.y(), q.z(), x, y, z);
        return Eigen::Vector3d(x, y, z);
    };
    const auto at = [&](double t) { return gestureLocalPose(p, personStateAt(p, t), width); };
    const auto up = at(0.5), down = at(1.5), rest = at(0.0);
    EXPECT_NEAR(personStateAt(p, 0.5).gesture, 12 * kPi / 180, 1e-12);
    for (const auto& P : {up, down, rest}) {
        EXPECT_LT((local(P, pivot) - pivot - Eigen::Vector3d(0, 0.005, 0)).norm(), 1e-12);
        const auto R = P.getRotationMatrix();
        EXPECT_NEAR(R(1, 1), 1.0, 1e-12) << "the hand stays in the photo's plane";
    }
    const Eigen::Vector3d below = pivot - Eigen::Vector3d(0, 0, 0.3);
    EXPECT_LT((local(rest, below) - below - Eigen::Vector3d(0, 0.005, 0)).norm(), 1e-12);
    EXPECT_NEAR((local(up, below) - local(down, below)).norm(), 2 * 0.3 * std::sin(12 * kPi / 180),
                1e-9);
    // Walkers may gesture too; without gesture_deg nobody does.
    p.kind = PersonKind::Walking;
    p.path = {{3, 2}, {3, 4}};
    EXPECT_NEAR(personStateAt(p, 0.5).gesture, 12 * kPi / 180, 1e-12);
    p.gesture_deg = 0;
    EXPECT_EQ(personStateAt(p, 0.5).gesture, 0.0);
}

// A seated person keeps the yaw of the first frame wherever the camera goes (rigid apart from
// the sway, as the person truth says); a walker turns to face the camera where it is.
TEST(PersonMotion, SeatedPeopleKeepTheirYawWalkersFaceTheCamera) {
    PersonSpec p;
    p.path = {{3, 2}};
    p.sway_deg = 0;
    const Eigen::Vector3d first_eye(0, 2, 1.2), moved_eye(0.3, 2.8, 1.0);
    const auto yawOf = [&](const Eigen::Vector3d& eye) {
        return personPhotoPose(p, personStateAt(p, 1.0), eye, first_eye).yaw();
    };
    for (const auto kind : {PersonKind::Sitting, PersonKind::Standing}) {
        p.kind = kind;
        EXPECT_NEAR(yawOf(moved_eye), yawOf(first_eye), 1e-12) << toString(kind);
        const auto a = personPhotoPose(p, personStateAt(p, 1.0), first_eye, first_eye);
        const auto b = personPhotoPose(p, personStateAt(p, 1.0), moved_eye, first_eye);
        EXPECT_LT((a.asVectorVal() - b.asVectorVal()).norm(), 1e-12) << toString(kind);
    }
    p.kind = PersonKind::Walking;
    p.path = {{3, 2}, {3, 4}};
    p.speed = 0.5;
    // Facing the camera: the photo's normal (local y) points from the person to the eye.
    const auto pose = personPhotoPose(p, personStateAt(p, 1.0), moved_eye, first_eye);
    const Eigen::Vector3d n = pose.getRotationMatrix().col(1);
    Eigen::Vector3d to_eye = moved_eye - Eigen::Vector3d(pose.x(), pose.y(), pose.z());
    to_eye.z() = 0;
    EXPECT_NEAR(std::abs(n.dot(to_eye.normalized())), 1.0, 1e-9);
    EXPECT_GT(std::abs(yawOf(moved_eye) - yawOf(first_eye)), 0.1);
}

TEST(Scenario, ShippedFilesLoadAndTyposAreReported) {
    std::size_t n = 0;
    for (const auto& e : fs::directory_iterator(kSynth)) {
        const auto name = e.path().stem().string();
        if (e.path().extension() != ".ini" || name.find("_room") != std::string::npos) continue;
        const auto sc = loadScenario(e.path().string());
        EXPECT_FALSE(sc.people.empty()) << name;
        EXPECT_FALSE(sc.room.boxes.empty()) << name;
        EXPECT_EQ(sc.K, core::CameraIntrinsics::fromPreset("freiburg3")) << name;
        if (name == "short_walking")
            EXPECT_EQ(sc.n_frames, 60u);
        else
            EXPECT_TRUE(sc.n_frames >= 600 && sc.n_frames <= 900) << name << ": 20-30 s at 30 Hz";
        ++n;
    }
    EXPECT_EQ(n, 8u);  // walking_xyz, sitting_xyz, walking_static, walking_halfsphere,
                       // walking_towards, walking_rpy, short_walking, sitting_bare
    TempDir tmp;
    const std::string room = "room            = office_room.ini";
    const auto withEdit = [&](std::string s, const std::string& from, const std::string& to) {
        const auto pos = s.find(from);
        EXPECT_NE(pos, std::string::npos) << from;
        if (pos != std::string::npos) s.replace(pos, from.size(), to);
        std::ofstream(tmp.str("s.ini")) << s;
        return tmp.str("s.ini");
    };
    const std::string shipped = readFile(kSynth + "/short_walking.ini");
    // Paths are relative to the file that names them: a copy elsewhere names what is missing.
    fs::copy_file(kSynth + "/office_room.ini", tmp.str("office_room.ini"));
    expectMessage([&] { (void)loadScenario(withEdit(shipped, "seed ", "seed ")); },
                  "' is no such file or folder");
    std::string abs = shipped;  // the same scenario with absolute paths
    for (std::size_t p = abs.find("../../data"); p != std::string::npos; p = abs.find("../../data"))
        abs.replace(p, 5, kRoot);
    const std::string base = withEdit(abs, room, "room = " + kSynth + "/office_room.ini"),
                      text = readFile(base);
    EXPECT_NO_THROW((void)loadScenario(base));
    expectMessage([&] { (void)loadScenario(withEdit(text, "rate_hz", "speeed = 3\nrate_hz")); },
                  "[scenario]: unknown key 'speeed'");
    // The shipped room with absolute photo paths, changed by `edit`, behind the scenario:
    // loading must fail with `msg`.
    const std::string room_text = readFile(kSynth + "/office_room.ini");
    const auto expectRoomMessage = [&](auto&& edit, const std::string& msg) {
        std::string r = room_text;
        for (std::size_t p = r.find("../../data"); p != std::string::npos; p = r.find("../../data"))
            r.replace(p, 10, kRoot + "/data");
        edit(r);
        std::ofstream(tmp.str("bad_room.ini")) << r;
        expectMessage(
            [&] {
                (void)loadScenario(withEdit(text, "room = " + kSynth + "/office_room.ini",
                                            "room = " + tmp.str("bad_room.ini")));
            },
            msg);
    };
    for (const auto& bad_msg :
         {std::pair<std::string, std::string>{"wall_blur     = -1",
                                              "bad_room.ini [room] wall_blur: must be 0..100"},
          {"floor_blur    = x", "floor_blur"}}) {
        const std::string& bad = bad_msg.first;
        expectRoomMessage(
            [&](std::string& r) {
                const auto key = bad.substr(0, bad.find('='));  // the shipped line, with its value
                const auto at = r.find(key);
                ASSERT_NE(at, std::string::npos) << key;
                r.replace(at, r.find('\n', at) - at, bad);
            },
            bad_msg.second);
    }
    expectRoomMessage(  // a box's blur
        [](std::string& r) { r.replace(r.find("[box_crate]\n"), 12, "[box_crate]\nblur = 101\n"); },
        tmp.str("bad_room.ini") + " [box_crate] blur: must be 0..100");
    expectRoomMessage(  // a box without a name (was accepted; [person_] was refused)
        [](std::string& r) { r.replace(r.find("[box_crate]\n"), 12, "[box_]\n"); },
        tmp.str("bad_room.ini") + " [box_]: a box's section needs a name after 'box_'");
    // A file that is no image was named only by the renderer, at the first frame, without
    // the key that listed it.
    std::ofstream(tmp.str("not_a_photo.png")) << "text, not a PNG\n";
    expectRoomMessage(
        [&](std::string& r) {
            const auto at = r.find("floor_textures");
            r.replace(at, r.find('\n', at) - at, "floor_textures = " + tmp.str("not_a_photo.png"));
        },
        tmp.str("bad_room.ini") + " [room] floor_textures: '" + tmp.str("not_a_photo.png") +
            "' is not an image OpenCV can read");
    expectRoomMessage(  // a mistyped section is not ignored
        [](std::string& r) { r.replace(r.find("[room]\n"), 7, "[rooom]\n"); },
        tmp.str("bad_room.ini") + ": unknown section [rooom] (known: room, box_*)");
    // --set: written over the scenario file's settings, checked like them.
    (void)withEdit(text, "n_frames", "n_frames");  // s.ini (= base) as it was
    EXPECT_DOUBLE_EQ(loadScenario(base).people.at(0).speed, 0.7);
    const auto fast = loadScenario(base, {"person_1.speed=0.9", "scenario.seed=7"});
    EXPECT_DOUBLE_EQ(fast.people.at(0).speed, 0.9);
    EXPECT_EQ(fast.seed, 7u);
    EXPECT_EQ(fast.overrides.size(), 2u);
    // A key --set wrote is named as such (the scenario's and people's sections said only
    // the file).
    expectMessage([&] { (void)loadScenario(base, {"person_1.sped=0.9"}); },
                  base + " with --set [person_1]: unknown key 'sped'");
    expectMessage([&] { (void)loadScenario(base, {"scenario.zzz=1"}); },
                  base + " with --set [scenario]: unknown key 'zzz'");
    expectMessage([&] { (void)loadScenario(base, {"person_1speed=0.9"}); },
                  "expected SECTION.KEY=VALUE");
    expectMessage([&] { (void)loadScenario(base, {"persn_1.speed=0.9"}); },
                  "unknown section [persn_1]");
    expectMessage(
        [&] {
            (void)loadScenario(
                withEdit(text, "n_frames        = 60", "n_frames = 60\ntexture_filter = cubic"));
        },
        "[scenario] texture_filter: must be linear or nearest, got 'cubic'");
    // A person photo without alpha is named by the file, section and key that give it (the
    // renderer named only the image).
    (void)withEdit(text, "n_frames", "n_frames");  // s.ini (= base) as it was
    std::ofstream(tmp.str("cut.png"), std::ios::binary)
        << readFile(kRoot + "/data/textures/person_standing.png").substr(0, 200);
    for (const auto& [image, says] : std::vector<std::pair<std::string, std::string>>{
             {kRoot + "/data/images/person.jpg", "': need an RGBA PNG (alpha = person)"},
             {tmp.str("cut.png"), "': cannot read"}})
        expectMessage(
            [&] { (void)loadScenario(base, {"person_1.texture=" + image}); },
            tmp.str("s.ini") + " with --set [person_1] texture: person texture '" + image + says);
    expectMessage([&] { (void)loadScenario(withEdit(text, "kind    = walking", "kind = flying")); },
                  tmp.str("s.ini") + " [person_1] kind: unknown person kind 'flying'");
    (void)withEdit(text, "n_frames", "n_frames");  // s.ini (= base) as it was
    // Each range error names its own key (they named the first key of a pair).
    expectMessage([&] { (void)loadScenario(base, {"depth_noise.sigma_b=-1"}); },
                  tmp.str("s.ini") + " with --set [depth_noise] sigma_b: must be >= 0");
    expectMessage(
        [&] { (void)loadScenario(base, {"trajectory.elevation_period=0"}); },
        tmp.str("s.ini") + " with --set [trajectory] elevation_period: must be in [0.1, 1e5] [s]");
    // Bounds (fuzz): values no camera or sensor comes near, which rendered nonsense silently.
    expectMessage([&] { (void)loadScenario(base, {"trajectory.period=[7 9 1e-300]"}); },
                  tmp.str("s.ini") + " with --set [trajectory] period: must be in [0.1, 1e5] [s]");
    expectMessage([&] { (void)loadScenario(base, {"trajectory.rot_period=[5 1e300 8]"}); },
                  "[trajectory] rot_period: must be in [0.1, 1e5] [s]");
    expectMessage([&] { (void)loadScenario(base, {"trajectory.rot_amplitude_deg=[1 1 1e6]"}); },
                  "[trajectory] rot_amplitude_deg: must be in [-90, 90] [deg]");
    expectMessage([&] { (void)loadScenario(base, {"trajectory.azimuth_amplitude_deg=400"}); },
                  "[trajectory] azimuth_amplitude_deg: must be in [-180, 180] [deg]");
    expectMessage([&] { (void)loadScenario(base, {"scenario.rgb_noise_sigma=1e300"}); },
                  tmp.str("s.ini") + " with --set [scenario] rgb_noise_sigma: must be in [0, 255]");
    EXPECT_NO_THROW((void)loadScenario(
        base, {"trajectory.period=[0.1 1e5 11]", "trajectory.rot_amplitude_deg=[-90 90 0]",
               "scenario.rgb_noise_sigma=255"}));
    // A key given with no value is refused, not read as the built-in default (look_at = took
    // [4 2.5 1.0] over the file's value, name = wrote into out/synth/ itself).
    expectMessage([&] { (void)loadScenario(base, {"trajectory.look_at="}); },
                  tmp.str("s.ini") + " with --set [trajectory] look_at: expected 3 numbers, got 0");
    expectMessage([&] { (void)loadScenario(base, {"scenario.name="}); },
                  tmp.str("s.ini") + " with --set [scenario] name: must be a non-empty name");
    // A halfsphere orbit over the top would turn the view over between two frames.
    expectMessage(
        [&] {
            (void)loadScenario(
                base, {"trajectory.type=halfsphere", "trajectory.elevation_amplitude_deg=120"});
        },
        tmp.str("s.ini") + " with --set [trajectory] elevation_amplitude_deg: the orbit reaches");
    // A duration shorter than half a frame is no sequence at all (it wrote empty lists).
    expectMessage(
        [&] {
            (void)loadScenario(base, {"scenario.n_frames=0", "scenario.duration=0.01"});
        },
        "[scenario] n_frames: must be >= 1");
    expectMessage(
        [&] { (void)loadScenario(withEdit(text, "n_frames        = 60", "duration = 0.01")); },
        tmp.str("s.ini") + " [scenario] duration: gives no frame at rate_hz");
    // Bounds (fuzz): a billion frames started a render of days, t0 = 1e300 gave every frame
    // one stamp (each overwrote the last), rate_hz = 1e-300 gave 300-digit stamps.
    (void)withEdit(text, "n_frames", "n_frames");  // s.ini (= base) as it was
    expectMessage([&] { (void)loadScenario(base, {"scenario.n_frames=1000000000"}); },
                  tmp.str("s.ini") + " with --set [scenario] n_frames: must be at most 100000");
    expectMessage([&] { (void)loadScenario(base, {"scenario.n_frames=100001"}); },
                  "[scenario] n_frames: must be at most 100000");
    EXPECT_EQ(loadScenario(base, {"scenario.n_frames=100000"}).n_frames, 100000u);
    expectMessage(
        [&] { (void)loadScenario(withEdit(text, "n_frames        = 60", "duration = 1e9")); },
        tmp.str("s.ini") + " [scenario] duration: gives more than 100000 frames");
    (void)withEdit(text, "n_frames", "n_frames");  // s.ini (= base) as it was
    expectMessage([&] { (void)loadScenario(base, {"scenario.t0=1e300"}); },
                  tmp.str("s.ini") + " with --set [scenario] t0: must be in [0, 1e10] [s]");
    expectMessage([&] { (void)loadScenario(base, {"scenario.t0=-1"}); },
                  "[scenario] t0: must be in [0, 1e10] [s]");
    expectMessage([&] { (void)loadScenario(base, {"scenario.rate_hz=1e-300"}); },
                  tmp.str("s.ini") + " with --set [scenario] rate_hz: must be in [1, 1000] [Hz]");
    expectMessage([&] { (void)loadScenario(base, {"scenario.rate_hz=1001"}); },
                  "[scenario] rate_hz: must be in [1, 1000] [Hz]");
    expectMessage(
        [&] {
            (void)loadScenario(
                withEdit(text, "n_frames        = 60", "n_frames = 60\nduration = 3"));
        },
        "exactly one of 'duration'");
    expectMessage(
        [&] {
            (void)loadScenario(
                withEdit(text, "path    = [2.4 1.6  2.4 4.4]", "path = [2.4 1.6 x 4.4]"));
        },
        "[person_1] path: 'x' is not a number");
    // Numbers are read in full, and the error names the file (MRPT's reader gives 60).
    expectMessage(
        [&] { (void)loadScenario(withEdit(text, "n_frames        = 60", "n_frames = 60x")); },
        tmp.str("s.ini") + " [scenario] n_frames: expected an integer, got '60x'");
    // A gesture needs its region and pivot, as fractions of the photo.
    (void)withEdit(text, "n_frames", "n_frames");  // s.ini (= base) as it was
    const auto gesture = [&](const std::string& region, const std::string& pivot) {
        std::vector<std::string> items = {"person_2.gesture_deg=10"};
        if (!region.empty()) items.push_back("person_2.gesture_region=" + region);
        if (!pivot.empty()) items.push_back("person_2.gesture_pivot=" + pivot);
        return loadScenario(base, items);
    };
    EXPECT_DOUBLE_EQ(gesture("[0.7,0.2,1,0.6]", "[0.8,0.2]").people.at(1).gesture_region[2], 1.0);
    expectMessage([&] { (void)gesture("", "[0.8,0.2]"); }, "gesture_region");
    expectMessage([&] { (void)gesture("[0.7,0.2,0.6,0.6]", "[0.8,0.2]"); },
                  "[person_2] gesture_region: must be [left top right bottom]");
    expectMessage([&] { (void)gesture("[0.7,0.2,1,0.6]", "[0.8]"); },
                  "gesture_pivot: expected 2 numbers, got 1");
    expectMessage([&] { (void)gesture("[0.7,0.2,1,0.6]", "[0.8,1.2]"); },
                  "[person_2] gesture_pivot: must be [across down]");
    expectMessage([&] { (void)loadScenario(base, {"person_2.gesture_period=0"}); },
                  "[person_2] gesture_period: must be in [0.1, 1e5] [s]");
    // Given without a gesture (gesture_deg 0), a region or pivot is checked all the same.
    expectMessage([&] { (void)loadScenario(base, {"person_2.gesture_region=bogus"}); },
                  "[person_2] gesture_region: 'bogus' is not a number");
    expectMessage([&] { (void)loadScenario(base, {"person_2.gesture_pivot=[0.8,1.2]"}); },
                  "[person_2] gesture_pivot: must be [across down]");
    EXPECT_NO_THROW((void)loadScenario(base, {"person_2.gesture_pivot=[0.8,0.2]"}));
    // A bob or sway no person makes.
    expectMessage([&] { (void)loadScenario(base, {"person_1.bob=-5"}); },
                  tmp.str("s.ini") + " with --set [person_1] bob: must be in [0, 0.3] [m]");
    expectMessage([&] { (void)loadScenario(base, {"person_1.bob=1e9"}); }, "bob: must be in");
    expectMessage([&] { (void)loadScenario(base, {"person_2.sway_deg=90"}); },
                  "[person_2] sway_deg: must be in [-45, 45] [deg]");
    // Periods and offsets no person comes near: 1e-7 s made the sitter jump about from frame
    // to frame while labelled static; 1e300 m along the path, the walker stood still while
    // labelled moving.
    expectMessage([&] { (void)loadScenario(base, {"person_2.sway_period=1e-7"}); },
                  "[person_2] sway_period: must be in [0.1, 1e5] [s]");
    expectMessage([&] { (void)loadScenario(base, {"person_1.start_offset=1e300"}); },
                  "[person_1] start_offset: must be in [-1e4, 1e4] [m]");
    // Keys of the other kind of person, and a sitter's second point, were ignored without a
    // word (the renders were byte-identical).
    expectMessage([&] { (void)loadScenario(base, {"person_1.sway_deg=20"}); },
                  tmp.str("s.ini") +
                      " with --set [person_1] sway_deg: is not used by a walking person");
    expectMessage([&] { (void)loadScenario(base, {"person_2.speed=1.2"}); },
                  "[person_2] speed: is not used by a sitting person");
    expectMessage([&] { (void)loadScenario(base, {"person_2.path=[3.5 2.9 1 1]"}); },
                  "[person_2] path: a sitting person stays at one point: give one x y pair");
    // The room's sections are the room file's: --set says where they go.
    expectMessage([&] { (void)loadScenario(base, {"room.wall_blur=3"}); },
                  tmp.str("s.ini") +
                      " with --set: [room] is a section of the room file; the scenario sets it "
                      "with [scenario] room_set (--set \"scenario.room_set=room.KEY=VALUE\")");
    // The camera's sections name the file too, and are checked when loaded, not at the render.
    expectMessage([&] { (void)loadScenario(base, {"trajectory.typ=xyz"}); },
                  tmp.str("s.ini") + " with --set [trajectory]: unknown key 'typ'");
    expectMessage(
        [&] { (void)loadScenario(base, {"trajectory.look_at=[0.6 2.5 0.2]"}); },
        tmp.str("s.ini") + " with --set [trajectory] look_at: straight above or below position");
    expectMessage([&] { (void)loadScenario(base, {"camera.dist=[0 0 x 0 0]"}); },
                  tmp.str("s.ini") + " with --set [camera] dist: 'x' is not a number");
    expectMessage([&] { (void)loadScenario(base, {"camera.dist=[0 0 0 0]"}); },
                  "[camera] dist: must have 5 values");
    // Names the key, and refuses what would take gigabytes before the first frame.
    expectMessage([&] { (void)loadScenario(base, {"camera.preset=fr9"}); },
                  tmp.str("s.ini") + " with --set [camera] preset: unknown camera preset 'fr9'");
    expectMessage(
        [&] { (void)loadScenario(base, {"trajectory.type=spiral"}); },
        tmp.str("s.ini") + " with --set [trajectory] type: unknown trajectory type 'spiral'");
    expectMessage([&] { (void)loadScenario(base, {"camera.width=16000"}); },
                  tmp.str("s.ini") + " with --set [camera] width/height: must be 1..4096 [px]");
    expectMessage(
        [&] {
            (void)loadScenario(
                base, {"camera.width=4", "camera.height=4", "camera.cx=1.5", "camera.cy=1.5"});
        },
        tmp.str("s.ini") + " with --set [camera] width/height: must be at least 8 px");
    // Depth a TUM PNG cannot hold (16 bits of 1/5000 m) failed at the first far frame, after
    // the old outputs were gone.
    expectMessage(
        [&] { (void)loadScenario(base, {"depth_noise.max_range=20"}); },
        tmp.str("s.ini") + " with --set [depth_noise] max_range: must be at most 13.107 m");
    EXPECT_NO_THROW((void)loadScenario(base, {"depth_noise.enabled=false"}));
    expectMessage(
        [&] {
            (void)loadScenario(withEdit(text, "n_frames        = 60",
                                        "n_frames = 60\nroom_set = room.size=[20,5,2.8]"),
                               {"depth_noise.enabled=false"});
        },
        "[scenario] far_clip: with [depth_noise] enabled = false the depth reaches");
    (void)withEdit(text, "n_frames", "n_frames");  // s.ini (= base) as it was
    expectMessage([&] { (void)loadScenario(base, {"scenario.n_frames=0"}); },
                  tmp.str("s.ini") + " with --set [scenario] n_frames: must be >= 1");
    // Clip planes that ruin the depth: near_clip 0.001 put it 4 cm off and lost person
    // pixels, far_clip 1e300 rendered no depth and nobody; both went without a word.
    expectMessage([&] { (void)loadScenario(base, {"scenario.near_clip=0.001"}); },
                  tmp.str("s.ini") + " with --set [scenario] near_clip: must be >= 0.01 [m]");
    expectMessage([&] { (void)loadScenario(base, {"scenario.far_clip=1e300"}); },
                  tmp.str("s.ini") + " with --set [scenario] far_clip: must be <= 1e4 [m]");
    EXPECT_NO_THROW((void)loadScenario(base, {"scenario.near_clip=0.01", "scenario.far_clip=1e4"}));
    expectMessage([&] { (void)loadScenario(base, {"person_9.speed=1"}); },  // a new person
                  tmp.str("s.ini") + " with --set [person_9] kind: missing");
    expectMessage(
        [&] { (void)loadScenario(base, {"scenario.room=nowhere.ini"}); },
        tmp.str("s.ini") + " [scenario] room: '" + tmp.str("nowhere.ini") + "' is no such file");
    // One that is there but no file was "no such file" too.
    expectMessage([&] { (void)loadScenario(base, {"scenario.room=/dev/zero"}); },
                  tmp.str("s.ini") + " [scenario] room: '/dev/zero' is no regular file");
    expectMessage([&] { (void)loadScenario(base, {"scenario.room=" + tmp.str("")}); },
                  "' is a folder, not a room file");
    // room_set: written over the room file's [room] and [box_*] settings, checked like them.
    const auto withRoomSet = [&](const std::string& items) {
        return withEdit(text, "n_frames        = 60", "n_frames = 60\nroom_set = " + items);
    };
    const auto set = loadScenario(withRoomSet("box_desk.blur=5 room.wall_blur=3"));
    EXPECT_DOUBLE_EQ(set.room.wall_blur, 3.0);
    EXPECT_EQ(set.room.overrides.size(), 2u);
    for (const auto& b : set.room.boxes) EXPECT_DOUBLE_EQ(b.blur, b.name == "box_desk" ? 5 : 0);
    expectMessage([&] { (void)loadScenario(withRoomSet("room.size=[10000,10000,2.8]")); },
                  "[room] size: a room of 10000 x 10000 x 2.8 m in panels of 1.1 x 0.8 m has "
                  "2.2742e+08 panels (at most 5000)");
    expectMessage([&] { (void)loadScenario(withRoomSet("box_dsk.blur=5")); },
                  "room_set item 'box_dsk.blur=5': the room file has no [box_dsk] section");
    expectMessage([&] { (void)loadScenario(withRoomSet("box_desk.blurr=5")); },
                  "[box_desk]: unknown key 'blurr'");
    expectMessage([&] { (void)loadScenario(withRoomSet("box_desk.blur=500")); },
                  "[box_desk] blur: must be 0..100 [px] (room_set of " + tmp.str("s.ini") + ")");
    expectMessage([&] { (void)loadScenario(withRoomSet("box_desk")); },
                  "room_set item 'box_desk': expected SECTION.KEY=VALUE");
    // --set reaches room_set too (one item: --set values have no spaces).
    (void)withEdit(text, "n_frames", "n_frames");
    const auto via_set = loadScenario(base, {"scenario.room_set=box_crate.blur=2"});
    for (const auto& b : via_set.room.boxes)
        EXPECT_DOUBLE_EQ(b.blur, b.name == "box_crate" ? 2 : 0);
}

// sitting_bare is sitting_xyz's room with every box blurred through room_set: the same
// room file, boxes and walls, only the boxes' blur differs.
TEST(Scenario, TheCameraAndThePeopleStayInTheRoom) {
    // Outside the room they rendered walls seen from behind, or nobody, without a word; so
    // did the room's boxes.
    const std::string path = kRoot + "/sim_worlds/synth/walking_xyz.ini";
    for (const auto& [item, message] : std::vector<std::pair<std::string, std::string>>{
             {"person_1.path=[100 100 200 200]",
              "[person_1] path: the point (100, 100) lies outside the room (0..5.5 x 0..5 m)"},
             {"trajectory.position=[100 100 100]",
              "[trajectory] position: the camera at t = 0 s is at ("},
             {"person_.height=1.7", "[person_]: a person's section needs a name"},
             {"person_1.base_z=-100",
              "[person_1] base_z: must be in (-height, room height) = (-1.75, 2.8) [m]: the "
              "person is under the floor or over the ceiling"},
             {"person_1.base_z=1e9", "[person_1] base_z: must be in (-height, room height)"},
             // A box outside the room, or under its floor, rendered as nothing.
             {"scenario.room_set=box_crate.base=[40 4.3 0]",
              "office_room.ini [box_crate] base: (40, 4.3, 0) lies outside the room (0..5.5 x "
              "0..5 x 0..2.8 m)"},
             {"scenario.room_set=box_crate.base=[4.9 4.3 -10]",
              "[box_crate] base: (4.9, 4.3, -10) lies outside the room"}}) {
        try {
            (void)render::loadScenario(path, {item});
            ADD_FAILURE() << "accepted: " << item;
        } catch (const std::invalid_argument& e) {
            EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
        }
    }
    // A camera 0.1 m from the wall that moves 0.25 m to and fro every 0.5 s leaves the room in
    // half of each period; only every 300th frame of these 60000 was checked (10 s: always the
    // same phase), and it passed.
    try {
        (void)render::loadScenario(path,
                                   {"scenario.duration=2000", "trajectory.position=[0.1 2.5 1.3]",
                                    "trajectory.period=[7 9 0.5]"});
        ADD_FAILURE() << "a camera that leaves the room was accepted";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("outside the room"), std::string::npos) << e.what();
    }
}

TEST(Scenario, SittingBareBlursTheOfficeRoomsFurniture) {
    const auto xyz = loadScenario(kSynth + "/sitting_xyz.ini");
    const auto bare = loadScenario(kSynth + "/sitting_bare.ini");
    EXPECT_EQ(bare.room.source, xyz.room.source);
    ASSERT_EQ(bare.room.boxes.size(), xyz.room.boxes.size());
    ASSERT_FALSE(bare.room.boxes.empty());
    for (std::size_t i = 0; i < bare.room.boxes.size(); ++i) {
        EXPECT_EQ(bare.room.boxes[i].textures, xyz.room.boxes[i].textures);
        EXPECT_DOUBLE_EQ(xyz.room.boxes[i].blur, 0.0);
        EXPECT_DOUBLE_EQ(bare.room.boxes[i].blur, xyz.room.wall_blur) << bare.room.boxes[i].name;
    }
    EXPECT_DOUBLE_EQ(bare.room.wall_blur, xyz.room.wall_blur);
    ASSERT_EQ(bare.people.size(), xyz.people.size());
    for (std::size_t i = 0; i < bare.people.size(); ++i) {  // the same sitters, same motion
        const auto &a = bare.people[i], &b = xyz.people[i];
        EXPECT_EQ(a.path, b.path);
        EXPECT_EQ(a.sway_deg, b.sway_deg);
        EXPECT_EQ(a.sway_period, b.sway_period);
        EXPECT_EQ(a.gesture_deg, b.gesture_deg);
        EXPECT_EQ(a.gesture_period, b.gesture_period);
        EXPECT_EQ(a.gesture_region, b.gesture_region);
        EXPECT_EQ(a.gesture_pivot, b.gesture_pivot);
    }
}

TEST(PersonTexture, GrabCutCutsThePhotoAndCellsFollowAlpha) {
    const cv::Mat img = cv::imread(kRoot + "/data/images/person.jpg");
    ASSERT_FALSE(img.empty());
    const cv::Mat rgba = cutPersonTexture(img, {178, 88, 102, 292}, 2);
    ASSERT_EQ(rgba.type(), CV_8UC4);
    std::vector<cv::Mat> ch;
    cv::split(rgba, ch);
    const double frac = cv::countNonZero(ch[3]) / double(rgba.total());
    EXPECT_GT(frac, 0.3);
    EXPECT_LT(frac, 0.9);
    EXPECT_THROW((void)cutPersonTexture(img, {600, 400, 100, 100}), std::invalid_argument);
    const auto tex = loadPersonTexture(kRoot + "/data/textures/person_standing.png", 4);
    EXPECT_GT(cv::countNonZero(tex.cell_mask), 100);
    EXPECT_LT(cv::countNonZero(tex.cell_mask), int(tex.cell_mask.total()));
    EXPECT_THROW((void)loadPersonTexture(kRoot + "/data/images/dog.jpg"), std::runtime_error);
}
