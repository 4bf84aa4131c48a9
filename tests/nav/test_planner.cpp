// Grid A* with known answers, endpoint validation, waypoints and replanning triggers.
#include <devslam/core/Config.h>
#include <devslam/nav/GridPlanner.h>
#include <devslam/nav/Navigator.h>
#include <devslam/nav/Replan.h>
#include <devslam/nav/VfhPlus.h>

#include "ConfigRoundTrip.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <tuple>
#include <vector>

using namespace devslam::nav;
using mrpt::math::TPoint2D;

namespace {
mrpt::maps::COccupancyGridMap2D emptyGrid(double w, double h, double res = 0.1) {
    mrpt::maps::COccupancyGridMap2D g;
    g.setSize(0, w, 0, h, static_cast<float>(res), 1.0f);
    return g;
}
void fillRect(mrpt::maps::COccupancyGridMap2D& g, double x0, double y0, double x1, double y1) {
    for (int y = 0; y < int(g.getSizeY()); y++)
        for (int x = 0; x < int(g.getSizeX()); x++) {
            const double cx = g.idx2x(x), cy = g.idx2y(y);
            if (cx >= x0 && cx <= x1 && cy >= y0 && cy <= y1) g.setCell(x, y, 0.0f);
        }
}
GridPlannerOptions plain() {
    GridPlannerOptions o;
    o.robot_radius = 0.05;
    o.inflation_margin = 0.0;
    o.clearance_weight = 0.0;
    return o;
}
}  // namespace

TEST(GridPlanner, StraightLineInFreeSpace) {
    GridPlanner p(plain());
    p.setMap(emptyGrid(10, 10));
    const auto path = p.plan({1.05, 5.05}, {8.05, 5.05});
    ASSERT_TRUE(path);
    EXPECT_NEAR(path->length, 7.0, 1e-9);
}

// Start and goal in one cell: the path runs from the start to the goal (it was the goal
// twice, length 0, the start lost).
TEST(GridPlanner, StartAndGoalInOneCell) {
    GridPlanner p(plain());
    p.setMap(emptyGrid(10, 10));
    const auto path = p.plan({1.01, 1.01}, {1.03, 1.05});
    ASSERT_TRUE(path);
    ASSERT_EQ(path->points.size(), 2u);
    EXPECT_DOUBLE_EQ(path->points.front().x, 1.01);
    EXPECT_DOUBLE_EQ(path->points.back().y, 1.05);
    EXPECT_NEAR(path->length, std::hypot(0.02, 0.04), 1e-12);
}

TEST(GridPlanner, OctileDiagonal) {
    GridPlanner p(plain());
    p.setMap(emptyGrid(10, 10));
    const auto path = p.plan({1.05, 1.05}, {4.05, 6.05});  // 3 diagonal + 2 straight metres
    ASSERT_TRUE(path);
    EXPECT_NEAR(path->cost, 3.0 * std::sqrt(2.0) + 2.0, 1e-6);
}

TEST(GridPlanner, WallWithGapKnownLength) {
    // 10x10 m, wall at x in [4.95, 5.05] except a gap around y = 8; path must go through it
    auto g = emptyGrid(10, 10);
    fillRect(g, 4.9, 0.0, 5.1, 7.5);
    fillRect(g, 4.9, 8.5, 5.1, 10.0);
    GridPlanner p(plain());
    p.setMap(g);
    const TPoint2D s(2.05, 2.05), t(8.05, 2.05);
    const auto path = p.plan(s, t);
    ASSERT_TRUE(path);
    // optimal on the cell graph: (2.05,2.05) -> (4.85,7.55) [lowest free gap row, wall cells
    // at x = 4.95 and 5.05] -> straight 0.3 m through the gap -> (5.15,7.55) -> (8.05,2.05)
    const double expected = (2.8 * std::sqrt(2.0) + 2.7) + 0.3 + (2.9 * std::sqrt(2.0) + 2.6);
    EXPECT_NEAR(path->cost, expected, 1e-6);
    bool through_gap = false;
    for (const auto& q : path->points)
        if (std::abs(q.x - 5.0) < 0.1 && q.y > 7.5 && q.y < 8.5) through_gap = true;
    EXPECT_TRUE(through_gap);
}

TEST(GridPlanner, NoPathIsNullopt) {
    auto g = emptyGrid(10, 10);
    fillRect(g, 4.9, 0.0, 5.1, 10.0);  // wall across the map
    GridPlanner p(plain());
    p.setMap(g);
    EXPECT_FALSE(p.plan({2, 5}, {8, 5}).has_value());
}

TEST(GridPlanner, InvalidEndpointsThrowClearErrors) {
    auto g = emptyGrid(10, 10);
    fillRect(g, 6.0, 4.0, 7.0, 6.0);
    GridPlannerOptions o;
    o.robot_radius = 0.3;
    GridPlanner p(o);
    p.setMap(g);
    try {
        (void)p.plan({-1, 5}, {2, 2});
        FAIL();
    } catch (const PlanningError& e) {
        EXPECT_EQ(e.status(), EndpointStatus::OutsideMap);
        EXPECT_NE(std::string(e.what()).find("start"), std::string::npos);
    }
    try {
        (void)p.plan({1, 1}, {6.5, 5.0});
        FAIL();
    } catch (const PlanningError& e) {
        EXPECT_EQ(e.status(), EndpointStatus::InsideObstacle);
        EXPECT_NE(std::string(e.what()).find("goal"), std::string::npos);
    }
    EXPECT_EQ(p.checkEndpoint({5.85, 5.0}), EndpointStatus::TooCloseToObstacle);
    // a goal 0.35 m from the box (inside the inflation margin, outside the radius) is reachable
    const auto near = p.plan({1, 1}, {5.65, 5.0});
    ASSERT_TRUE(near);
}

// A robot whose edge is 3 cm off a wall stands in a cell the 5 cm grid calls too close (its
// clearances are up to a cell and a half short): it is planned from the nearest cell it may
// stand in, which is a few centimetres away, not refused (the navigator's replan failed
// every time there, and the robot waited for the timeout).
TEST(GridPlanner, NearestTraversableCellOfARobotPressedAgainstAWall) {
    auto g = emptyGrid(6, 4, 0.05);
    // A wall whose face is at y = 1.01, in the cells it touches: its face on the grid is
    // at y = 1.05.
    fillRect(g, 0, 0.9, 6.0, 1.03);
    GridPlannerOptions o;
    o.robot_radius = 0.25;
    GridPlanner p(o);
    p.setMap(g);
    const TPoint2D robot{3.0, 1.29};  // its edge 3 cm off the wall
    ASSERT_EQ(p.checkEndpoint(robot), EndpointStatus::TooCloseToObstacle);
    EXPECT_THROW((void)p.plan(robot, {3.0, 3.5}), PlanningError);
    const auto s = p.nearestTraversable(robot, o.robot_radius);
    ASSERT_TRUE(s);
    EXPECT_EQ(p.checkEndpoint(*s), EndpointStatus::Ok);
    EXPECT_LE(std::hypot(s->x - robot.x, s->y - robot.y), 0.1);
    EXPECT_TRUE(p.plan(*s, {3.0, 3.5}));
    // A cell that is fine is its own answer; none within reach: nullopt.
    EXPECT_EQ(p.nearestTraversable({3.0, 2.5}, 0.25)->y, 2.5);
    EXPECT_FALSE(p.nearestTraversable({3.0, 0.95}, 0.1));
}

TEST(GridPlanner, InflationAndClearanceKeepAwayFromWalls) {
    auto g = emptyGrid(10, 6, 0.05);
    fillRect(g, 0, 2.9, 6.0, 3.1);  // a wall just above a straight line
    GridPlannerOptions o;
    o.robot_radius = 0.25;
    GridPlanner p(o);
    p.setMap(g);
    const auto path = p.plan({1.0, 2.0}, {9.0, 2.0});
    ASSERT_TRUE(path);
    double min_c = 1e9;
    for (const auto& q : path->points) min_c = std::min(min_c, p.clearance(q));
    EXPECT_GE(min_c, o.robot_radius + o.inflation_margin - 1e-6);
}

TEST(GridPlanner, WaypointsWithinSpacingAndClear) {
    auto g = emptyGrid(20, 10, 0.05);
    fillRect(g, 9.9, 0.0, 10.1, 6.0);
    GridPlanner p;
    p.setMap(g);
    const auto path = p.plan({2, 2}, {18, 2});
    ASSERT_TRUE(path);
    const auto wps = decimateWaypoints(p, *path, 1.5);
    ASSERT_GE(wps.size(), 2u);
    EXPECT_LT(wps.size(), path->points.size() / 5);
    EXPECT_NEAR(wps.back().x, 18.0, 1e-9);
    TPoint2D prev(2, 2);
    for (const auto& w : wps) {
        EXPECT_LE(std::hypot(w.x - prev.x, w.y - prev.y), 1.5 + 1e-9);
        EXPECT_TRUE(p.segmentClear(prev, w, p.options().robot_radius));
        prev = w;
    }
    // The same waypoints as indices into the path, increasing.
    const auto idx = decimateWaypointIndices(p, *path, 1.5);
    ASSERT_EQ(idx.size(), wps.size());
    for (std::size_t i = 0; i < idx.size(); ++i) {
        if (i > 0) {
            EXPECT_GT(idx[i], idx[i - 1]);
        }
        ASSERT_LT(idx[i], path->points.size());
        EXPECT_EQ(path->points[idx[i]].x, wps[i].x);
        EXPECT_EQ(path->points[idx[i]].y, wps[i].y);
    }
    EXPECT_EQ(idx.back(), path->points.size() - 1);
}

TEST(Replan, TriggersOnBlockedPathAndSustainedDensity) {
    ReplanOptions o;
    o.min_interval = 2.0;
    o.density_time = 3.0;
    o.density_threshold = 0.6;
    ReplanTrigger t(o);
    t.reset(0.0);
    EXPECT_EQ(t.update({1.0, true, 0.0}), ReplanReason::None);  // too soon after the last replan
    EXPECT_EQ(t.update({2.5, true, 0.0}), ReplanReason::PathBlocked);
    EXPECT_EQ(t.update({3.0, false, 0.9}), ReplanReason::None);  // dense since 3.0
    EXPECT_EQ(t.update({5.0, false, 0.9}), ReplanReason::None);  // only 2 s
    EXPECT_EQ(t.update({6.1, false, 0.9}), ReplanReason::HighDensity);
    EXPECT_EQ(t.update({9.0, false, 0.2}), ReplanReason::None);
}

TEST(Replan, PathBlockedLooksAheadOnly) {
    const std::vector<TPoint2D> path{{0, 0}, {2, 0}, {4, 0}, {6, 0}};
    const auto at = [&](const TPoint2D& robot) { return pathProgress(path, robot, 0, 1e9); };
    EXPECT_EQ(at({0.5, 0}), 0u);
    EXPECT_EQ(at({4.5, 0}), 2u);
    EXPECT_TRUE(pathBlocked(path, at({0.5, 0}), {{1.5, 0.1}}, 0.3, 2.0));
    EXPECT_FALSE(pathBlocked(path, at({0.5, 0}), {{1.5, 0.5}}, 0.3, 2.0));  // beside the path
    EXPECT_FALSE(pathBlocked(path, at({0.5, 0}), {{5.5, 0.0}}, 0.3, 2.0));  // beyond lookahead
    EXPECT_FALSE(pathBlocked(path, at({4.5, 0}), {{1.0, 0.0}}, 0.3, 2.0));  // behind the robot
    EXPECT_EQ(pathProgress({}, {0, 0}, 0, 2.0), 0u);
    EXPECT_EQ(pathProgress(path, {5.5, 0}, 99, 2.0), 2u);  // past the end: the last segment
    EXPECT_EQ(pathProgress(path, {0, 0}, 99, 2.0), 1u);    // 2 m back from it, no further
}

// A path that folds back past the robot (out along y = 0, round, back along y = 0.6, as a
// grid path of 5 cm steps): a robot pushed 0.35 m off the outward leg is nearer the way back.
// Its progress stays on the outward leg, so a person standing 1 m ahead of it blocks the path;
// taking the nearest segment anywhere checked the way back and missed the person.
TEST(Replan, ProgressAlongAFoldedPathFollowsTheRobot) {
    std::vector<TPoint2D> path;
    for (int i = 0; i <= 60; ++i) path.emplace_back(0.05 * i, 0.0);
    for (int i = 1; i <= 12; ++i) path.emplace_back(3.0, 0.05 * i);
    for (int i = 1; i <= 60; ++i) path.emplace_back(3.0 - 0.05 * i, 0.6);
    const TPoint2D robot{0.2, 0.35};
    const std::vector<TPoint2D> person{{1.2, 0.0}};

    const std::size_t anywhere = pathProgress(path, robot, 0, 1e9);
    ASSERT_GT(anywhere, 72u) << "the way back is nearer";
    EXPECT_FALSE(pathBlocked(path, anywhere, person, 0.3, 2.0));

    std::size_t seg = 0;
    for (const double x : {0.0, 0.1, 0.2}) {  // the robot's last steps
        const std::size_t next = pathProgress(path, {x, x < 0.2 ? 0.0 : 0.35}, seg, 2.0);
        EXPECT_GE(next, seg);
        seg = next;
    }
    EXPECT_EQ(seg, 3u) << "the outward segment ending beside the robot (x 0.15-0.20)";
    EXPECT_TRUE(pathBlocked(path, seg, person, 0.3, 2.0));
    // It moves on along the way back once the robot gets there.
    for (int i = 3; i <= 30; ++i) seg = pathProgress(path, {0.1 * i, 0.0}, seg, 2.0);
    for (int i = 30; i >= 10; --i) seg = pathProgress(path, {0.1 * i, 0.6}, seg, 2.0);
    EXPECT_EQ(seg, 111u) << "the way back, the segment ending at x = 1.0";
    // Pushed back 1 m along the way back, it is followed there; the outward leg, 0.6 m away
    // beside it but 4 m back along the path, is out of reach.
    EXPECT_EQ(pathProgress(path, {2.0, 0.6}, seg, 2.0), 91u) << "back to x = 2.0";
    EXPECT_GT(pathProgress(path, {2.0, 0.25}, seg, 2.0), 72u) << "the outward leg is behind";
}

// When MRPT gives up and no new plan is found, the navigator sends the old path on from the
// waypoint ahead of the robot's progress. On the folded path, a robot pushed off the outward
// leg is nearest a waypoint of the way back, across the fold from it.
TEST(Replan, WaypointAheadFollowsProgressNotDistance) {
    EXPECT_EQ(waypointAhead({}, 3), 0u);
    const std::vector<std::size_t> idx{10, 20, 30, 40};
    EXPECT_EQ(waypointAhead(idx, 0), 0u);
    EXPECT_EQ(waypointAhead(idx, 9), 0u);   // segment 9 ends at point 10
    EXPECT_EQ(waypointAhead(idx, 10), 1u);  // at point 10 already: the next
    EXPECT_EQ(waypointAhead(idx, 39), 3u);
    EXPECT_EQ(waypointAhead(idx, 40), 3u);  // past the last: the last (the goal)

    std::vector<TPoint2D> path;
    for (int i = 0; i <= 60; ++i) path.emplace_back(0.05 * i, 0.0);
    for (int i = 1; i <= 12; ++i) path.emplace_back(3.0, 0.05 * i);
    for (int i = 1; i <= 60; ++i) path.emplace_back(3.0 - 0.05 * i, 0.6);
    std::vector<std::size_t> wp;  // every 10th point and the goal
    for (std::size_t i = 10; i < path.size(); i += 10) wp.push_back(i);
    if (wp.back() != path.size() - 1) wp.push_back(path.size() - 1);
    const TPoint2D robot{0.2, 0.35};
    std::size_t seg = 0;
    for (const double x : {0.0, 0.1}) seg = pathProgress(path, {x, 0.0}, seg, 2.0);
    seg = pathProgress(path, robot, seg, 2.0);
    const auto ahead = path[wp[waypointAhead(wp, seg)]];
    EXPECT_NEAR(ahead.x, 0.5, 1e-9);
    EXPECT_NEAR(ahead.y, 0.0, 1e-9);
    const auto nearest = *std::min_element(wp.begin(), wp.end(), [&](auto a, auto b) {
        return std::hypot(path[a].x - robot.x, path[a].y - robot.y) <
               std::hypot(path[b].x - robot.x, path[b].y - robot.y);
    });
    EXPECT_NEAR(path[nearest].y, 0.6, 1e-9) << "nearest anywhere: on the way back";
}

// A person sensed beside the goal (or the robot) is stamped on the replanning map, and the
// goal and start stay plannable: a disc whose cells reached within the robot radius of the
// goal's cell (clearance between cell centres) made the replan fail and fall back to the
// static map, without any of the sensed obstacles (0.55-0.57 m from the goal: 57 % of points).
TEST(Replan, SensedDiscsLeaveStartAndGoalPlannable) {
    const auto map = emptyGrid(6, 6, 0.05);
    GridPlannerOptions po;
    po.robot_radius = 0.25;
    GridPlanner planner(po);
    ReplanOptions ro;  // discs of 0.30 m within 3 m
    const TPoint2D robot{1.51, 3.02}, goal{3.52, 3.02};
    int stamped = 0;
    for (int k = 0; k < 36; ++k) {
        const double a = k * 10.0 * M_PI / 180.0;
        // (Points within the robot radius + the disc of the goal, 0.55 m, are not stamped.)
        for (const double d : {0.56, 0.57, 0.58, 0.62, 0.66, 0.70}) {
            const TPoint2D near_goal{goal.x + d * std::cos(a), goal.y + d * std::sin(a)};
            const TPoint2D near_robot{robot.x + d * std::cos(a), robot.y + d * std::sin(a)};
            const auto m =
                stampSensedObstacles(map, robot, goal, {near_goal, near_robot}, 0.25, ro);
            planner.setMap(m);
            ASSERT_EQ(planner.checkEndpoint(goal), EndpointStatus::Ok) << d << " m at " << k * 10;
            ASSERT_EQ(planner.checkEndpoint(robot), EndpointStatus::Ok) << d << " m at " << k * 10;
            ASSERT_TRUE(planner.plan(robot, goal).has_value());
            // The sensed point itself is on the map (not dropped), where it is in reach.
            stamped += m.getCell(m.x2idx(near_goal.x), m.y2idx(near_goal.y)) < 0.5f;
        }
    }
    EXPECT_EQ(stamped, 36 * 6);
    // Nothing is stamped on the robot itself or beyond sensed_range.
    const auto m = stampSensedObstacles(map, robot, goal, {{1.6, 3.02}, {5.9, 0.5}}, 0.25, ro);
    EXPECT_GT(m.getCell(m.x2idx(1.6), m.y2idx(3.02)), 0.5f);
    EXPECT_GT(m.getCell(m.x2idx(5.9), m.y2idx(0.5)), 0.5f);
}

// The laser sees the walls the route keeps clear of: those points are not obstacles to replan
// for (a route 0.25-0.35 m from a wall was "blocked" by it and planned again, unchanged, every
// min_interval). People and unmapped objects are.
TEST(Replan, OnlyPointsTheMapDoesNotHoldCount) {
    auto map = emptyGrid(6, 6, 0.05);
    fillRect(map, 0, 2.0, 6, 2.1);  // a wall along y = 2.0-2.1
    GridPlannerOptions po;
    po.robot_radius = 0.25;
    GridPlanner planner(po);
    planner.setMap(map);
    const std::vector<TPoint2D> sensed{{1.0, 1.99},
                                       {2.0, 1.97},
                                       {3.0, 2.11},   // the wall's faces
                                       {4.0, 1.70}};  // a person 0.3 m from it
    const auto left = unmappedPoints(planner, sensed);
    ASSERT_EQ(left.size(), 1u);
    EXPECT_DOUBLE_EQ(left[0].x, 4.0);
    // A route 0.3 m from the wall is blocked by the person only.
    const std::vector<TPoint2D> route{{0.5, 1.7}, {5.5, 1.7}};
    EXPECT_TRUE(pathBlocked(route, 0, sensed, 0.30, 6.0)) << "all points";
    EXPECT_FALSE(pathBlocked(route, 0, unmappedPoints(planner, {sensed[0], sensed[1]}), 0.30, 6.0));
    EXPECT_TRUE(pathBlocked(route, 0, left, 0.30, 6.0));
}

// config_ini/nav_reactive.ini is the one navigation INI shipped (the world files have their
// own test): its values are read, not the defaults.
TEST(NavConfig, TheShippedNavIniLoads) {
    const std::string path = std::string(DEVSLAM_SOURCE_DIR) + "/config_ini/nav_reactive.ini";
    const auto cfg = devslam::core::loadIni(path);
    const auto o = NavigatorOptions::fromConfig(*cfg, path);
    EXPECT_EQ(o.holonomic_method, "CHolonomicVFHPlus");
    EXPECT_DOUBLE_EQ(o.nav_period, 0.1);
    EXPECT_DOUBLE_EQ(o.planner.waypoint_spacing, 1.5);
    EXPECT_DOUBLE_EQ(o.person_margin, 0.1);
    EXPECT_TRUE(o.guard.enabled);
    EXPECT_DOUBLE_EQ(o.guard.max_acc, 1.0);
    EXPECT_NEAR(o.guard.max_ang_acc, M_PI, 1e-12);  // 180 deg/s^2
    EXPECT_DOUBLE_EQ(o.guard.margin, 0.02);
    VfhPlusOptions v;
    v.loadFromConfigFile(*cfg, "CHolonomicVFHPlus", path);
    EXPECT_GT(v.mu1, v.mu2 + v.mu3);
}

/// The message NavigatorOptions::fromConfig throws for `c` read as "x.ini", "" if none.
std::string navError(const mrpt::config::CConfigFileBase& c) {
    try {
        (void)NavigatorOptions::fromConfig(c, "x.ini");
    } catch (const std::invalid_argument& e) {
        return e.what();
    }
    return "";
}

/// config_ini/nav_reactive.ini in memory, to be changed by a test.
mrpt::config::CConfigFileMemory shippedNavIni() {
    const auto shipped =
        devslam::core::loadIni(std::string(DEVSLAM_SOURCE_DIR) + "/config_ini/nav_reactive.ini");
    std::string text;
    shipped->getContent(text);
    return mrpt::config::CConfigFileMemory(text);
}

// MRPT reads its own sections leniently ("fast" is 0, a mistyped key is ignored); they are
// checked against the keys MRPT's parameter structures write, with the file named.
TEST(NavConfig, MrptSectionsAreReadStrictly) {
    const auto errorOf = [&](const std::string& section, const std::string& key,
                             const std::string& value) {
        auto c = shippedNavIni();
        c.write(section, key, value);
        return navError(c);
    };
    EXPECT_EQ(errorOf("navigator", "nav_period", "0.1"), "");  // the shipped file passes
    // [replan] values that silently turned a trigger off (a negative margin) are refused.
    EXPECT_EQ(errorOf("replan", "blocked_margin", "-0.5"),
              "x.ini [replan] blocked_margin: must be >= 0 m");
    EXPECT_EQ(errorOf("replan", "sensed_range", "0"), "x.ini [replan] sensed_range: must be > 0 m");
    // Values no robot needs, which silently disabled what they set (the replans fell back
    // to the static map; VFH+ blocked every sector).
    EXPECT_EQ(errorOf("replan", "obstacle_inflation", "1e9"),
              "x.ini [replan] obstacle_inflation: must be in [0, 2] m");
    EXPECT_EQ(errorOf("CHolonomicVFHPlus", "enlargement_radius", "1e9"),
              "x.ini [CHolonomicVFHPlus] enlargement_radius: must be in [0, 5] m");
    EXPECT_EQ(errorOf("CAbstractPTGBasedReactive", "robotMax_V_mps", "fast"),
              "x.ini [CAbstractPTGBasedReactive] robotMax_V_mps: expected a number, got 'fast'");
    EXPECT_EQ(errorOf("CAbstractNavigator", "alarm_seems_not_approaching_target_timeout", "15s"),
              "x.ini [CAbstractNavigator] alarm_seems_not_approaching_target_timeout: expected a "
              "number, got '15s'");
    // One number where MRPT reads one (it takes the first of a list), whole where it reads
    // an integer (it cuts 121.7 to 121).
    EXPECT_EQ(errorOf("CAbstractPTGBasedReactive", "robotMax_V_mps", "0.3 5"),
              "x.ini [CAbstractPTGBasedReactive] robotMax_V_mps: expected a number, got '0.3 5'");
    EXPECT_EQ(errorOf("CReactiveNavigationSystem", "PTG0_num_paths", "121.7"),
              "x.ini [CReactiveNavigationSystem] PTG0_num_paths: expected an integer, got '121.7'");
    // MRPT's read_bool reads "on" as false (not true/false/yes/no: an integer, 0).
    EXPECT_EQ(errorOf("CAbstractPTGBasedReactive", "enable_obstacle_filtering", "on"),
              "x.ini [CAbstractPTGBasedReactive] enable_obstacle_filtering: expected true or "
              "false, got 'on'");
    EXPECT_EQ(errorOf("CAbstractPTGBasedReactive", "enable_obstacle_filtering", "yes"), "");
    // Numbered keys MRPT reads as many of as another key says, and the obstacle filter's.
    EXPECT_EQ(errorOf("CHolonomicFullEval", "PHASE4_FACTORS", "[1]"), "");
    EXPECT_EQ(errorOf("CHolonomicFullEval", "PHASE4_THRESHOLD", "0.7x"),
              "x.ini [CHolonomicFullEval] PHASE4_THRESHOLD: expected a number, got '0.7x'");
    EXPECT_EQ(errorOf("CReactiveNavigationSystem", "PTG0_shape_x0", "0.2"),  // known, no y0
              "x.ini [CReactiveNavigationSystem] PTG0_*: MRPT refuses this PTG: Error: mismatch "
              "between number of pts in {x,y} defining robot shape");
    EXPECT_EQ(errorOf("CPointCloudFilterByDistance", "min_dist", "0.1"), "");
    EXPECT_NE(
        errorOf("CPointCloudFilterByDistance", "min_dst", "0.1").find("unknown key 'min_dst'"),
        std::string::npos);
    EXPECT_EQ(errorOf("CAbstractPTGBasedReactive", "use_delays_model", "maybe"),
              "x.ini [CAbstractPTGBasedReactive] use_delays_model: expected true or false, got "
              "'maybe'");
    EXPECT_NE(errorOf("CAbstractPTGBasedReactive", "secure_distanse_start", "0.05")
                  .find("x.ini [CAbstractPTGBasedReactive]: unknown key 'secure_distanse_start' "
                        "(MRPT's navigator knows: "),
              std::string::npos);
    // exprtk's inf in a formula: every motion scored inf or NaN, and the robot never moved.
    EXPECT_EQ(errorOf("CMultiObjMotionOpt_Scalarization", "scalar_score_formula",
                      "ptg_priority_score*(0.3*target_distance + INF*hysteresis_score)"),
              "x.ini [CMultiObjMotionOpt_Scalarization] scalar_score_formula: uses exprtk's "
              "constant inf: a score of inf or NaN leaves MRPT no motion to choose");
    EXPECT_EQ(errorOf("CMultiObjectiveMotionOptimizerBase", "score1_formula", "-inf"),
              "x.ini [CMultiObjectiveMotionOptimizerBase] score1_formula: uses exprtk's constant "
              "inf: a score of inf or NaN leaves MRPT no motion to choose");
    EXPECT_NE(errorOf("CMultiObjectiveMotionOptimizerBase", "score1_formula", "0.5*2inf"), "");
    // A movement assertion may compare with inf: a truth value, no score.
    EXPECT_EQ(errorOf("CMultiObjectiveMotionOptimizerBase", "movement_assert1",
                      "collision_free_distance < inf"),
              "");
    EXPECT_EQ(errorOf("CMultiObjMotionOpt_Scalarization", "scalar_score_formula",
                      "ptg_priority_score*(0.3*target_distance + 8.0*info_gain)"),
              "");  // a name holding "inf" is no constant
    EXPECT_EQ(errorOf("CHolonomicND", "factorWeights", "1 0.5 x 0.4"),
              "x.ini [CHolonomicND] factorWeights: 'x' is not a number");
    // Values MRPT asserts on only while navigating: a speed limit of 0 or below gave an MRPT
    // stack trace at every step (and the run went on); factorWeights of the wrong length a
    // message with no file that stopped mid-sentence.
    for (const char* k : {"robotMax_V_mps", "robotMax_W_degps"})
        for (const char* v : {"0", "-1"})
            EXPECT_EQ(errorOf("CAbstractPTGBasedReactive", k, v),
                      std::string("x.ini [CAbstractPTGBasedReactive] ") + k + ": must be > 0")
                << k << " = " << v;
    EXPECT_EQ(errorOf("CHolonomicND", "factorWeights", "1.0"),
              "x.ini [CHolonomicND] factorWeights: expected 4 numbers, got 1");
    EXPECT_EQ(errorOf("CHolonomicFullEval", "factorWeights", "[0.25]"),
              "x.ini [CHolonomicFullEval] factorWeights: expected 7 numbers, got 1");
    EXPECT_EQ(errorOf("CHolonomicFullEval", "factorWeights", "1 1 1 0 1 1 1"), "");
    // FullEval's phases and VFF's forces, which MRPT checks only inside a navigation step
    // (an index out of range or PHASE_COUNT 0: an error at every step until the timeout) or
    // not at all (a force below 0: the robot stood still until the timeout).
    EXPECT_EQ(errorOf("CHolonomicFullEval", "PHASE_COUNT", "0"),
              "x.ini [CHolonomicFullEval] PHASE_COUNT: must be 1..16");
    EXPECT_EQ(errorOf("CHolonomicFullEval", "PHASE_COUNT", "4"),
              "x.ini [CHolonomicFullEval] PHASE4_FACTORS: missing (PHASE_COUNT is 4)");
    EXPECT_EQ(errorOf("CHolonomicFullEval", "PHASE1_FACTORS", "[99]"),
              "x.ini [CHolonomicFullEval] PHASE1_FACTORS: factor indices must be integers 0..6");
    EXPECT_EQ(errorOf("CHolonomicFullEval", "PHASE1_FACTORS", "[0.5]"),
              "x.ini [CHolonomicFullEval] PHASE1_FACTORS: factor indices must be integers 0..6");
    EXPECT_EQ(errorOf("CHolonomicFullEval", "PHASE2_THRESHOLD", "1.5"),
              "x.ini [CHolonomicFullEval] PHASE2_THRESHOLD: must be in [0, 1]");
    // (2026-12-07, a bad-input sweep) weights MRPT asserted on at the first step, with a stack
    // trace: a phase whose factors weigh 0 in all. Negative weights MRPT takes (a review ran
    // FullEval and ND with them): accepted.
    EXPECT_EQ(errorOf("CHolonomicFullEval", "factorWeights", "1 1 1 1 1 1 0"),
              "x.ini [CHolonomicFullEval] PHASE1_FACTORS: the factorWeights of these factors sum "
              "to 0; a phase needs a weight above 0");
    EXPECT_EQ(errorOf("CHolonomicND", "factorWeights", "1 -0.5 1 1"), "");
    // PTG settings MRPT took with a message naming no key and a PTG it then ran without (the
    // alpha constants at 0), or refused mid-sentence (2 paths with evaluate_clearance, fewer
    // than the 15 its clearance analysis takes; without it they run), or failed with at the
    // first step (paths shorter than the 1 m MRPT 2.5's scoring asks for).
    EXPECT_EQ(errorOf("CReactiveNavigationSystem", "PTG1_cte_a0v_deg", "0"),
              "x.ini [CReactiveNavigationSystem] PTG1_cte_a0v_deg: must be > 0");
    EXPECT_EQ(errorOf("CReactiveNavigationSystem", "PTG0_num_paths", "2"), "");
    {
        auto c = shippedNavIni();
        c.write("CAbstractPTGBasedReactive", "evaluate_clearance", "true");
        c.write("CReactiveNavigationSystem", "PTG0_num_paths", "2");
        EXPECT_EQ(navError(c), "x.ini [CReactiveNavigationSystem] PTG0_num_paths: must be at "
                               "least PTG0_clearance_decimated_paths (15)");
        c.write("CReactiveNavigationSystem", "PTG0_num_paths", "15");
        EXPECT_EQ(navError(c), "");
    }
    EXPECT_EQ(errorOf("CReactiveNavigationSystem", "PTG3_refDistance", "0.9"),
              "x.ini [CReactiveNavigationSystem] PTG3_refDistance: must be at least 1 m (MRPT "
              "2.5 scores each path at its point 1 m along it)");
    EXPECT_EQ(errorOf("CHolonomicVFF", "TARGET_ATTRACTIVE_FORCE", "-20"),
              "x.ini [CHolonomicVFF] TARGET_ATTRACTIVE_FORCE: must be > 0");
    EXPECT_EQ(errorOf("CHolonomicVFF", "TARGET_SLOW_APPROACHING_DISTANCE", "-0.1"),
              "x.ini [CHolonomicVFF] TARGET_SLOW_APPROACHING_DISTANCE: must be >= 0");
    EXPECT_EQ(errorOf("CHolonomicVFF", "TARGET_SLOW_APPROACHING_DISTANCE", "0"), "");
    EXPECT_EQ(errorOf("CHolonomicVFHPlus", "window", "0.6x"),
              "x.ini [CHolonomicVFHPlus] window: expected a number, got '0.6x'");
    // The PTGs: their count, classes and each class's own keys.
    EXPECT_EQ(errorOf("CReactiveNavigationSystem", "PTG0_v_max_mps", "0.6m"),
              "x.ini [CReactiveNavigationSystem] PTG0_v_max_mps: expected a number, got '0.6m'");
    const std::string k = errorOf("CReactiveNavigationSystem", "PTG1_K", "1");  // C has K
    EXPECT_EQ(k.rfind("x.ini [CReactiveNavigationSystem]: unknown key 'PTG1_K' (MRPT's "
                      "navigator knows: ",
                      0),
              0u)
        << k;
    for (const char* known :
         {"PTG0_K,", "PTG1_cte_a0v_deg,", "PTG_COUNT,", "RobotModel_shape2D_xs"})
        EXPECT_NE(k.find(known), std::string::npos) << known;
    EXPECT_EQ(errorOf("CReactiveNavigationSystem", "PTG_COUNT", "0"),
              "x.ini [CReactiveNavigationSystem] PTG_COUNT: must be 1..32, got 0");
    EXPECT_EQ(errorOf("CReactiveNavigationSystem", "PTG_COUNT", "5"),
              "x.ini [CReactiveNavigationSystem] PTG4_Type: missing (PTG_COUNT is 5)");
    EXPECT_EQ(errorOf("CReactiveNavigationSystem", "PTG0_Type", "CPTG_Spiral"),
              "x.ini [CReactiveNavigationSystem] PTG0_Type: unknown PTG class 'CPTG_Spiral'");
    EXPECT_EQ(errorOf("CReactiveNavigationSystem", "PTG0_num_paths", "0"),
              "x.ini [CReactiveNavigationSystem] PTG0_num_paths: must be > 0");
    // What MRPT builds at the start without a word: 10000 paths ran for minutes, 0.0001 m
    // cells ran out of memory; a negative speed filter gave NaN commands.
    EXPECT_EQ(errorOf("CReactiveNavigationSystem", "PTG0_num_paths", "10000"),
              "x.ini [CReactiveNavigationSystem] PTG0_num_paths: must be at most 1000");
    EXPECT_EQ(errorOf("CReactiveNavigationSystem", "PTG1_resolution", "0.0001"),
              "x.ini [CReactiveNavigationSystem] PTG1_resolution: with PTG1_refDistance 2.5 m "
              "and PTG1_resolution 0.0001 m, the collision grid has 50000 x 50000 cells (at most "
              "3000 x 3000)");
    EXPECT_EQ(errorOf("CAbstractPTGBasedReactive", "speedfilter_tau", "-1"),
              "x.ini [CAbstractPTGBasedReactive] speedfilter_tau: must be in [0, 1e4] s");
    // Taken unchecked until 2026-12-07 (a bad-input sweep): a filter that never lets the
    // robot speed up (1e9 s; 1e5 s still ran), a slow-down ramp beyond the paths, a timeout of
    // 0, a negative count of steps, a C PTG's direction 0, a negative priority.
    EXPECT_EQ(errorOf("CAbstractPTGBasedReactive", "speedfilter_tau", "1e9"),
              "x.ini [CAbstractPTGBasedReactive] speedfilter_tau: must be in [0, 1e4] s");
    EXPECT_EQ(errorOf("CAbstractPTGBasedReactive", "secure_distance_end", "5"),
              "x.ini [CAbstractPTGBasedReactive] secure_distance_end: must be at most 1 (a "
              "fraction of each PTG's refDistance)");
    EXPECT_EQ(errorOf("CAbstractNavigator", "alarm_seems_not_approaching_target_timeout", "0"),
              "x.ini [CAbstractNavigator] alarm_seems_not_approaching_target_timeout: must be "
              "> 0 s");
    EXPECT_EQ(errorOf("CWaypointsNavigator", "min_timesteps_confirm_skip_waypoints", "-1"),
              "x.ini [CWaypointsNavigator] min_timesteps_confirm_skip_waypoints: must be >= 0 "
              "[steps]");
    EXPECT_EQ(errorOf("CWaypointsNavigator", "min_timesteps_confirm_skip_waypoints", "0"), "");
    EXPECT_EQ(errorOf("CReactiveNavigationSystem", "PTG0_K", "0"),
              "x.ini [CReactiveNavigationSystem] PTG0_K: must not be 0 (its sign is the "
              "direction: 1 forward, -1 backward)");
    EXPECT_EQ(errorOf("CReactiveNavigationSystem", "PTG2_K", "-5"), "");  // MRPT takes its sign
    EXPECT_EQ(errorOf("CReactiveNavigationSystem", "PTG0_score_priority", "-1"),
              "x.ini [CReactiveNavigationSystem] PTG0_score_priority: must be >= 0");
    EXPECT_EQ(errorOf("CMultiObjectiveMotionOptimizerBase", "scores_to_normalize",
                      "hysteresis_score, bogus_score"),
              "x.ini [CMultiObjectiveMotionOptimizerBase] scores_to_normalize: no score is "
              "named 'bogus_score' (scores: target_distance, collision_free_distance_score, "
              "euclidean_nearness, hysteresis_score, path_index_near_target, "
              "ptg_priority_score)");
    EXPECT_EQ(errorOf("CMultiObjectiveMotionOptimizerBase", "scores_to_normalize",
                      "hysteresis_score,euclidean_nearness"),
              "");
    // MRPT's other differential-drive PTGs read the same keys as C (K included): accepted.
    for (const char* type : {"CPTG_DiffDrive_CC", "CPTG_DiffDrive_CCS", "CPTG_DiffDrive_CS"})
        EXPECT_EQ(errorOf("CReactiveNavigationSystem", "PTG2_Type", type), "") << type;
    // A holonomic PTG has no collision grid: the diff-drive keys are not its own.
    EXPECT_NE(errorOf("CReactiveNavigationSystem", "PTG0_Type", "CPTG_Holo_Blend")
                  .find("x.ini [CReactiveNavigationSystem]: unknown key 'PTG0_K'"),
              std::string::npos);
    // Formulas are text; the numbered score keys are known by their pattern.
    EXPECT_EQ(errorOf("CMultiObjectiveMotionOptimizerBase", "score7_name", "extra"), "");
    EXPECT_NE(errorOf("CMultiObjectiveMotionOptimizerBase", "scor7_name", "extra"), "");
}

// --max-speed's INI: MRPT's top speed and the PTGs at it take the new one; PTG3, slower on
// purpose (0.3 m/s, its tight turns behind the robot), keeps its own.
TEST(NavConfig, SetTopSpeedRaisesThePtgsAtTheTopSpeedOnly) {
    auto c = shippedNavIni();
    ASSERT_EQ(c.read_double("CAbstractPTGBasedReactive", "robotMax_V_mps", 0), 0.6);
    devslam::nav::setTopSpeed(c, 1.4);
    EXPECT_EQ(c.read_double("CAbstractPTGBasedReactive", "robotMax_V_mps", 0), 1.4);
    for (const char* key : {"PTG0_v_max_mps", "PTG1_v_max_mps", "PTG2_v_max_mps"})
        EXPECT_EQ(c.read_double("CReactiveNavigationSystem", key, 0), 1.4) << key;
    EXPECT_EQ(c.read_double("CReactiveNavigationSystem", "PTG3_v_max_mps", 0), 0.3);
    EXPECT_EQ(navError(c), "");
    for (const double v : {0.0, -1.0, 5.5, std::nan("")}) {
        try {
            devslam::nav::setTopSpeed(c, v);
            ADD_FAILURE() << v;
        } catch (const std::invalid_argument& e) {
            EXPECT_STREQ(e.what(), "--max-speed: must be in (0, 5] m/s");
        }
    }
}

TEST(NavConfig, UnknownKeyIsReported) {
    // The message of reading one INI holding `section.key = value`, "" when it is accepted.
    const auto errorOf = [](const std::vector<std::tuple<std::string, std::string, double>>& kv) {
        auto c = shippedNavIni();
        for (const auto& [section, key, value] : kv) c.write(section, key, value);
        return navError(c);
    };
    EXPECT_NE(errorOf({{"navigator", "nav_perod", 0.1}}).find("nav_perod"), std::string::npos);
    EXPECT_EQ(errorOf({{"navigator", "person_margin", -0.1}}),
              "x.ini [navigator] person_margin: must be in [0, 2] m");
    EXPECT_EQ(errorOf({{"navigator", "nav_period", 5.0}}),
              "x.ini [navigator] nav_period: must be in (0, 1] s");
    // The speed guard's limits: a robot that cannot accelerate never moves, one above the
    // world files' bounds is no robot they describe.
    for (const double a : {0.0, -1.0, 21.0})
        EXPECT_EQ(errorOf({{"navigator", "max_acc", a}}),
                  "x.ini [navigator] max_acc: must be in (0, 20] m/s^2")
            << a;
    for (const double a : {0.0, 3601.0})
        EXPECT_EQ(errorOf({{"navigator", "max_ang_acc_deg", a}}),
                  "x.ini [navigator] max_ang_acc_deg: must be in (0, 3600] deg/s^2")
            << a;
    EXPECT_EQ(errorOf({{"navigator", "max_ang_acc_deg", 3600.0}}), "");
    EXPECT_EQ(errorOf({{"navigator", "guard_margin", -0.01}}),
              "x.ini [navigator] guard_margin: must be in [0, 1] m");
    EXPECT_EQ(errorOf({{"navigator", "guard_margin", 0.0}}), "");
    for (const double h : {-0.1, 5.5})
        EXPECT_EQ(errorOf({{"navigator", "person_predict_horizon", h}}),
                  "x.ini [navigator] person_predict_horizon: must be in [0, 5] s")
            << h;
    EXPECT_EQ(errorOf({{"navigator", "person_predict_horizon", 0.0}}), "");
    {
        auto c = shippedNavIni();
        c.write("navigator", "guard_walkers", std::string("sometimes"));
        const auto e = navError(c);
        EXPECT_NE(e.find("x.ini [navigator] guard_walkers"), std::string::npos) << e;
        c.write("navigator", "guard_walkers", std::string("false"));
        EXPECT_EQ(navError(c), "");
    }
    for (const double d : {-1.0, 0.0, 1e9})
        EXPECT_EQ(errorOf({{"navigator", "waypoint_allowed_distance", d}}),
                  "x.ini [navigator] waypoint_allowed_distance: must be in (0, 10] m")
            << d;
    // MRPT asserted end > start inside every navigation step.
    EXPECT_EQ(errorOf({{"CAbstractPTGBasedReactive", "secure_distance_start", 0.2}}),
              "x.ini [CAbstractPTGBasedReactive] secure_distance_end: must be > "
              "secure_distance_start (0.2)");
    EXPECT_EQ(errorOf({{"CAbstractPTGBasedReactive", "secure_distance_start", -0.1}}),
              "x.ini [CAbstractPTGBasedReactive] secure_distance_start: must be >= 0");
    // Values of the planner's and the replanner's sections, and MRPT's ref_distance, name the
    // file as well.
    EXPECT_EQ(errorOf({{"global_planner", "robot_radius", -1.0}}),
              "x.ini [global_planner] robot_radius: must be > 0 m");
    EXPECT_EQ(errorOf({{"CAbstractPTGBasedReactive", "ref_distance", 0.0}}),
              "x.ini [CAbstractPTGBasedReactive] ref_distance: must be > 0 m");
    // A mistyped section: its keys would all be ignored.
    const std::string section =
        errorOf({{"navigator", "nav_period", 0.1}, {"CHolonomicVFHPlu", "mu1", 6.0}});
    EXPECT_NE(section.find("x.ini: unknown section [CHolonomicVFHPlu] (known: navigator, "
                           "global_planner, replan,"),
              std::string::npos)
        << section;
    // A holonomic method MRPT does not know, or no section for MRPT's navigator: named here,
    // before a run (MRPT would stop it with a stack trace).
    auto c = shippedNavIni();
    c.write("navigator", "holonomic_method", "CHolonomicVHF");
    EXPECT_EQ(navError(c),
              "x.ini [navigator] holonomic_method: unknown holonomic method 'CHolonomicVHF' "
              "(known: CHolonomicVFHPlus, CHolonomicND, CHolonomicFullEval, CHolonomicVFF)");
    c.write("navigator", "holonomic_method", "CHolonomicND");
    EXPECT_EQ(navError(c), "");
    EXPECT_EQ(navError(mrpt::config::CConfigFileMemory("[navigator]\nnav_period = 0.1\n")),
              "x.ini: no [CAbstractPTGBasedReactive] section (MRPT's navigator needs it; see "
              "config_ini/nav_reactive.ini)");
}

// Every key of [global_planner] and [replan]: read back into its own field, at full precision.
TEST(GridPlanner, EveryKeyRoundTrips) {
    devslam::test::expectEveryKeyRoundTrips(
        [](const devslam::test::Ini& in, devslam::test::Ini& out) {
            GridPlannerOptions o;
            o.loadFromConfigFile(in, "global_planner");
            o.saveToConfigFile(out, "global_planner");
        });
}

TEST(Replan, EveryKeyRoundTrips) {
    devslam::test::expectEveryKeyRoundTrips(
        [](const devslam::test::Ini& in, devslam::test::Ini& out) {
            ReplanOptions o;
            o.loadFromConfigFile(in, "replan");
            o.saveToConfigFile(out, "replan");
        });
}
