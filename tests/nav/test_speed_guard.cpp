// The speed guard (SpeedGuard.h): the command scale it allows for known speeds, limits and
// points, checked against stopping distances worked out by hand.
#include <devslam/nav/SpeedGuard.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

using devslam::nav::GuardMotion;
using devslam::nav::guardScale;
using devslam::nav::SpeedGuardOptions;
using mrpt::math::TPoint2D;

namespace {
constexpr double kRadius = 0.25;

SpeedGuardOptions limits() {
    SpeedGuardOptions o;
    o.max_acc = 1.0;       // m/s^2
    o.max_ang_acc = M_PI;  // rad/s^2 (180 deg/s^2)
    o.margin = 0.02;       // m
    return o;
}

/// A wall across the robot's way, `x` m ahead (points every 2 cm over 4 m).
std::vector<TPoint2D> wallAhead(double x) {
    std::vector<TPoint2D> w;
    for (double y = -2; y <= 2; y += 0.02) w.emplace_back(x, y);
    return w;
}

GuardMotion motion(double v0, double w0, double vc, double wc) {
    GuardMotion m;
    m.v0 = v0;
    m.w0 = w0;
    m.vc = vc;
    m.wc = wc;
    m.hold = 0.1;
    return m;
}
}  // namespace

TEST(SpeedGuard, NothingNearLeavesTheCommand) {
    EXPECT_EQ(guardScale(motion(1.0, 0, 1.0, 0.5), {}, kRadius, limits()), 1.0);
    // a wall farther than the robot can go before it stops: 1 m/s held 0.1 s, then 0.5 m
    EXPECT_EQ(guardScale(motion(1.0, 0, 1.0, 0), wallAhead(1.0), kRadius, limits()), 1.0);
}

// From 1 m/s at 1 m/s^2 the robot stops in 0.5 m. Commanded to stop, a wall whose points lie
// 3 cm beyond that (with radius and margin) is passed; 3 cm short of it, nothing is: the
// guard then says 0, to brake at once.
TEST(SpeedGuard, BrakingDistanceDecides) {
    const double stop = 0.5, keep = kRadius + 0.02;
    EXPECT_EQ(guardScale(motion(1.0, 0, 0, 0), wallAhead(stop + keep + 0.03), kRadius, limits()),
              1.0);
    int tried = 0;
    EXPECT_EQ(
        guardScale(motion(1.0, 0, 0, 0), wallAhead(stop + keep - 0.03), kRadius, limits(), &tried),
        0.0);
    EXPECT_EQ(tried, 11);  // 1, 0.9, ..., 0
    // Going on at 1 m/s for the period first (0.1 s) and stopping needs 0.1 + 0.5 m.
    EXPECT_EQ(guardScale(motion(1.0, 0, 1.0, 0), wallAhead(0.6 + keep + 0.03), kRadius, limits()),
              1.0);
    const double s =
        guardScale(motion(1.0, 0, 1.0, 0), wallAhead(0.6 + keep - 0.03), kRadius, limits());
    EXPECT_LT(s, 1.0);
    // Slower commands brake earlier: from 1 m/s toward s m/s for 0.1 s loses 0.1 m/s at most
    // (the acceleration limit), so any s < 0.9 is the same motion as 0.9: 0.095 m held, then
    // 0.405 m braking. That fits 0.6 - 0.03 m.
    EXPECT_GT(s, 0.0);
}

// Faster, the same wall is reached sooner: the scale never grows with the speed.
TEST(SpeedGuard, ScaleFallsWithSpeedAndGrowsWithRoom) {
    double last = 2;
    for (double v = 0.2; v <= 2.0; v += 0.2) {
        const double s = guardScale(motion(v, 0, v, 0), wallAhead(1.2), kRadius, limits());
        EXPECT_LE(s, last) << v;
        last = s;
    }
    EXPECT_EQ(last, 0.0);  // 2 m/s: 2 m to stop, the wall at 1.2 m
    last = -1;
    for (double x = 0.5; x <= 3.0; x += 0.25) {
        const double s = guardScale(motion(1.5, 0, 1.5, 0), wallAhead(x), kRadius, limits());
        EXPECT_GE(s, last) << x;
        last = s;
    }
    EXPECT_EQ(last, 1.0);
}

// The overshoot of paper_fig6 at 1.4 m/s: driving straight at 1.4 m/s, commanded into a
// left turn of 1.4 m/s and 90 deg/s with a wall 1.3 m ahead. The arc itself (radius 0.89 m)
// would clear it, but the robot needs 0.5 s to reach the turn rate and 1.4 s to stop.
TEST(SpeedGuard, ATurnTheRobotCannotTakeInTimeIsSlowed) {
    const auto m = motion(1.4, 0, 1.4, M_PI / 2);
    EXPECT_LT(guardScale(m, wallAhead(1.3), kRadius, limits()), 1.0);
    // With no acceleration limit to speak of, the same turn is taken as commanded.
    auto quick = limits();
    quick.max_acc = 20;
    quick.max_ang_acc = 60;
    EXPECT_EQ(guardScale(m, wallAhead(1.3), kRadius, quick), 1.0);
    // The turn rate's own lag: at 1 m/s a box corner 0.5 m ahead and 0.25 m to the right is
    // cleared by a left turn of 90 deg/s taken at once (in 0.1 s it turns 9 deg, then brakes
    // along it), not by the same turn built up at 180 deg/s^2 (under 2 deg), nor straight on.
    const std::vector<TPoint2D> corner{{0.5, -0.25}};
    auto instant_turn = limits();
    instant_turn.max_ang_acc = 1e6;
    const auto turn = motion(1.0, 0, 1.0, M_PI / 2);
    EXPECT_EQ(guardScale(turn, corner, kRadius, instant_turn), 1.0);
    EXPECT_EQ(guardScale(turn, corner, kRadius, limits()), 0.0);
    EXPECT_EQ(guardScale(motion(1.0, 0, 1.0, 0), corner, kRadius, instant_turn), 0.0);
}

// Driven at a wall by a command that never changes (as a navigator that wants to go there),
// step after step, the robot stops short of it: inside the margin the bound is fixed, so it
// does not creep in by the laser's noise at every step (the bound taken from the clearance
// now let it end 6-10 mm from the wall).
TEST(SpeedGuard, RepeatedStepsDoNotCreepIntoTheMargin) {
    const auto o = limits();
    for (const double speed : {0.1, 0.3, 0.6, 1.0}) {
        const double wall = 1.0;  // [m] its x; the robot starts at 0 facing it
        double x = 0, v = 0;
        for (int step = 0; step < 300; ++step) {  // 30 s of 0.1 s navigation periods
            const double s = guardScale(motion(v, 0, speed, 0), wallAhead(wall - x), kRadius, o);
            const double vc = s * speed;
            for (int k = 0; k < 10; ++k) {  // the robot at 100 Hz, as sim::Simulator drives it
                const double v1 = v + std::clamp(vc - v, -o.max_acc * 0.01, o.max_acc * 0.01);
                x += 0.5 * (v + v1) * 0.01;
                v = v1;
            }
        }
        const double clearance = wall - x - kRadius;
        EXPECT_GE(clearance, o.margin - 0.01 - 1e-3) << speed;  // the margin less the noise
        EXPECT_LE(clearance, o.margin + 0.01) << speed;         // and it did come close
        EXPECT_NEAR(v, 0, 1e-9) << speed;
    }
}

// A point already inside radius + margin (a wall brushed, a person come close) does not
// freeze the robot: it may turn in place, or move away, and toward it only down to the
// margin less the laser's noise.
TEST(SpeedGuard, APointAlreadyNearOnlyForbidsComingCloser) {
    const std::vector<TPoint2D> near{{0.253, 0.0}};  // 3 mm from the robot's edge, ahead
    EXPECT_EQ(guardScale(motion(0, 0, 0, 1.0), near, kRadius, limits()), 1.0);
    EXPECT_EQ(guardScale(motion(0, 0, -0.3, 0), near, kRadius, limits()), 1.0);
    EXPECT_EQ(guardScale(motion(0, 0, 0.3, 0), near, kRadius, limits()), 0.0);
    // 1.5 cm from the edge (inside the 2 cm margin): the robot may come 5 mm nearer, to the
    // margin less 1 cm of laser noise. 0.3 m/s for 0.1 s and the stop after it would take
    // 1 cm; 0.03 m/s takes 2 mm.
    const std::vector<TPoint2D> cm{{0.265, 0.0}};
    const double s = guardScale(motion(0, 0, 0.3, 0), cm, kRadius, limits());
    EXPECT_LT(s, 1.0);
    EXPECT_GT(s, 0.0);
    // Driving along a wall 1.5 cm off: every point of the wall ahead is nearer than now, but
    // the clearance stays.
    std::vector<TPoint2D> wall;
    for (double x = -2; x <= 2; x += 0.02) wall.emplace_back(x, 0.265);
    EXPECT_EQ(guardScale(motion(0.5, 0, 0.5, 0), wall, kRadius, limits()), 1.0);
    // NaN points (a sensor's gaps) are left out, not taken as everywhere
    const std::vector<TPoint2D> gap{{std::nan(""), std::nan("")}};
    EXPECT_EQ(guardScale(motion(0.5, 0, 0.5, 0), gap, kRadius, limits()), 1.0);
}

namespace {
/// A walker's near side as the laser sees it: an arc of points of a 0.22 m disc centred at
/// (cx, cy), facing the robot at the origin, moving at (vx, vy) [m/s].
devslam::nav::MovingPoints walker(double cx, double cy, double vx, double vy) {
    devslam::nav::MovingPoints w;
    const double r = 0.22, facing = std::atan2(-cy, -cx);
    for (int k = -3; k <= 3; ++k) {
        const double a = facing + 0.35 * k;
        w.points.emplace_back(cx + r * std::cos(a), cy + r * std::sin(a));
    }
    w.velocity = {vx, vy};
    return w;
}
}  // namespace

// A walker coming head-on: from 1 m/s the robot stops in 0.5 m (0.6 m with the hold), so the
// walker's near side 1.2 m ahead is clear as a still point (0.33 m beyond the 0.27 m kept)...
// but walking at the robot at 1 m/s it covers 1.1 m in the 1.1 s of the hold and that stop,
// and meets it. One walking away, or passing 0.75 m to the side, is no reason to slow; nor any
// walker with `walkers` off.
TEST(SpeedGuard, AWalkerIsCheckedWhereItWillBe) {
    const auto m = motion(1.0, 0, 1.0, 0);
    const auto coming = walker(1.42, 0, -1.0, 0);
    EXPECT_EQ(guardScale(m, coming.points, kRadius, limits()), 1.0) << "as still points";
    EXPECT_LT(guardScale(m, coming.points, {coming}, kRadius, limits()), 1.0);
    const auto going = walker(1.42, 0, 1.0, 0);
    EXPECT_EQ(guardScale(m, going.points, {going}, kRadius, limits()), 1.0);
    // (near enough to be looked at: within the robot's reach, 1 m, and the walker's 1.22 m)
    const auto passing = walker(1.6, 0.75, -1.0, 0);
    EXPECT_EQ(guardScale(m, passing.points, {passing}, kRadius, limits()), 1.0);
    auto off = limits();
    off.walkers = false;
    EXPECT_EQ(guardScale(m, coming.points, {coming}, kRadius, off), 1.0);
    // A walker far enough: in the 1.1 s of motion the robot goes 0.6 m, the walker 1.1 m, and
    // 0.27 m are kept; its near side 2.08 m ahead leaves 0.11 m.
    const auto far = walker(2.3, 0, -1.0, 0);
    EXPECT_EQ(guardScale(m, far.points, {far}, kRadius, limits()), 1.0);
}

// A walker inside the margin (1 cm off the robot's edge, walking away) does not loosen the bound
// of the still points: a wall that 0.5 m/s held and the stop bring 5 mm inside the margin
// slows the robot with the walker there as without it (the first version took the walker's
// nearness for a brushed wall and let the robot 1 cm nearer to it).
TEST(SpeedGuard, AWalkerNeverLoosensTheWallsBound) {
    const auto m = motion(0.5, 0, 0.5, 0);  // 0.05 m held, 0.125 m to stop
    const auto wall = wallAhead(0.175 + 0.265);
    const double alone = guardScale(m, wall, kRadius, limits());
    EXPECT_LT(alone, 1.0);
    devslam::nav::MovingPoints away;
    away.points = {{-0.26, 0.0}};
    away.velocity = {-1.0, 0.0};
    double still_only = -1;
    EXPECT_EQ(guardScale(m, wall, {away}, kRadius, limits(), nullptr, &still_only), alone);
    EXPECT_EQ(still_only, alone);
}

// A robot at rest that only turns moves its disc nowhere: a walker coming at it is no reason
// to turn slower (a slower turn ends sooner, before the walker arrives, and seemed to miss it).
TEST(SpeedGuard, AWalkerDoesNotSlowATurnInPlace) {
    const auto coming = walker(0.64, 0, -1.0, 0);  // near side 0.42 m off: 0.27 m in 0.15 s
    EXPECT_EQ(guardScale(motion(0, 0, 0, 2.0), coming.points, {coming}, kRadius, limits()), 1.0);
}

// A walker catching up from behind meets the robot whatever it does, and the sooner the
// harder it brakes: of the scales clear of the still points, the guard sends the one whose
// contact comes latest (here going on at full speed), not a stop. All 11 scales were tried.
TEST(SpeedGuard, AWalkerCatchingUpIsNotMetByStopping) {
    const auto m = motion(0.6, 0, 0.6, 0);
    const auto behind = walker(-1.02, 0, 1.2, 0);  // near side 0.8 m behind the centre
    int tried = 0;
    EXPECT_EQ(guardScale(m, behind.points, {behind}, kRadius, limits(), &tried), 1.0);
    EXPECT_EQ(tried, 11) << "no scale keeps clear of the walker";
    // ... but never one a still point forbids: with a wall 0.5 m ahead the robot goes on no
    // faster than the wall alone allows.
    auto pts = behind.points;
    const auto wall = wallAhead(0.5);
    pts.insert(pts.end(), wall.begin(), wall.end());
    const double by_wall = guardScale(m, pts, kRadius, limits());
    EXPECT_LT(by_wall, 1.0);
    EXPECT_EQ(guardScale(m, pts, {behind}, kRadius, limits()), by_wall);
}
