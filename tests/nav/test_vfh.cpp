// VFH+ on synthetic obstacle fields with known answers, and the MRPT plugin registration.
#include <devslam/nav/CHolonomicVFHPlus.h>
#include <devslam/nav/VfhPlus.h>

#include "ConfigRoundTrip.h"

#include <gtest/gtest.h>
#include <mrpt/config/CConfigFileMemory.h>
#include <mrpt/rtti/CObject.h>

#include <cmath>

using namespace devslam::nav;

namespace {
constexpr int kN = 121;  // sectors, as MRPT's PTGs with num_paths = 121
constexpr double kSector = 2 * M_PI / kN;

VfhInput field(double free = 1.0) {
    VfhInput in;
    in.obstacles.assign(kN, free);
    in.ref_distance = 2.5;
    in.target_x = 0.8;
    in.target_y = 0.0;
    return in;
}
/// Sets sectors whose direction lies in [a0, a1] (rad) to distance d.
void setArc(VfhInput& in, double a0, double a1, double d) {
    for (int k = 0; k < kN; k++) {
        const double a = vfhSectorAngle(k, kN);
        if (a >= a0 && a <= a1) in.obstacles[k] = d;
    }
}
void setTarget(VfhInput& in, double angle, double dist) {
    in.target_x = dist * std::cos(angle);
    in.target_y = dist * std::sin(angle);
}
}  // namespace

TEST(VfhPlus, FreeSpaceGoesToTarget) {
    for (double a : {0.0, 0.5, -1.2, 2.0}) {
        auto in = field();
        setTarget(in, a, 0.8);
        const auto out = vfhPlusStep(in, {}, {});
        ASSERT_GE(out.sector, 0);
        EXPECT_NEAR(out.direction, a, kSector) << "target at " << a;
        EXPECT_NEAR(out.speed, 1.0, 1e-9);  // nothing nearby: full speed
    }
}

TEST(VfhPlus, ATargetNearPlusOrMinusPiIsReachable) {
    // The histogram's ends are no obstacle: in free space a target 3 sectors from -pi (or +pi)
    // is the direction taken. Keeping wide_valley_sectors / 2 off the ends, VFH+ chose a
    // sector 8 off, and MRPT then found no way to a goal the robot had just passed.
    for (const double a : {-M_PI + 3.5 * kSector, M_PI - 3.5 * kSector}) {
        auto in = field();
        setTarget(in, a, 0.17);
        const auto out = vfhPlusStep(in, {}, {});
        ASSERT_GE(out.sector, 0);
        EXPECT_EQ(out.sector, out.target_sector) << "target at " << a;
        EXPECT_NEAR(out.direction, a, kSector) << "target at " << a;
    }
}

TEST(VfhPlus, WallWithGapPicksTheGap) {
    // a wall at 0.25 (norm) everywhere ahead except a gap centred at +0.6 rad
    auto in = field();
    setArc(in, -1.5, 0.3, 0.25);
    setArc(in, 0.9, 1.5, 0.25);
    setTarget(in, 0.0, 0.9);
    const auto out = vfhPlusStep(in, {}, {});
    ASSERT_GE(out.sector, 0);
    EXPECT_GT(out.direction, 0.3);
    EXPECT_LT(out.direction, 0.9);
    EXPECT_NEAR(out.direction, 0.6, 2 * kSector);
}

TEST(VfhPlus, NarrowCorridorStaysCentred) {
    // corridor walls on both sides: only a narrow cone around the heading is free
    auto in = field();
    setArc(in, -M_PI, -0.55, 0.2);
    setArc(in, 0.55, M_PI, 0.2);
    setTarget(in, 0.0, 0.9);
    const auto out = vfhPlusStep(in, {}, {});
    ASSERT_GE(out.sector, 0);
    EXPECT_NEAR(out.direction, 0.0, kSector);
    // a narrow valley is followed along its centre even when the target is off to one side
    setTarget(in, 0.25, 0.9);
    const auto out2 = vfhPlusStep(in, {}, {});
    EXPECT_NEAR(out2.direction, 0.0, kSector);
}

TEST(VfhPlus, ObstacleDeadAheadTurns) {
    auto in = field();
    setArc(in, -0.3, 0.3, 0.2);  // box right ahead
    setTarget(in, 0.0, 0.9);
    const auto out = vfhPlusStep(in, {}, {});
    ASSERT_GE(out.sector, 0);
    EXPECT_GT(std::abs(out.direction), 0.3);  // leaves the blocked cone
    EXPECT_LT(std::abs(out.direction), 1.2);  // but not more than needed
    EXPECT_EQ(out.binary[vfhSectorOf(0.0, kN)], 1);
    EXPECT_GT(out.target_density, 0.5);
}

TEST(VfhPlus, HysteresisPreventsOscillationBetweenEqualValleys) {
    // target straight ahead is blocked; two mirror-image valleys left and right
    auto in = field();
    setArc(in, -0.35, 0.35, 0.2);
    setArc(in, -M_PI, -1.2, 0.2);
    setArc(in, 1.2, M_PI, 0.2);
    setTarget(in, 0.0, 0.9);
    VfhState st;
    const auto first = vfhPlusStep(in, st, {});
    ASSERT_GE(first.sector, 0);
    const double side = first.direction > 0 ? 1.0 : -1.0;
    st = first.next;
    // now the target drifts slightly toward the OTHER side, step after step: VFH+ keeps
    // its choice (mu3 term + binary hysteresis) instead of flipping back and forth
    for (int i = 0; i < 20; i++) {
        setTarget(in, -side * 0.04 * ((i % 2) + 1), 0.9);
        const auto out = vfhPlusStep(in, st, {});
        ASSERT_GE(out.sector, 0);
        EXPECT_GT(out.direction * side, 0.0) << "flipped at step " << i;
        st = out.next;
    }
    // without the previous-direction memory the same input flips to the other valley
    setTarget(in, -side * 0.08, 0.9);
    VfhPlusOptions no_memory;
    no_memory.mu3 = 0.0;
    const auto fresh = vfhPlusStep(in, {}, no_memory);
    EXPECT_LT(fresh.direction * side, 0.0);
}

TEST(VfhPlus, BinaryHistogramHysteresis) {
    VfhPlusOptions o;
    auto in = field();
    // pick a distance whose density lies between tau_low and tau_high
    const double w = o.window;
    const double mid = 0.5 * (o.tau_low + o.tau_high);
    const double d = w * std::sqrt(1.0 - mid);
    setArc(in, 1.0, 1.3, d);
    setTarget(in, 0.0, 0.9);
    VfhState blocked_before;
    blocked_before.binary.assign(kN, 1);
    VfhState free_before;
    free_before.binary.assign(kN, 0);
    const int k = vfhSectorOf(1.15, kN);
    EXPECT_EQ(vfhPlusStep(in, blocked_before, o).binary[k], 1);
    EXPECT_EQ(vfhPlusStep(in, free_before, o).binary[k], 0);
}

TEST(VfhPlus, AllBlockedStops) {
    auto in = field(0.05);
    const auto out = vfhPlusStep(in, {}, {});
    EXPECT_EQ(out.sector, -1);
    EXPECT_EQ(out.speed, 0.0);
}

// Every key of [CHolonomicVFHPlus]: read back into its own field, at full precision.
TEST(VfhPlus, EveryKeyRoundTrips) {
    devslam::test::expectEveryKeyRoundTrips(
        [](const devslam::test::Ini& in, devslam::test::Ini& out) {
            VfhPlusOptions o;
            o.loadFromConfigFile(in, "CHolonomicVFHPlus");
            o.saveToConfigFile(out, "CHolonomicVFHPlus");
        });
}

TEST(VfhPlus, OptionsValidateAndRoundTrip) {
    VfhPlusOptions o;
    o.mu1 = 3.0;  // not > mu2 + mu3 = 4
    EXPECT_THROW(o.validate(), std::invalid_argument);
    VfhPlusOptions a;
    a.tau_low = 0.3;
    a.wide_valley_sectors = 12;
    mrpt::config::CConfigFileMemory c;
    a.saveToConfigFile(c, "CHolonomicVFHPlus");
    VfhPlusOptions b;
    b.loadFromConfigFile(c, "CHolonomicVFHPlus");
    EXPECT_DOUBLE_EQ(b.tau_low, 0.3);
    EXPECT_EQ(b.wide_valley_sectors, 12);
    c.write("CHolonomicVFHPlus", "tau_lwo", 0.2);
    try {
        b.loadFromConfigFile(c, "CHolonomicVFHPlus", "test.ini");
        FAIL() << "unknown key accepted";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("tau_lwo"), std::string::npos);
    }
}

TEST(CHolonomicVFHPlus, RegisteredAndCreatedByName) {
    registerNavClasses();
    for (const char* name : {"CHolonomicVFHPlus", "devslam::nav::CHolonomicVFHPlus"}) {
        auto m = mrpt::nav::CAbstractHolonomicReactiveMethod::Factory(name);
        ASSERT_TRUE(m) << name;
        EXPECT_NE(dynamic_cast<CHolonomicVFHPlus*>(m.get()), nullptr);
    }
}

TEST(CHolonomicVFHPlus, NavigateFillsOutputAndLogRecord) {
    CHolonomicVFHPlus m;
    mrpt::nav::CAbstractHolonomicReactiveMethod::NavInput ni;
    ni.obstacles.assign(kN, 1.0);
    ni.targets.emplace_back(0.0, 0.7);  // TP target to the left
    mrpt::nav::CAbstractHolonomicReactiveMethod::NavOutput no;
    m.navigate(ni, no);
    EXPECT_NEAR(no.desiredDirection, M_PI / 2, kSector);
    EXPECT_GT(no.desiredSpeed, 0.0);
    auto log = std::dynamic_pointer_cast<CLogFileRecord_VFHPlus>(no.logRecord);
    ASSERT_TRUE(log);
    EXPECT_EQ(log->binary.size(), static_cast<size_t>(kN));
    ASSERT_EQ(log->dirs_eval.size(), 1u);
    EXPECT_EQ(log->dirs_eval[0].size(), static_cast<size_t>(kN));
    EXPECT_EQ(log->selected_sector, m.lastOutput().sector);
}
