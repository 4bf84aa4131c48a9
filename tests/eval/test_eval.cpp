#include <devslam/core/Pose.h>
#include <devslam/eval/MaskScore.h>
#include <devslam/eval/Metrics.h>
#include <devslam/eval/Plot.h>
#include <devslam/eval/Report.h>
#include <devslam/io/TrajectoryIO.h>

#include <mrpt/core/bits_math.h>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <gtest/gtest.h>

#include "Command.h"
#include "Scratch.h"

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>


using namespace devslam;
using mrpt::poses::CPose3D;

namespace {

const std::string kGt =
    std::string(DEVSLAM_SOURCE_DIR) + "/data/tum/fr1_xyz_first37/groundtruth.txt";

// A smooth synthetic trajectory at `hz` (helix with changing orientation).
core::Trajectory helix(std::size_t n, double hz) {
    core::Trajectory t;
    for (std::size_t i = 0; i < n; ++i) {
        const double s = static_cast<double>(i) / hz;
        t.push_back({100.0 + s,
                     CPose3D(std::cos(s), std::sin(s), 0.1 * s, 0.3 * s, 0.1 * std::sin(s), 0.05)});
    }
    return t;
}

core::Trajectory transformed(const core::Trajectory& in, const CPose3D& T) {
    core::Trajectory out = in;
    for (auto& p : out) p.pose = T + p.pose;
    return out;
}

// Adds a world-frame translation offset to pose i (rotation unchanged).
CPose3D shifted(const CPose3D& p, const Eigen::Vector3d& d) {
    CPose3D q = p;
    q.x_incr(d.x());
    q.y_incr(d.y());
    q.z_incr(d.z());
    return q;
}

}  // namespace

TEST(Horn, RecoversAKnownRigidTransform) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-2, 2);
    std::vector<Eigen::Vector3d> data, model;
    const CPose3D T(0.4, -1.2, 2.0, 0.7, -0.3, 1.1);
    const Eigen::Isometry3d Ti = core::toIsometry(T);
    for (int i = 0; i < 20; ++i) {
        data.emplace_back(u(rng), u(rng), u(rng));
        model.push_back(Ti * data.back());
    }
    EXPECT_TRUE(eval::hornAlign(model, data).matrix().isApprox(Ti.matrix(), 1e-10));
    EXPECT_THROW((void)eval::hornAlign({model[0], model[1]}, {data[0], data[1]}),
                 std::invalid_argument);
}

TEST(Ate, RigidlyMovedTrajectoryHasZeroError) {
    const auto gt = helix(300, 30);
    const CPose3D T(3, -2, 1, 1.0, 0.2, -0.4);
    const auto r = eval::computeAte(gt, transformed(gt, T));
    EXPECT_EQ(r.trans.count, 300u);
    EXPECT_LT(r.trans.rmse, 1e-9);
    EXPECT_LT(r.trans.max, 1e-9);
    // the alignment is the inverse of the motion applied
    EXPECT_TRUE(r.T_gt_est.matrix().isApprox(core::toIsometry(-T).matrix(), 1e-9));
}

TEST(Ate, GaussianNoiseGivesExpectedRmse) {
    const auto gt = helix(3000, 30);
    auto est = gt;
    std::mt19937 rng(42);
    constexpr double kSigma = 0.01;  // [m] per axis
    std::normal_distribution<double> n(0, kSigma);
    for (auto& p : est) p.pose = shifted(p.pose, {n(rng), n(rng), n(rng)});
    const auto r = eval::computeAte(gt, est);
    // E|e|^2 = 3 sigma^2 -> RMSE = sqrt(3) sigma; the mean of a chi(3) is 2 sqrt(2/pi) sigma.
    EXPECT_NEAR(r.trans.rmse, std::sqrt(3.0) * kSigma, 0.03 * std::sqrt(3.0) * kSigma);
    EXPECT_NEAR(r.trans.mean, 2 * std::sqrt(2 / M_PI) * kSigma, 0.03 * 1.6 * kSigma);
}

TEST(Ate, AssociationWindowIsHonoured) {
    const auto gt = helix(100, 10);  // 0.1 s apart
    auto est = gt;
    for (std::size_t i = 0; i < est.size(); ++i) est[i].t += (i % 2 ? 0.015 : 0.025);
    // Only the odd poses are within 0.02 s of their ground truth.
    EXPECT_EQ(eval::computeAte(gt, est).trans.count, 50u);
    eval::AteOptions wide;
    wide.max_dt = 0.03;
    EXPECT_EQ(eval::computeAte(gt, est, wide).trans.count, 100u);
    eval::AteOptions off;
    off.offset = -0.025;  // undoes the even poses' shift exactly; the odd ones are 0.01 s off
    EXPECT_EQ(eval::computeAte(gt, est, off).trans.count, 100u);
    off.max_dt = 0.005;  // ... now only the even ones (none without the offset)
    EXPECT_EQ(eval::computeAte(gt, est, off).trans.count, 50u);
    auto far = gt;
    for (auto& p : far) p.t += 1000;
    const auto message = [&](const core::Trajectory& e) {
        try {
            (void)eval::computeAte(gt, e);
        } catch (const std::invalid_argument& x) {
            return std::string(x.what());
        }
        return std::string();
    };
    EXPECT_NE(message(far).find("only 0 of 100 estimated poses associate with the ground truth "
                                "within 0.02 s"),
              std::string::npos)
        << message(far);
    // Two poses that do associate: the alignment's need, not the files, is the reason.
    EXPECT_EQ(message(core::Trajectory(gt.begin(), gt.begin() + 2)),
              "ATE: 2 associated poses, the alignment needs at least 3 (2 estimated, 100 in "
              "the ground truth)");
}

TEST(RelativePose, ErrorOfAMeasuredConstraintAgainstTheTruth) {
    const auto gt = helix(100, 10.0);
    const Eigen::Isometry3d Qa = core::toIsometry(gt[10].pose), Qb = core::toIsometry(gt[70].pose);
    const Eigen::Isometry3d T_true = Qa.inverse() * Qb;
    const auto exact = eval::relativePoseError(gt, gt[10].t, gt[70].t, T_true);
    ASSERT_TRUE(exact);
    EXPECT_NEAR(exact->trans, 0.0, 1e-9);
    EXPECT_NEAR(exact->rot, 0.0, 1e-6);
    // 5 cm along the measured frame's x, 2 deg about its z
    Eigen::Isometry3d d = Eigen::Isometry3d::Identity();
    d.translation() = Eigen::Vector3d(0.05, 0, 0);
    d.linear() = Eigen::AngleAxisd(2.0 * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    const auto off = eval::relativePoseError(gt, gt[10].t + 0.01, gt[70].t, T_true * d);
    ASSERT_TRUE(off) << "10 ms from a gt stamp is within the 20 ms window";
    EXPECT_NEAR(off->trans, 0.05, 1e-9);
    EXPECT_NEAR(off->rot, 2.0, 1e-6);
    EXPECT_FALSE(eval::relativePoseError(gt, gt[10].t + 0.05, gt[70].t, T_true))
        << "no gt pose within 20 ms of t_a";
    EXPECT_FALSE(eval::relativePoseError({}, gt[10].t, gt[70].t, T_true));
}

TEST(Rpe, ConstantDriftGivesExpectedError) {
    // World-frame drift d per frame: E_i has translation (j-i) R_i^T d, norm (j-i)|d|,
    // and no rotation, whatever the ground truth's orientation.
    const auto gt = helix(300, 30);
    auto est = gt;
    const Eigen::Vector3d d(0.001, -0.0005, 0.0002);
    for (std::size_t i = 0; i < est.size(); ++i) est[i].pose = shifted(gt[i].pose, d * double(i));
    eval::RpeOptions frames;
    frames.delta = 10;
    frames.delta_in_frames = true;
    const auto r = eval::computeRpe(gt, est, frames);
    EXPECT_NEAR(r.trans.rmse, 10 * d.norm(), 1e-9);
    EXPECT_NEAR(r.trans.std, 0, 1e-9);
    EXPECT_LT(r.rot.max, 1e-6);
    // delta 1 s at 30 Hz = 30 frames; pairs ending at the last pose are dropped (as in
    // evaluate_rpe.py) -> 300 - 30 - 1 pairs.
    const auto s = eval::computeRpe(gt, est, {});
    EXPECT_NEAR(s.trans.median, 30 * d.norm(), 1e-9);
    EXPECT_EQ(s.n_pairs, 269u);
}

TEST(Rpe, ReproducesEvaluateRpeQuirks) {
    const auto gt = helix(5, 1);
    eval::RpeOptions o;
    o.delta = 1;
    o.delta_in_frames = true;
    // pairs (0,1) (1,2) (2,3); (3,4) ends at the last index and (4,4) too: dropped.
    EXPECT_EQ(eval::computeRpe(gt, gt, o).n_pairs, 3u);
    // A constant rotation error about z on every pose of a pure translation gives 0 RPE.
    core::Trajectory line, rotated;
    for (int i = 0; i < 50; ++i) {
        line.push_back({double(i), CPose3D(0.1 * i, 0, 0, 0, 0, 0)});
        rotated.push_back(
            {double(i), CPose3D(0.1 * i, 0, 0, 0, 0, 0) + CPose3D(0, 0, 0, 0.2, 0, 0)});
    }
    o.delta = 5;
    const auto r = eval::computeRpe(line, rotated, o);
    EXPECT_NEAR(r.rot.max, 0, 1e-9);
    EXPECT_NEAR(r.trans.max, 0.5 * std::hypot(1 - std::cos(0.2), std::sin(0.2)), 1e-9);
    // Half a frame would pair every pose with itself (error 0): whole frames only, as there.
    o.delta = 0.5;
    EXPECT_THROW((void)eval::computeRpe(line, rotated, o), std::invalid_argument);
}

// A delta longer than the estimate leaves no pair, however long: at 1e16 s the search in
// double precision (stamps of 1.3e9 s) paired every pose with the first one, and gave figures.
// One shorter than half a frame interval leaves none either.
TEST(Rpe, ADeltaLongerThanTheRunOrUnderHalfAFrameLeavesNoPair) {
    core::Trajectory gt, est;
    for (int i = 0; i < 30; ++i) {
        const double t = 1305031102.175304 + 0.1 * i;
        gt.push_back({t, CPose3D(0.01 * i, 0, 0, 0, 0, 0)});
        est.push_back({t, CPose3D(0.011 * i, 0, 0, 0, 0, 0)});
    }
    eval::RpeOptions o;
    o.delta = 2.5;  // the span is 2.9 s
    EXPECT_GE(eval::computeRpe(gt, est, o).n_pairs, 2u);
    for (const double delta : {3.0, 1e6, 1e16, 1e300}) {
        o.delta = delta;
        try {
            (void)eval::computeRpe(gt, est, o);
            ADD_FAILURE() << "delta " << delta << " s gave pairs";
        } catch (const std::invalid_argument& e) {
            EXPECT_NE(std::string(e.what()).find("RPE: no pose pair"), std::string::npos)
                << e.what();
        }
    }
    o.delta_in_frames = true;
    o.delta = 1e19;  // frames
    EXPECT_THROW((void)eval::computeRpe(gt, est, o), std::invalid_argument);
    // Under half the frame interval (0.1 s) each pose is closest to itself: no pair, not a
    // perfect RPE over 29 pairs of a pose with itself (evaluate_rpe.py's figure).
    o.delta_in_frames = false;
    for (const double delta : {0.01, 1e-9}) {
        o.delta = delta;
        try {
            const auto r = eval::computeRpe(gt, est, o);
            ADD_FAILURE() << "delta " << delta << " s: " << r.n_pairs << " pairs, RMSE "
                          << r.trans.rmse;
        } catch (const std::invalid_argument& e) {
            EXPECT_NE(std::string(e.what()).find("RPE: no pose pair"), std::string::npos)
                << e.what();
        }
    }
    o.delta = 0.06;  // over half: the next pose
    EXPECT_EQ(eval::computeRpe(gt, est, o).n_pairs, 28u);
}

// evaluate_rpe.py refuses trajectories that overlap at one estimate pose ("Number of overlap
// in the timestamps is too small"): ground truth at 0 and 100 s, the estimate at 0..10 s,
// every estimate stamp meets the ground truth at 0 s, whose nearest estimate stamp is 0 s.
// Our RPE gave 9 pairs, all against the ground-truth pose at 0 s.
TEST(Rpe, TrajectoriesThatHardlyOverlapAreRefusedAsByTheScript) {
    core::Trajectory gt{{0.0, CPose3D()}, {100.0, CPose3D(1, 0, 0, 0, 0, 0)}}, est;
    for (int i = 0; i <= 10; ++i) est.push_back({double(i), CPose3D(0.1 * i, 0, 0, 0, 0, 0)});
    eval::RpeOptions o;
    o.delta = 1;
    try {
        (void)eval::computeRpe(gt, est, o);
        ADD_FAILURE() << "accepted";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("Number of overlap in the timestamps is too small"),
                  std::string::npos)
            << e.what();
    }
    // Ground truth over the whole estimate: two poses come back, and it is evaluated.
    core::Trajectory gt2;
    for (int i = 0; i <= 10; ++i) gt2.push_back({double(i), CPose3D(0.1 * i, 0, 0, 0, 0, 0)});
    EXPECT_EQ(eval::computeRpe(gt2, est, o).n_pairs, 9u);
}

// evaluate_rpe.py's error is A B^-1 (A, B: the estimate's and the ground truth's relative
// motions), not the TUM paper's B^-1 A: with a rotation error its translation differs.
// Ground truth: 1 m steps along x. Estimate: the same positions, turned 10 deg more about z
// at each pose. Pair (0,1): A = T(1 0 0) Rz(10), B = T(1 0 0): |e_x - Rz(10) e_x| =
// 2 sin(5 deg); pair (1,2): A = Rz(-10) T(1 0 0) Rz(20): |Rz(-10) e_x - Rz(10) e_x| =
// 2 sin(10 deg); (2,3) ends at the last pose (dropped). B^-1 A would give 0 and 2 sin(5 deg).
TEST(Rpe, TranslationIsTheScriptsNotThePapers) {
    core::Trajectory gt, est;
    for (int i = 0; i < 4; ++i) {
        gt.push_back({double(i), CPose3D(i, 0, 0, 0, 0, 0)});
        est.push_back({double(i), CPose3D(i, 0, 0, mrpt::DEG2RAD(10.0 * i), 0, 0)});
    }
    eval::RpeOptions o;
    o.delta = 1;
    o.delta_in_frames = true;
    const auto r = eval::computeRpe(gt, est, o);
    ASSERT_EQ(r.n_pairs, 2u);
    EXPECT_NEAR(r.trans.min, 2 * std::sin(mrpt::DEG2RAD(5.0)), 1e-12);
    EXPECT_NEAR(r.trans.max, 2 * std::sin(mrpt::DEG2RAD(10.0)), 1e-12);
    EXPECT_NEAR(r.rot.min, 10.0, 1e-9);
    EXPECT_NEAR(r.rot.max, 10.0, 1e-9);
    // The script's definition, transcribed with 4x4 matrices: ominus(a, b) = a^-1 b.
    const auto M = [](const CPose3D& p) { return core::toIsometry(p).matrix(); };
    const auto ominus = [](const Eigen::Matrix4d& a, const Eigen::Matrix4d& b) {
        return Eigen::Matrix4d(a.inverse() * b);
    };
    for (int i = 0; i < 2; ++i) {
        const Eigen::Matrix4d e = ominus(ominus(M(est[i + 1].pose), M(est[i].pose)),
                                         ominus(M(gt[i + 1].pose), M(gt[i].pose)));
        const double t = e.block<3, 1>(0, 3).norm();
        EXPECT_NEAR(t, i == 0 ? r.trans.min : r.trans.max, 1e-12);
    }
    // One pair is too few, as there: the script raises.
    core::Trajectory gt3(gt.begin(), gt.begin() + 3), est3(est.begin(), est.begin() + 3);
    try {
        (void)eval::computeRpe(gt3, est3, o);
        ADD_FAILURE() << "one pair gave figures";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("RPE: one pose pair 1 frames apart"),
                  std::string::npos)
            << e.what();
    }
}

// The real fr1_xyz ground truth (100 Hz motion capture), subsampled and perturbed by known
// amounts: the figures must be those the TUM definitions give in closed form.
TEST(RealGroundTruth, KnownPerturbationsGiveKnownFigures) {
    const auto gt = io::readTumTrajectory(kGt);
    core::Trajectory est;
    for (std::size_t i = 0; i < gt.size(); i += 3) est.push_back(gt[i]);  // ~33 Hz
    for (auto& p : est) p.t += 0.002;  // still nearest to its own gt pose (gt is 100 Hz)
    const CPose3D T(-0.5, 0.3, 1.2, 2.0, -0.1, 0.3);
    {  // rigid motion only: ATE = RPE = 0
        const auto moved = transformed(est, T);
        const auto a = eval::computeAte(gt, moved);
        EXPECT_EQ(a.trans.count, est.size());
        EXPECT_LT(a.trans.rmse, 1e-7);
        EXPECT_LT(eval::computeRpe(gt, moved, {}).trans.rmse, 1e-7);
    }
    {  // +-1 cm along x, alternating: the alignment cannot absorb it -> RMSE 1 cm, std ~0
        auto e = est;
        for (std::size_t i = 0; i < e.size(); ++i)
            e[i].pose = shifted(e[i].pose, {i % 2 ? 0.01 : -0.01, 0, 0});
        const auto a = eval::computeAte(gt, transformed(e, T));
        EXPECT_NEAR(a.trans.rmse, 0.01, 1e-4);
        EXPECT_NEAR(a.trans.median, 0.01, 2e-4);
        EXPECT_LT(a.trans.std, 2e-4);
    }
    {  // 1 mm of world drift per estimate: RPE over 10 frames = 1 cm for every pair
        auto e = est;
        for (std::size_t i = 0; i < e.size(); ++i)
            e[i].pose = shifted(e[i].pose, {0.001 * double(i), 0, 0});
        eval::RpeOptions o;
        o.delta = 10;
        o.delta_in_frames = true;
        const auto r = eval::computeRpe(gt, transformed(e, T), o);
        EXPECT_NEAR(r.trans.min, 0.01, 1e-7);
        EXPECT_NEAR(r.trans.max, 0.01, 1e-7);
        EXPECT_LT(r.rot.max, 1e-5);
        EXPECT_EQ(r.n_pairs, est.size() - 11);
    }
}

TEST(Report, TableJsonPlotAndApp) {
    const auto gt = helix(100, 30);
    auto est = gt;
    for (std::size_t i = 0; i < est.size(); ++i)
        est[i].pose = shifted(est[i].pose, {0.002 * (i % 3), 0, 0});
    const auto a = eval::computeAte(gt, est);
    const auto r = eval::computeRpe(gt, est, {});
    const std::string table = eval::formatTable(&a, &r);
    EXPECT_NE(table.find("ATE translation"), std::string::npos);
    EXPECT_NE(table.find("RPE rotation"), std::string::npos);
    const std::string json = eval::toJson(&a, &r);
    EXPECT_NE(json.find("\"rmse\": " + std::to_string(a.trans.rmse).substr(0, 6)),
              std::string::npos)
        << json;

    const auto dir = devslam::test::scratchPath("devslam_eval_report");
    std::filesystem::create_directories(dir);
    io::writeTumTrajectory((dir / "gt.txt").string(), gt);
    io::writeTumTrajectory((dir / "est.txt").string(), est);
    const std::string cmd = std::string(DEVSLAM_BIN_DIR) + "/devslam-eval " +
                            (dir / "gt.txt").string() + " " + (dir / "est.txt").string() +
                            " --json " + (dir / "e.json").string() + " --plot " +
                            (dir / "e.png").string() + " > " + (dir / "out.txt").string();
    ASSERT_EQ(std::system(cmd.c_str()), 0);
    EXPECT_GT(std::filesystem::file_size(dir / "e.png"), 10000u);
    std::ifstream in(dir / "e.json");
    const std::string app_json((std::istreambuf_iterator<char>(in)),
                               std::istreambuf_iterator<char>());
    EXPECT_NE(app_json.find("\"translation_m\""), std::string::npos);
    // bad input: a clear error and a non-zero exit status
    std::ofstream(dir / "bad.txt") << "1 2 3\n";
    const std::string bad = std::string(DEVSLAM_BIN_DIR) + "/devslam-eval " +
                            (dir / "gt.txt").string() + " " + (dir / "bad.txt").string() + " 2> " +
                            (dir / "err.txt").string();
    EXPECT_NE(std::system(bad.c_str()), 0);
    std::ifstream err(dir / "err.txt");
    const std::string msg((std::istreambuf_iterator<char>(err)), std::istreambuf_iterator<char>());
    EXPECT_NE(msg.find("bad.txt line 1: expected"), std::string::npos) << msg;
    // Options that are no number, or no usable one, are named ("inf" would associate every
    // pose with every other).
    for (const auto& [opt, says] : std::vector<std::pair<std::string, std::string>>{
             {"--max-dt inf", "--max-dt: expected a number, got 'inf'"},
             {"--scale nan", "--scale: expected a number, got 'nan'"},
             {"--max-dt 0", "--max-dt: must be > 0, got '0'"},
             {"--delta -1", "--delta: must be > 0, got '-1'"},
             {"--delta 0.5 --delta-unit f",
              "--delta: in frames (--delta-unit f) a whole number, got 0.5"},
             {"--plot x.jpgx", "--plot 'x.jpgx': the plot's name must end in .png"}}) {
        const std::string c = std::string(DEVSLAM_BIN_DIR) + "/devslam-eval " +
                              (dir / "gt.txt").string() + " " + (dir / "est.txt").string() + " " +
                              opt + " > /dev/null 2> " + (dir / "err.txt").string();
        EXPECT_NE(std::system(c.c_str()), 0) << opt;
        std::ifstream e(dir / "err.txt");
        const std::string m((std::istreambuf_iterator<char>(e)), std::istreambuf_iterator<char>());
        EXPECT_NE(m.find(says), std::string::npos) << opt << ": " << m;
    }
    // An estimate too short for the RPE keeps its ATE: printed and written, then the error.
    const core::Trajectory three(est.begin(), est.begin() + 3);  // 0.6 s, RPE over 1 s
    io::writeTumTrajectory((dir / "short.txt").string(), three);
    std::filesystem::remove(dir / "e.json");
    const std::string sh = std::string(DEVSLAM_BIN_DIR) + "/devslam-eval " +
                           (dir / "gt.txt").string() + " " + (dir / "short.txt").string() +
                           " --json " + (dir / "e.json").string() + " > " +
                           (dir / "out.txt").string() + " 2> " + (dir / "err.txt").string();
    EXPECT_EQ(WEXITSTATUS(std::system(sh.c_str())), 1);
    const auto text = [&](const char* f) {
        std::ifstream t(dir / f);
        return std::string((std::istreambuf_iterator<char>(t)), std::istreambuf_iterator<char>());
    };
    EXPECT_NE(text("out.txt").find("ATE translation"), std::string::npos) << text("out.txt");
    EXPECT_NE(text("e.json").find("\"ate\""), std::string::npos) << text("e.json");
    EXPECT_NE(text("err.txt").find("RPE: no pose pair"), std::string::npos) << text("err.txt");
    EXPECT_NE(text("err.txt").find("the ATE above is written"), std::string::npos);
    std::filesystem::remove_all(dir);
}

// Fuzz: --scale 1e308, or positions near 1e200, overflowed the alignment and wrote
// "rmse": -nan (no JSON) under exit status 0; --json EST replaced the estimate with the
// figures; "--json --plot p.png" took "--plot" for the JSON's name.
TEST(Report, RefusesOverflowNonFiniteJsonAndOutputsThatAreInputs) {
    devslam::test::TempDir d("devslam_eval_");
    const auto gt = helix(60, 30);
    EXPECT_THROW((void)eval::computeAte(gt, gt, {0.02, 0.0, 1e308}), std::invalid_argument);
    EXPECT_NO_THROW((void)eval::computeAte(gt, gt, {0.02, 0.0, 1e6}));
    eval::AteResult nan = eval::computeAte(gt, gt);
    nan.trans.rmse = std::nan("");
    nan.trans.max = -std::numeric_limits<double>::infinity();
    const std::string json = eval::toJson(&nan, nullptr, nullptr);
    EXPECT_NE(json.find("\"rmse\": null"), std::string::npos) << json;
    EXPECT_NE(json.find("\"max\": null"), std::string::npos) << json;
    EXPECT_EQ(json.find("nan"), std::string::npos) << json;
    EXPECT_EQ(json.find("inf"), std::string::npos) << json;

    const std::string g = d.str("gt.txt"), e = d.str("est.txt"), far = d.str("far.txt");
    io::writeTumTrajectory(g, gt);
    io::writeTumTrajectory(e, gt);
    std::ofstream(far) << "1 0 0 0 0 0 0 1\n2 1e200 0 0 0 0 0 1\n";
    try {
        (void)io::readTumTrajectory(far);
        ADD_FAILURE() << "no error for a position of 1e200 m";
    } catch (const std::runtime_error& x) {
        EXPECT_EQ(std::string(x.what()).find(far + " line 2: tx 1e200 is beyond +-1e6 m"), 0u)
            << x.what();
    }
    const auto text = [](const std::string& f) {
        std::ifstream in(f);
        return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    };
    const std::string est_text = text(e);
    for (const auto& [args, says] : std::vector<std::pair<std::string, std::string>>{
             {g + " " + g + " --scale 1e308 --json " + d.str("j.json"),
              "--scale: must be in [1e-6, 1e6], got '1e308'"},
             {g + " " + far + " --json " + d.str("j.json"), "far.txt line 2: tx 1e200"},
             {g + " " + e + " --json " + e, "--json '" + e + "' is the input '" + e + "'"},
             {g + " " + e + " --json " + g, "--json '" + g + "' is the input '" + g + "'"},
             {g + " " + e + " --json --plot " + d.str("p.png"), "--json needs a value"},
             // (an empty name, a script's unset variable, wrote nothing and said nothing)
             {g + " " + e + " --plot '' --json " + d.str("j.json"),
              "--plot: the file name is empty"},
             {g + " " + e + " --json " + d.str("p.png") + " --plot " + d.str("x/../p.png"),
              "--json and --plot are the same file '" + d.str("x/../p.png") +
                  "': the plot would replace the figures; name two"}}) {
        const auto r = devslam::test::runApp("devslam-eval", args);
        EXPECT_EQ(r.rc, 1) << args << "\n" << r.out;
        EXPECT_NE(r.out.find(says), std::string::npos) << args << "\n" << r.out;
        EXPECT_FALSE(std::filesystem::exists(d.str("j.json"))) << args;
        EXPECT_FALSE(std::filesystem::exists(d.str("p.png"))) << args;
    }
    EXPECT_EQ(text(e), est_text);
    // A full disk: the JSON fits the stream's buffer, which goes out (and fails) only at the
    // close; the app said nothing and returned 0.
    EXPECT_TRUE(std::filesystem::exists("/dev/full"))
        << "Linux has /dev/full: the write error is not tested";
    if (std::filesystem::exists("/dev/full")) {
        const auto r = devslam::test::runApp("devslam-eval", g + " " + e + " --json /dev/full");
        EXPECT_EQ(r.rc, 1) << r.out;
        EXPECT_NE(r.out.find("cannot write '/dev/full'"), std::string::npos) << r.out;
        // The figures on a standard output that cannot take them: an error, not 0.
        const auto full = devslam::test::runAppOntoFullDisk("devslam-eval", g + " " + e);
        EXPECT_EQ(full.rc, 1) << full.out;
        EXPECT_EQ(full.out,
                  "devslam-eval: cannot write the standard output (No space left on device)\n");
    }
    // A file-size limit under the plot, SIGXFSZ left at its default (it killed the program:
    // no error, no figures, a cut p.png.part left): the figures, the error, no cut file.
    const auto cut = devslam::test::runAppWithFileLimit(
        "devslam-eval", g + " " + e + " --plot " + d.str("p.png"), 2000, false);
    EXPECT_EQ(cut.rc, 1) << cut.out;
    EXPECT_NE(cut.out.find("ATE translation"), std::string::npos) << cut.out;
    EXPECT_NE(
        cut.out.find("devslam-eval: plot: cannot write '" + d.str("p.png") + "': File too large"),
        std::string::npos)
        << cut.out;
    EXPECT_FALSE(std::filesystem::exists(d.str("p.png")));
    EXPECT_FALSE(std::filesystem::exists(d.str("p.png.part")));
}

TEST(MaskScore, CountsWalkersStaticPeopleAndArea) {
    // Labels: person 1 (walking) 100x100 px, person 2 (static) 50x50 px, person 3 (walking)
    // 10x10 px - below min_pixels, so only its area counts.
    cv::Mat labels(200, 300, CV_8UC1, cv::Scalar(0));
    labels(cv::Rect(0, 0, 100, 100)).setTo(1);
    labels(cv::Rect(200, 0, 50, 50)).setTo(2);
    labels(cv::Rect(150, 150, 10, 10)).setTo(3);
    const std::vector<eval::PersonEntry> persons{
        {1, "a", true, 10000}, {2, "b", false, 2500}, {3, "c", true, 100}};
    cv::Mat mask(200, 300, CV_8UC1, cv::Scalar(0));
    mask(cv::Rect(0, 0, 60, 100)).setTo(255);     // 60 % of person 1
    mask(cv::Rect(100, 100, 40, 50)).setTo(255);  // background
    eval::MaskScore s;
    s.add(mask, labels, persons, 500, 1.5);
    EXPECT_EQ(s.moving_instances, 1u);
    EXPECT_EQ(s.moving_masked, 1u);
    EXPECT_EQ(s.static_instances, 1u);
    EXPECT_EQ(s.static_masked, 0u);
    EXPECT_DOUBLE_EQ(s.movingRecall(), 1.0);
    EXPECT_DOUBLE_EQ(s.movingAreaRecall(), 6000.0 / 10100.0);
    EXPECT_DOUBLE_EQ(s.precision(), 6000.0 / 8000.0);
    EXPECT_TRUE(s.errors.empty());
    // 40 % masked is not masked; the error list names the frame and the person.
    mask.setTo(0);
    mask(cv::Rect(0, 0, 40, 100)).setTo(255);
    s.add(mask, labels, persons, 500, 2.5);
    EXPECT_DOUBLE_EQ(s.movingRecall(), 0.5);
    ASSERT_EQ(s.errors.size(), 1u);
    EXPECT_EQ(s.errors[0].person_id, 1);
    EXPECT_DOUBLE_EQ(s.errors[0].timestamp, 2.5);
    EXPECT_NEAR(s.errors[0].masked_fraction, 0.4, 1e-12);
    EXPECT_EQ(s.errors[0].filter_box, "none") << "no boxes given: a detector miss";
    EXPECT_EQ(s.movingMissedWithoutBox(), 1u);
    // With the filter's boxes, the error names the state of the box covering the person
    // most (a box covering under 30 % of them is not theirs).
    const std::vector<eval::FilterBox> boxes{{{0.f, 0.f, 20.f, 100.f}, "moving"},
                                             {{0.f, 0.f, 100.f, 80.f}, "static"}};
    s.add(mask, labels, persons, 500, 3.5, boxes);
    ASSERT_EQ(s.errors.size(), 2u);
    EXPECT_EQ(s.errors[1].filter_box, "static");
    EXPECT_NEAR(s.errors[1].box_cover, 0.8, 1e-12);
    EXPECT_EQ(s.movingMissedWithoutBox(), 1u);
    s.add(mask, labels, persons, 500, 4.5, {{{0.f, 0.f, 25.f, 100.f}, "moving"}});
    ASSERT_EQ(s.errors.size(), 3u);
    EXPECT_EQ(s.errors[2].filter_box, "none") << "25 % cover is below min_box_cover";
}

TEST(MaskScore, PersonTruthOfAFolder) {
    namespace fs = std::filesystem;
    const fs::path dir = devslam::test::scratchPath("devslam_test_person_truth");
    fs::remove_all(dir);
    EXPECT_FALSE(eval::PersonTruth::open(dir.string()).has_value());  // no folder: real data
    fs::create_directories(dir);
    {
        std::ofstream p(dir / "persons.txt");
        p << "# t id name state x y w h visible\n1.000000 1 p moving 0 0 10 10 100\n";
    }
    EXPECT_FALSE(eval::PersonTruth::open(dir.string()).has_value());  // no labels/ (--no-labels)
    EXPECT_FALSE(eval::PersonTruth::hasWalkers(dir.string()));  // no truth, no walkers
    fs::create_directories(dir / "labels");
    EXPECT_TRUE(eval::PersonTruth::hasWalkers(dir.string()));
    const auto truth = eval::PersonTruth::open(dir.string());
    ASSERT_TRUE(truth.has_value());
    eval::MaskScore s;
    // the label image is missing: a clear error naming it
    try {
        truth->score(cv::Mat(), 1.0, 1, s);
        ADD_FAILURE() << "no error";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("labels/1.000000.png"), std::string::npos) << e.what();
    }
    cv::Mat labels(20, 20, CV_8UC1, cv::Scalar(0));
    labels(cv::Rect(0, 0, 10, 10)).setTo(1);
    cv::imwrite((dir / "labels" / "1.000000.png").string(), labels);
    truth->score(cv::Mat(), 1.0, 1, s);  // empty mask: nothing masked
    EXPECT_EQ(s.moving_instances, 1u);
    EXPECT_EQ(s.moving_masked, 0u);
    EXPECT_THROW(truth->score(cv::Mat(), 2.0, 1, s), std::runtime_error);  // no entry
    EXPECT_THROW((void)truth->walkerMask(2.0, 0), std::runtime_error);
    // Labels of another size than the frame: named, not an OpenCV size assertion.
    try {
        truth->score(cv::Mat(30, 20, CV_8UC1, cv::Scalar(0)), 1.0, 1, s);
        ADD_FAILURE() << "no error";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("labels/1.000000.png' are 20x20, the frame is 20x30"),
                  std::string::npos)
            << e.what();
    }
    EXPECT_THROW((void)truth->walkerMask(1.0, 0, cv::Size(20, 30)), std::runtime_error);
    EXPECT_EQ(truth->walkerMask(1.0, 0, cv::Size(20, 20)).size(), cv::Size(20, 20));
    // A labelled id the frame's rows do not list (another render's labels): named, not scored
    // against the wrong people.
    // Unusable truth, as a missing label image (MissingTruth: devslam-run keeps the frames
    // before it).
    labels(cv::Rect(12, 12, 3, 3)).setTo(4);
    cv::imwrite((dir / "labels" / "1.000000.png").string(), labels);
    try {
        truth->score(cv::Mat(), 1.0, 1, s);
        ADD_FAILURE() << "no error";
    } catch (const eval::MissingTruth& e) {
        EXPECT_NE(std::string(e.what()).find("labels/1.000000.png' hold id 4, which " +
                                             dir.string() +
                                             "/persons.txt does not list for frame 1.000000"),
                  std::string::npos)
            << e.what();
    }
    {
        // Seated people only: mode truth's mask would be empty in every frame.
        std::ofstream p(dir / "persons.txt");
        p << "1.000000 1 p static 0 0 10 10 100\n2.000000 1 p static 0 0 10 10 90\n";
    }
    EXPECT_FALSE(eval::PersonTruth::hasWalkers(dir.string()));
    {
        std::ofstream p(dir / "persons.txt");
        p << "1.0 1 p walking 0 0 10 10 100\n";  // bad state
    }
    EXPECT_THROW((void)eval::PersonTruth::open(dir.string()), std::runtime_error);
    EXPECT_THROW((void)eval::PersonTruth::hasWalkers(dir.string()), std::runtime_error);
    // A person twice in a frame (it was scored twice), an id no 8-bit label holds, a negative
    // size, a tenth value: refused, naming the line.
    const std::string good = "1.000000 1 p moving 0 0 10 10 100\n";
    for (const auto& [text, says] : std::vector<std::pair<std::string, std::string>>{
             {good + "2.000000 1 p moving 0 0 10 10 100\n" + good,
              "line 3: person 1 of frame 1.000000 again (line 1)"},
             {"1.000000 256 p moving 0 0 10 10 100\n", "line 1: person id 256"},
             {"1.000000 0 p moving 0 0 10 10 100\n", "line 1: person id 0"},
             {"1.000000 1 p moving 0 0 -10 10 100\n", "line 1: a negative box size"},
             {"1.000000 1 p moving 0 0 10 10 100 7\n", "line 1: '7' after the 9 values"}}) {
        std::ofstream(dir / "persons.txt") << text;
        try {
            (void)eval::PersonTruth::open(dir.string());
            ADD_FAILURE() << "accepted: " << text;
        } catch (const std::runtime_error& e) {
            EXPECT_NE(std::string(e.what()).find((dir / "persons.txt").string() + " " + says),
                      std::string::npos)
                << e.what();
        }
    }
    fs::remove_all(dir);
}

// devslam-run's diagnostic mode `truth`: the walkers' pixels, dilated, never a static person.
TEST(MaskScore, WalkerMaskIsTheWalkersPixelsDilated) {
    namespace fs = std::filesystem;
    const fs::path dir = devslam::test::scratchPath("devslam_test_walker_mask");
    fs::remove_all(dir);
    fs::create_directories(dir / "labels");
    std::ofstream(dir / "persons.txt") << "1.000000 1 walker moving 2 2 4 4 16\n"
                                          "1.000000 2 sitter static 12 12 4 4 16\n";
    cv::Mat labels(20, 20, CV_8UC1, cv::Scalar(0));
    labels(cv::Rect(2, 2, 4, 4)).setTo(1);
    labels(cv::Rect(12, 12, 4, 4)).setTo(2);
    cv::imwrite((dir / "labels" / "1.000000.png").string(), labels);
    const auto truth = eval::PersonTruth::open(dir.string());
    ASSERT_TRUE(truth.has_value());
    const cv::Mat exact = truth->walkerMask(1.0, 0);
    ASSERT_EQ(exact.type(), CV_8UC1);
    EXPECT_EQ(cv::countNonZero(exact), 16);
    EXPECT_EQ(cv::countNonZero(exact(cv::Rect(2, 2, 4, 4))), 16);
    const cv::Mat grown = truth->walkerMask(1.0, 2);
    EXPECT_EQ(cv::countNonZero(grown), 8 * 8);  // 4x4 grown by 2 px on every side
    EXPECT_EQ(cv::countNonZero(grown(cv::Rect(12, 12, 4, 4))), 0);  // the sitter stays
    // Scored against the same truth, it masks every walker and no static person.
    eval::MaskScore s;
    truth->score(grown, 1.0, 1, s);
    EXPECT_EQ(s.movingRecall(), 1.0);
    EXPECT_EQ(s.staticMasked(), 0.0);
    fs::remove_all(dir);
}

TEST(Plot, LongTitleStaysInsideItsArea) {
    // A title naming a long path is shortened from the front, so it does not run into the
    // plot beside it (devslam-eval's top view has the x/y/z plots to its right).
    const std::string title = "out/bench/runs/walking_halfsphere/dynamic/seed14_r0/"
                              "trajectory.txt: top view, ATE RMSE 0.0353 m";
    cv::Mat canvas(200, 600, CV_8UC3, cv::Scalar(255, 255, 255));
    eval::Plot p(cv::Rect(0, 0, 300, 200), title, "x [m]", "y [m]");
    p.fit({0.0, 1.0}, {0.0, 1.0});
    p.axes(canvas);
    cv::Mat gray;
    cv::cvtColor(canvas(cv::Rect(300, 0, 300, 200)), gray, cv::COLOR_BGR2GRAY);
    EXPECT_EQ(cv::countNonZero(gray < 255), 0) << "ink right of the plot's area";
    cv::cvtColor(canvas(cv::Rect(0, 0, 300, 30)), gray, cv::COLOR_BGR2GRAY);
    EXPECT_GT(cv::countNonZero(gray < 128), 50) << "the title is drawn";
}

TEST(Plot, LegendGoesToTheCornerWithoutData) {
    // A trajectory in the top-left corner (where the legend used to be drawn) and along the
    // right edge: the legend goes to the bottom left, the only free corner.
    const cv::Scalar data(0, 0, 255), key(0, 200, 0);
    std::vector<double> xs, ys;
    for (int i = 0; i <= 40; ++i) {
        xs.push_back(0.02 * i), ys.push_back(0.98);  // top left to top middle
        xs.push_back(1.0), ys.push_back(0.025 * i);  // right edge, bottom to top
    }
    cv::Mat canvas(400, 400, CV_8UC3, cv::Scalar(255, 255, 255));
    // A trajectory 5e12 m out with no extent: its tick step is below the coordinates' float
    // spacing; the axes are drawn and the call returns (it used to loop for ever).
    eval::Plot far(cv::Rect(0, 0, 400, 400), "t", "x [m]", "y [m]");
    far.fit({5e12}, {5e12});
    far.axes(canvas);
    canvas.setTo(cv::Scalar(255, 255, 255));
    eval::Plot p(cv::Rect(0, 0, 400, 400), "t", "x [m]", "y [m]");
    p.fit({0.0, 1.0}, {0.0, 1.0});
    p.axes(canvas);
    p.points(canvas, xs, ys, {data}, 3);
    p.legend(canvas, {{"a long legend label", key}}, xs, ys);
    const auto inkOf = [&](const cv::Scalar& colour, const cv::Rect& r) {
        cv::Mat hit;
        cv::inRange(canvas(r), colour, colour, hit);
        return cv::countNonZero(hit);
    };
    const cv::Rect top_left(0, 0, 200, 200), bottom_left(0, 200, 200, 200);
    EXPECT_EQ(inkOf(key, top_left), 0) << "legend drawn over the data";
    EXPECT_GT(inkOf(key, bottom_left), 10) << "legend not in the free corner";
    EXPECT_GT(inkOf(data, top_left), 100) << "the data stays visible";
    // Without points to avoid it keeps the top-left corner.
    cv::Mat plain(400, 400, CV_8UC3, cv::Scalar(255, 255, 255));
    p.legend(plain, {{"a long legend label", key}});
    cv::Mat hit;
    cv::inRange(plain(top_left), key, key, hit);
    EXPECT_GT(cv::countNonZero(hit), 10);
}
