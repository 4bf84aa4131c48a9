// The whole SLAM on the 37 shipped TUM frames (fr1_xyz_first37), and on sequences
// synthesized from them to test robustness: black frames, zero depth, a repeated frame,
// a 2 s gap, a dynamic mask, and a forward-backward run that must close a loop.
#include <devslam/core/Config.h>
#include <devslam/core/Pose.h>
#include <devslam/eval/Metrics.h>
#include <devslam/io/RgbdReader.h>
#include <devslam/slam/MapFile.h>
#include <devslam/slam/Slam.h>

#include <gtest/gtest.h>

#include <unistd.h>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

using namespace devslam;

namespace {

const std::string kData = std::string(DEVSLAM_SOURCE_DIR) + "/data/tum/fr1_xyz_first37";
const std::string kIni = std::string(DEVSLAM_SOURCE_DIR) + "/config_ini/slam_tum_fr1.ini";

struct Sequence {
    std::vector<core::Frame> frames;
    core::Trajectory gt;
};

const Sequence& realSequence() {
    static const Sequence seq = [] {
        Sequence s;
        io::ReaderOptions ro;
        ro.camera = "freiburg1";
        auto reader = io::openRgbd(kData, ro);
        while (auto f = reader->next()) s.frames.push_back(std::move(*f));
        s.gt = reader->groundTruth().value();
        return s;
    }();
    return seq;
}

/// Deep copy (cv::Mat copies share pixels; the tests modify images).
std::vector<core::Frame> cloneFrames() {
    std::vector<core::Frame> out = realSequence().frames;
    for (auto& f : out) {
        f.bgr = f.bgr.clone();
        f.depth = f.depth.clone();
    }
    return out;
}

slam::SlamOptions options() {
    return slam::SlamOptions::fromConfig(*core::loadIni(kIni));
}

struct RunOut {
    core::Trajectory traj;
    std::vector<std::size_t> lost;
    std::vector<slam::TrackingState> states;
    std::size_t keyframes = 0, landmarks = 0;
    int loops = 0;
};

RunOut runSlam(const std::vector<core::Frame>& frames, const slam::SlamOptions& opts,
               const cv::Mat& mask = {}, slam::Slam** keep = nullptr) {
    static std::unique_ptr<slam::Slam> last;
    last = std::make_unique<slam::Slam>(opts);
    RunOut out;
    for (std::size_t i = 0; i < frames.size(); ++i) {
        core::Frame f = frames[i];
        f.index = i;
        const auto r = last->process(f, mask);
        out.states.push_back(r.track.state);
        if (std::getenv("SLAM_TEST_VERBOSE"))
            std::printf("%zu %s inl=%d match=%d kf=%d %s\n", i,
                        slam::toString(r.track.state).c_str(), r.track.n_inliers, r.track.n_matches,
                        r.mapping.keyframe_inserted ? 1 : 0, r.track.reason.c_str());
    }
    out.traj = last->trajectory();
    out.lost = last->lostFrames();
    out.keyframes = last->map().keyframes().size();
    out.landmarks = last->map().landmarks().size();
    out.loops = last->loopsClosed();
    if (keep) *keep = last.get();
    return out;
}

/// ATE over the frames that are not in `skip` (e.g. frames lost on purpose).
double ate(const core::Trajectory& gt, const core::Trajectory& est,
           const std::vector<std::size_t>& skip = {}) {
    core::Trajectory e;
    for (std::size_t i = 0; i < est.size(); ++i)
        if (std::find(skip.begin(), skip.end(), i) == skip.end()) e.push_back(est[i]);
    return eval::computeAte(gt, e).trans.rmse;
}

/// Largest distance [m] between the positions of two trajectories of the same frames.
double largestPoseDifference(const core::Trajectory& a, const core::Trajectory& b) {
    double worst = 0;
    for (std::size_t i = 0; i < a.size() && i < b.size(); ++i)
        worst = std::max(worst, (a[i].pose.translation() - b[i].pose.translation()).norm());
    std::printf("largest pose difference %.5f m\n", worst);
    return worst;
}

}  // namespace

TEST(SlamIntegration, RealFramesMeetTheAteBound) {
    const auto& seq = realSequence();
    ASSERT_GE(seq.frames.size(), 30u);
    const auto r = runSlam(seq.frames, options());
    EXPECT_EQ(r.traj.size(), seq.frames.size());  // every frame has a pose
    EXPECT_TRUE(r.lost.empty());
    EXPECT_GE(r.keyframes, 3u);
    EXPECT_GT(r.landmarks, 1000u);
    const double rmse = ate(seq.gt, r.traj);
    std::printf("ATE RMSE %.5f m, keyframes %zu, landmarks %zu\n", rmse, r.keyframes, r.landmarks);
    EXPECT_LE(rmse, 0.006);  // issue 4 target; measured 0.0059 (see docs/RESULTS.md)
}

TEST(SlamIntegration, ASavedMapIsLocalizedInFromAnotherStart) {
    // Map the 32 frames, save the map, load it, and localize frames 16-31 in it from scratch:
    // the first of them finds its pose against the map's keyframes (no pose to start from),
    // and every frame's pose is the mapping run's, in the map's frame (not the first
    // frame's, as a new SLAM run's would be).
    const auto& seq = realSequence();
    const auto opts = options();
    slam::Slam* mapper = nullptr;
    const auto made = runSlam(seq.frames, opts, {}, &mapper);
    (void)mapper->finalize(seq.frames.front().K);
    const core::Trajectory mapped = mapper->trajectory();
    const char* tmp = std::getenv("TMPDIR");
    const std::string path = std::string(tmp ? tmp : "/tmp") + "/devslam_localize_" +
                             std::to_string(::getpid()) + ".yml";
    slam::saveMap(path, mapper->map(), opts.orb, seq.frames.front().K);
    const slam::MapFile m = slam::loadMap(path);
    std::remove(path.c_str());
    const std::size_t kfs = m.map.keyframes().size(), lms = m.map.landmarks().size();
    EXPECT_EQ(kfs, made.keyframes);
    EXPECT_EQ(lms, mapper->map().landmarks().size());

    const std::size_t start = 16;
    // (so that a run starting from the identity, as a new map's first frame does, fails)
    const double start_m = mapped[start].pose.translation().norm();
    std::printf("frame %zu is %.3f m from the map's origin\n", start, start_m);
    EXPECT_GT(start_m, 0.02);
    std::vector<core::Frame> later;
    // Two black frames first: lost (nothing to match) until a real one localizes.
    for (int i = 0; i < 2; ++i) {
        core::Frame f = seq.frames[start];
        f.bgr = cv::Mat(f.bgr.size(), f.bgr.type(), cv::Scalar::all(0));  // new pixels
        f.timestamp -= 0.1 * (2 - i);
        later.push_back(f);
    }
    later.insert(later.end(), seq.frames.begin() + start, seq.frames.end());
    // Localization only, then with the map extended from the first pose found in it; and
    // localization only with the keyframes ranked by matches instead of the place index.
    const std::pair<bool, bool> cases[] = {{false, true}, {true, true}, {false, false}};
    for (const auto& [extend, place] : cases) {
        SCOPED_TRACE(std::string(extend ? "extended" : "localization only") +
                     (place ? "" : ", place_recognition = false"));
        auto o = opts;
        o.tracker.place_recognition = place;
        slam::Slam loc(o);
        loc.localizeIn(m.map, extend);
        ASSERT_EQ(loc.placeIndex() != nullptr, place);
        if (place) {
            EXPECT_EQ(loc.placeIndex()->keyframes(), kfs);
        }
        EXPECT_TRUE(loc.localizing());
        EXPECT_FALSE(loc.localized());
        int inserted = 0;
        for (std::size_t i = 0; i < later.size(); ++i) {
            core::Frame f = later[i];
            f.index = i;
            const auto r = loc.process(f, {});
            inserted += r.mapping.keyframe_inserted ? 1 : 0;
            if (i < 2) {
                EXPECT_FALSE(r.track.pose_valid) << i;
                EXPECT_EQ(r.track.state, slam::TrackingState::Lost) << i;
                continue;
            }
            ASSERT_TRUE(r.track.pose_valid) << i << ": " << r.track.reason;
            EXPECT_EQ(r.track.state,
                      i == 2 ? slam::TrackingState::Relocalized : slam::TrackingState::Ok)
                << i;
        }
        EXPECT_TRUE(loc.localized());
        (void)loc.finalize(seq.frames.front().K);  // adjusts nothing without extend
        const core::Trajectory got = loc.trajectory();
        ASSERT_EQ(got.size(), later.size());
        double worst_m = 0, worst_deg = 0;
        for (std::size_t i = 2; i < later.size(); ++i) {
            const Eigen::Isometry3d want = core::toIsometry(mapped[start + i - 2].pose);
            const Eigen::Isometry3d d = want.inverse() * core::toIsometry(got[i].pose);
            worst_m = std::max(worst_m, d.translation().norm());
            worst_deg = std::max(worst_deg, Eigen::AngleAxisd(d.linear()).angle() * 180 / M_PI);
        }
        std::printf(
            "%s: largest difference from the mapping run %.4f m, %.3f deg; %d keyframes made\n",
            extend ? "extended" : "localized", worst_m, worst_deg, inserted);
        EXPECT_LT(worst_m, 0.005);
        EXPECT_LT(worst_deg, 0.5);
        EXPECT_EQ(loc.lostFrames(), (std::vector<std::size_t>{0, 1}));
        if (extend) {  // keyframes and landmarks of its own
            EXPECT_GE(inserted, 1);
            EXPECT_EQ(loc.map().keyframes().size(), kfs + static_cast<std::size_t>(inserted));
            EXPECT_GT(loc.map().landmarks().size(), lms);
            continue;
        }
        // The map is the loaded one, untouched (counters aside).
        EXPECT_EQ(inserted, 0);
        EXPECT_EQ(loc.map().keyframes().size(), kfs);
        EXPECT_EQ(loc.map().landmarks().size(), lms);
        auto kf = loc.map().keyframes().begin();
        for (const auto& [id, k] : mapper->map().keyframes())
            EXPECT_EQ((kf++)->second.T_wc.matrix(), k.T_wc.matrix());
        EXPECT_THROW(loc.localizeIn(slam::Map{}), std::logic_error);
    }
    slam::Slam fresh(opts);
    EXPECT_THROW(fresh.localizeIn(slam::Map{}), std::invalid_argument);
}

TEST(SlamIntegration, DeterministicRuns) {
    const auto& seq = realSequence();
    std::vector<core::Frame> first(seq.frames.begin(), seq.frames.begin() + 15);
    const auto a = runSlam(first, options());
    const auto b = runSlam(first, options());
    ASSERT_EQ(a.traj.size(), b.traj.size());
    for (std::size_t i = 0; i < a.traj.size(); ++i)
        EXPECT_EQ(a.traj[i].pose.asVectorVal(), b.traj[i].pose.asVectorVal()) << i;
}

TEST(SlamIntegration, BlackFramesAreLostThenRecovered) {
    auto frames = cloneFrames();
    for (int i = 10; i <= 12; ++i) frames[i].bgr.setTo(cv::Scalar::all(0));
    const auto r = runSlam(frames, options());
    EXPECT_EQ(r.lost, (std::vector<std::size_t>{10, 11, 12}));
    EXPECT_EQ(r.states[13], slam::TrackingState::Relocalized);
    for (std::size_t i = 14; i < frames.size(); ++i)
        EXPECT_EQ(r.states[i], slam::TrackingState::Ok) << i;
    EXPECT_LE(ate(realSequence().gt, r.traj, r.lost), 0.01);
}

TEST(SlamIntegration, ZeroDepthFramesDoNotBreakTracking) {
    auto frames = cloneFrames();
    for (int i = 8; i <= 13; ++i) frames[i].depth.setTo(0.0f);
    const auto r = runSlam(frames, options());
    // Without depth the frames still track on the map (2D-3D); nothing is lost.
    EXPECT_TRUE(r.lost.empty());
    EXPECT_LE(ate(realSequence().gt, r.traj), 0.01);
}

TEST(SlamIntegration, AllZeroDepthFromTheStartIsReportedNotInitialized) {
    auto frames = cloneFrames();
    frames.resize(5);
    for (auto& f : frames) f.depth.setTo(0.0f);
    const auto r = runSlam(frames, options());
    EXPECT_EQ(r.lost.size(), 5u);
    for (auto s : r.states) EXPECT_EQ(s, slam::TrackingState::NotInitialized);
    EXPECT_EQ(r.keyframes, 0u);
}

TEST(SlamIntegration, RepeatedFrame) {
    const auto& src = realSequence().frames;
    std::vector<core::Frame> frames(src.begin(), src.begin() + 11);
    for (int k = 1; k <= 3; ++k) {
        core::Frame f = src[10];
        f.timestamp += 0.005 * k;  // the same image again (a driver hiccup)
        frames.push_back(f);
    }
    frames.insert(frames.end(), src.begin() + 11, src.end());
    const auto r = runSlam(frames, options());
    EXPECT_TRUE(r.lost.empty());
    EXPECT_LE(ate(realSequence().gt, r.traj), 0.01);
}

// A camera that stands still for 8 s (a robot waiting): the interval rule adds a keyframe
// every max_frames frames. With keyframe culling the redundant ones go, and every frame
// keeps its pose (those of a culled keyframe are moved to the keyframe before it).
TEST(SlamIntegration, RedundantKeyframesOfAStillCameraAreCulled) {
    const auto& src = realSequence().frames;
    std::vector<core::Frame> frames(src.begin(), src.begin() + 6);
    for (int k = 1; k <= 240; ++k) {
        core::Frame f = src[5];
        f.timestamp += k / 30.0;
        frames.push_back(f);
    }
    auto opts = options();
    const auto kept = runSlam(frames, opts);
    opts.mapping.redundant_keyframe_ratio = 0.9;
    slam::Slam* s = nullptr;
    const auto culled = runSlam(frames, opts, {}, &s);
    std::printf("keyframes: %zu without culling, %zu with\n", kept.keyframes, culled.keyframes);
    EXPECT_GE(kept.keyframes, 240u / opts.keyframes.max_frames);
    EXPECT_LE(culled.keyframes, static_cast<std::size_t>(opts.local_ba.window) + 2);
    EXPECT_TRUE(culled.lost.empty());
    ASSERT_EQ(culled.traj.size(), kept.traj.size());
    const double worst = largestPoseDifference(kept.traj, culled.traj);
    EXPECT_LT(worst, 0.001);
    // The map stays consistent: every observation's keyframe exists and points back.
    for (const auto& [id, lm] : s->map().landmarks()) {
        EXPECT_FALSE(lm.observations.empty());
        EXPECT_NE(s->map().keyframes().count(lm.ref_kf), 0u);
        for (const auto& [kf, kp] : lm.observations)
            EXPECT_EQ(s->map().keyframe(kf).landmark_of_kp.at(kp), id);
    }
}

// Forward and backward over the real frames: keyframes of the later passes are redundant
// with the earlier ones' and are culled while the camera moves, so their frames move to a
// keyframe some centimetres away and must keep their poses.
TEST(SlamIntegration, CullingKeyframesOfAMovingCameraKeepsTheFramesPoses) {
    const auto& src = realSequence().frames;
    std::vector<core::Frame> frames;
    double t = src.front().timestamp;
    const auto push = [&](std::size_t i) {
        core::Frame f = src[i];
        f.timestamp = t;
        t += 1.0 / 30.0;
        frames.push_back(f);
    };
    // Six passes: keyframes are culled once loops have tied the passes together (the
    // tracker's local map is the newest keyframes; measured: none culled in three passes).
    push(0);
    for (int pass = 0; pass < 6; ++pass)
        for (std::size_t k = 1; k < src.size(); ++k) push(pass % 2 ? src.size() - 1 - k : k);
    auto opts = options();
    const auto kept = runSlam(frames, opts);
    opts.mapping.redundant_keyframe_ratio = 0.9;
    const auto culled = runSlam(frames, opts);
    std::printf("keyframes: %zu without culling, %zu with\n", kept.keyframes, culled.keyframes);
    EXPECT_LT(culled.keyframes, kept.keyframes);
    ASSERT_EQ(culled.traj.size(), kept.traj.size());
    const double worst = largestPoseDifference(kept.traj, culled.traj);
    // Measured 1.6 mm (the maps differ, so do the local BAs); 0.26 m when the culled
    // keyframe's frames keep their relative poses unchanged.
    EXPECT_LT(worst, 0.005);
}

TEST(SlamIntegration, TwoSecondGap) {
    const auto& seq = realSequence();
    std::vector<core::Frame> frames;
    core::Trajectory gt;
    const double t_gap = seq.frames[12].timestamp;
    for (std::size_t i = 0; i < seq.frames.size(); ++i) {
        if (i >= 12 && i < 20) continue;  // 8 frames missing...
        core::Frame f = seq.frames[i];
        if (i >= 20) f.timestamp += 2.0;  // ...and 2 s without data
        frames.push_back(f);
    }
    for (auto g : seq.gt) {
        if (g.t > t_gap) g.t += 2.0;
        gt.push_back(g);
    }
    const auto r = runSlam(frames, options());
    EXPECT_LE(r.lost.size(), 1u);  // measured: 0 (wide search / relocalization)
    for (std::size_t i = frames.size() - 5; i < frames.size(); ++i)
        EXPECT_EQ(r.states[i], slam::TrackingState::Ok);
    EXPECT_LE(ate(gt, r.traj, r.lost), 0.012);
}

TEST(SlamIntegration, NoLandmarkIsCreatedInsideTheDynamicMask) {
    const auto& seq = realSequence();
    cv::Mat mask(seq.frames[0].bgr.size(), CV_8UC1, cv::Scalar(0));
    mask(cv::Rect(0, 0, 320, mask.rows)).setTo(255);  // left half "moving person"
    slam::Slam* s = nullptr;
    std::vector<core::Frame> frames(seq.frames.begin(), seq.frames.begin() + 20);
    const auto r = runSlam(frames, options(), mask, &s);
    ASSERT_NE(s, nullptr);
    ASSERT_GT(r.landmarks, 100u);
    for (const auto& [id, lm] : s->map().landmarks()) {
        ASSERT_FALSE(lm.observations.empty());
        for (const auto& [kf, kp] : lm.observations) {
            const auto& pt = s->map().keyframe(kf).features.keypoints[kp].pt;
            // Keypoints are stored undistorted; near the image centre column the
            // undistortion moves them by less than a pixel.
            EXPECT_GE(pt.x, 318.0f) << "landmark " << id;
        }
    }
}

TEST(SlamIntegration, ForwardBackwardClosesALoop) {
    const auto& seq = realSequence();
    std::vector<core::Frame> frames = cloneFrames();
    core::Trajectory gt = seq.gt;
    const double t_end = seq.frames.back().timestamp;
    const double dt = 1.0 / 30.0;
    // Back along the same path: frame i again, at a later stamp.
    for (int i = static_cast<int>(seq.frames.size()) - 2; i >= 0; --i) {
        core::Frame f = seq.frames[i];
        f.timestamp = t_end + dt * (static_cast<int>(seq.frames.size()) - 1 - i);
        frames.push_back(f);
    }
    for (std::size_t i = seq.frames.size(); i < frames.size(); ++i) {
        // Ground truth for the replayed frames: the pose at the original stamp.
        const double t_orig = seq.frames[2 * seq.frames.size() - 2 - i].timestamp;
        const auto it =
            std::min_element(seq.gt.begin(), seq.gt.end(), [&](const auto& a, const auto& b) {
                return std::abs(a.t - t_orig) < std::abs(b.t - t_orig);
            });
        gt.push_back({frames[i].timestamp, it->pose});
    }
    std::sort(gt.begin(), gt.end(), [](const auto& a, const auto& b) { return a.t < b.t; });
    auto opts = options();
    opts.loop.min_keyframe_gap = 4;
    opts.keyframes.max_frames = 5;
    // Every verified loop closed at once, and loops closed only in confirmed pairs.
    for (int confirm : {0, 2}) {
        opts.loop.confirm_keyframes = confirm;
        const auto r = runSlam(frames, opts);
        EXPECT_TRUE(r.lost.empty()) << confirm;
        EXPECT_GE(r.loops, confirm > 0 ? 2 : 1) << confirm;
        if (confirm > 0) {
            EXPECT_EQ(r.loops % 2, 0) << "confirmed loops close in pairs";
        }
        EXPECT_LE(ate(gt, r.traj), 0.01) << confirm;
        std::cout << "confirm_keyframes " << confirm << ": " << r.loops << " loops\n";
    }
}

TEST(SlamIntegration, FramesHeldForRefinementStayBoundedWithoutLocalBa) {
    // refine_frames keeps a frame's observations while its keyframe is in the local-BA
    // window and releases them when it leaves: with local BA off too (they were kept to the
    // end of the run then). A keyframe every 3 frames: 12 keyframes on the 37 frames, the
    // window 5 of them, so about 15 frames may be held at a time. A final BA over 8
    // keyframes (final_window) holds the frames of those 8, for its own refinement.
    const auto& seq = realSequence();
    std::size_t held_window = 0;
    for (const auto& [ba, final_window] : {std::pair{true, 0}, {false, 0}, {true, 8}}) {
        SCOPED_TRACE("local BA " + std::to_string(ba) + ", final_window " +
                     std::to_string(final_window));
        auto opts = options();
        opts.keyframes.max_frames = 3;
        opts.local_ba.enabled = ba;
        opts.local_ba.final_window = final_window;
        slam::Slam* s = nullptr;
        const auto r = runSlam(seq.frames, opts, {}, &s);
        ASSERT_NE(s, nullptr);
        EXPECT_TRUE(r.lost.empty());
        ASSERT_GE(r.keyframes, 10u);
        const auto bound = static_cast<std::size_t>(
            std::max(opts.local_ba.window, final_window) * opts.keyframes.max_frames);
        const std::size_t held = s->framesHeldForRefinement();
        EXPECT_LE(held, bound);
        EXPECT_GT(held, 0u) << "the newest frames are held";
        if (ba && final_window == 0) held_window = held;
        if (final_window > 0) {
            EXPECT_GT(held, held_window) << "the final window's older frames are held too";
        }
    }
}

// A map of one keyframe has no word that tells keyframes apart, so its place index finds
// nothing; the tracker then verifies every keyframe (fewer than reloc_keyframes) and the
// frames after it are localized in it. (With the index alone none was, found in review.)
TEST(SlamIntegration, AMapOfOneKeyframeIsLocalizedInWithPlaceRecognition) {
    const auto& seq = realSequence();
    const auto opts = options();
    ASSERT_TRUE(opts.tracker.place_recognition);
    slam::Slam* mapper = nullptr;
    const std::vector<core::Frame> first(seq.frames.begin(), seq.frames.begin() + 1);
    (void)runSlam(first, opts, {}, &mapper);
    ASSERT_EQ(mapper->map().keyframes().size(), 1u);
    const slam::Map one = mapper->map();
    slam::Slam loc(opts);
    loc.localizeIn(one);
    ASSERT_NE(loc.placeIndex(), nullptr);
    EXPECT_TRUE(
        loc.placeIndex()->query(one.keyframes().begin()->second.features.descriptors, 5).empty());
    for (std::size_t i = 1; i <= 5; ++i) {
        core::Frame f = seq.frames[i];
        f.index = i - 1;
        const auto r = loc.process(f, {});
        EXPECT_TRUE(r.track.pose_valid) << i << ": " << r.track.reason;
    }
}

// The free-space test while localizing: the shipped frames in their own map, the first three
// as they are, then with every depth 1.5 times what it was, so that at the poses found on
// their pictures the depth sees through the map's landmarks: the first such frame, tracked
// on from the last, is lost saying why, and no later one relocalizes. Without the test
// (localize_max_see_through = 1) that frame keeps its pose.
TEST(SlamIntegration, APoseWhoseDepthSeesThroughTheMapIsRefusedWhileLocalizing) {
    const auto& seq = realSequence();
    const auto opts = options();
    ASSERT_LT(opts.tracker.localize_max_see_through, 1.0);
    slam::Slam* mapper = nullptr;
    (void)runSlam(seq.frames, opts, {}, &mapper);
    const slam::Map map = mapper->map();
    for (const double test : {opts.tracker.localize_max_see_through, 1.0}) {
        SCOPED_TRACE(test);
        auto o = opts;
        o.tracker.localize_max_see_through = test;
        slam::Slam loc(o);
        loc.localizeIn(map);
        std::vector<bool> tracked;
        std::vector<std::string> why;
        for (std::size_t i = 0; i < 10; ++i) {
            core::Frame f = seq.frames[i];
            f.index = i;
            if (i >= 3) f.depth = f.depth * 1.5;
            const auto r = loc.process(f, {});
            tracked.push_back(r.track.pose_valid);
            why.push_back(r.track.reason);
        }
        for (std::size_t i = 0; i < 3; ++i) EXPECT_TRUE(tracked[i]) << i << ": " << why[i];
        if (test < 1) {
            EXPECT_NE(why[3].find("the depth sees through "), std::string::npos) << why[3];
            EXPECT_NE(why[3].find(" map landmarks at the pose found"), std::string::npos);
            for (std::size_t i = 3; i < 10; ++i) EXPECT_FALSE(tracked[i]) << i;
        } else {  // (the depth that is wrong everywhere loses the track a few frames on)
            EXPECT_TRUE(tracked[3]) << why[3];
        }
    }
}
