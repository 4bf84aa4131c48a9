// Planning on a map file as devslam-run writes it (map_grid.gridmap): load, plan, picture,
// and the errors of a missing, foreign or cut file and of a goal in a wall.
#include <devslam/nav/MapPlan.h>

#include <gtest/gtest.h>

#include <mrpt/io/CFileGZOutputStream.h>
#include <mrpt/serialization/CArchive.h>
#include "Command.h"
#include "Scratch.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

namespace fs = std::filesystem;
using namespace devslam::nav;

namespace {
/// A 6 x 4 m room around the origin (x -1..5, y -2..2), every cell known and free, with a
/// wall across it at x = 2 that leaves a door at y 1.0..1.8; a band of unknown cells at
/// x 3.5..4 (a part of the room the camera did not see).
mrpt::maps::COccupancyGridMap2D room() {
    mrpt::maps::COccupancyGridMap2D g;
    g.setSize(-1, 5, -2, 2, 0.05f, 1.0f);
    for (int y = 0; y < int(g.getSizeY()); ++y)
        for (int x = 0; x < int(g.getSizeX()); ++x) {
            const double cx = g.idx2x(x), cy = g.idx2y(y);
            if (std::abs(cx - 2.0) < 0.1 && !(cy > 1.0 && cy < 1.8)) g.setCell(x, y, 0.0f);
            if (cx > 3.5 && cx < 4.0) g.setCell(x, y, 0.5f);
        }
    return g;
}

void save(const mrpt::maps::COccupancyGridMap2D& g, const std::string& path) {
    mrpt::io::CFileGZOutputStream f(path);
    auto arch = mrpt::serialization::archiveFrom(f);
    arch << g;
}

template <class F>
std::string errorOf(F&& f) {
    try {
        f();
    } catch (const std::exception& e) {
        return e.what();
    }
    return "(no error)";
}
}  // namespace

TEST(MapPlan, RouteThroughTheDoorOfASavedMap) {
    devslam::test::TempDir d("devslam_map_plan");
    const std::string file = d.str("room.gridmap");
    save(room(), file);
    const auto grid = loadGridMap(file);
    EXPECT_EQ(grid.getSizeX(), room().getSizeX());
    GridPlannerOptions o;  // robot radius 0.25 m, inflation 0.1 m
    const auto plan = planOnMap(grid, {0, 0}, {4.5, 0}, o);
    ASSERT_TRUE(plan.path.has_value());
    // through the door (x = 2, y 1.0..1.8): longer than the straight 4.5 m, at most the
    // detour over the door's middle (0 -> (2, 1.4) -> 4.5 is 2.44 + 2.86 m) plus grid slack
    EXPECT_GT(plan.path->length, 5.0);
    EXPECT_LT(plan.path->length, 5.9);
    bool through_door = false;
    for (const auto& q : plan.path->points)
        if (std::abs(q.x - 2.0) < 0.05) through_door = q.y > 1.0 && q.y < 1.8;
    EXPECT_TRUE(through_door);
    ASSERT_FALSE(plan.waypoints.empty());
    EXPECT_NEAR(plan.waypoints.back().x, 4.5, 0.05);
    EXPECT_NEAR(plan.waypoints.back().y, 0.0, 0.05);
    EXPECT_GE(plan.min_clearance, o.robot_radius);
    // the unknown band (0.5 m of a path crossing it about straight) is counted
    EXPECT_GT(plan.unknown_fraction, 0.05);
    EXPECT_LT(plan.unknown_fraction, 0.2);

    // Unknown counted as an obstacle: the band closes the room, no route.
    GridPlannerOptions strict = o;
    strict.occupied_threshold = 0.51;
    EXPECT_FALSE(planOnMap(grid, {0, 0}, {4.5, 0}, strict).path.has_value());

    const std::string png = d.str("plan.png");
    writeMapPlanPng(grid, plan, png, "room");
    EXPECT_GT(fs::file_size(png), 1000u);
}

TEST(MapPlan, BadFilesAndGoalsAreNamed) {
    devslam::test::TempDir d("devslam_map_plan_bad");
    const std::string file = d.str("room.gridmap");
    save(room(), file);
    const auto grid = loadGridMap(file);
    EXPECT_NE(errorOf([&] {
                  (void)planOnMap(grid, {0, 0}, {2.0, 0}, {});
              }).find("goal (2, 0) is inside an obstacle"),
              std::string::npos);
    EXPECT_NE(errorOf([&] {
                  (void)planOnMap(grid, {0, 0}, {9, 0}, {});
              }).find("goal (9, 0)"),
              std::string::npos);
    EXPECT_EQ(errorOf([&] { (void)loadGridMap(d.str("none.gridmap")); }),
              d.str("none.gridmap") + ": no such grid map file");
    std::filesystem::create_directory(d.str("folder.gridmap"));
    EXPECT_EQ(errorOf([&] { (void)loadGridMap(d.str("folder.gridmap")); }),
              d.str("folder.gridmap") + ": is a folder, not a grid map file");
    std::ofstream(d.str("text.gridmap")) << "not a grid";
    EXPECT_NE(errorOf([&] {
                  (void)loadGridMap(d.str("text.gridmap"));
              }).find("text.gridmap: not an MRPT occupancy grid"),
              std::string::npos);
    // Cut a few bytes short: MRPT would read the grid, the gzip trailer is what is missing.
    const auto size = fs::file_size(file);
    fs::resize_file(file, size - 4);
    EXPECT_NE(errorOf([&] { (void)loadGridMap(file); }).find("truncated or corrupt gzip stream"),
              std::string::npos);
}

// The app: devslam-nav --map prints the route and writes its picture; a bad goal fails.
TEST(MapPlan, DevslamNavPlansOnAMapFile) {
    devslam::test::TempDir d("devslam_nav_map");
    const std::string file = d.str("room.gridmap");
    save(room(), file);
    const auto run = [&](const std::string& args, std::string& out) {
        auto r = devslam::test::runApp("devslam-nav", args);
        out = std::move(r.out);
        return r.rc;
    };
    std::string out;
    EXPECT_EQ(run("--map " + file + " --to 4.5,0 --png " + d.str("p.png"), out), 0) << out;
    EXPECT_NE(out.find("result=path length="), std::string::npos) << out;
    EXPECT_NE(out.find("waypoint 4.50 0.00"), std::string::npos) << out;
    EXPECT_TRUE(fs::exists(d.str("p.png")));
    // A file-size limit under the picture, SIGXFSZ at its default (it killed the program,
    // leaving a cut q.png.part): the path, the error, no cut file.
    const auto cut = devslam::test::runAppWithFileLimit(
        "devslam-nav", "--map " + file + " --to 4.5,0 --png " + d.str("q.png"), 1000, false);
    EXPECT_EQ(cut.rc, 2) << cut.out;
    EXPECT_NE(cut.out.find("waypoint 4.50 0.00"), std::string::npos) << cut.out;
    EXPECT_NE(cut.out.find("cannot write '" + d.str("q.png") + "': File too large"),
              std::string::npos)
        << cut.out;
    EXPECT_FALSE(fs::exists(d.str("q.png")));
    EXPECT_FALSE(fs::exists(d.str("q.png.part")));
    EXPECT_EQ(run("--map " + file + " --from 0,0 --to 2,0", out), 2) << out;
    EXPECT_NE(out.find("goal (2, 0) is inside an obstacle"), std::string::npos) << out;
    EXPECT_NE(out.find("devslam-nav: " + file + ", --from 0,0 --to 2,0: global planner: "),
              std::string::npos)
        << out;  // the options and the file named, not only the planner's "goal"
    EXPECT_EQ(run("--map " + file, out), 2) << out;
    EXPECT_NE(out.find("--map needs --to X,Y"), std::string::npos) << out;
    // A map without an obstacle: its clearance is "none", not the planner's placeholder
    // (min_clearance=1000000.000 m).
    mrpt::maps::COccupancyGridMap2D open;
    open.setSize(-1, 5, -1, 1, 0.05f, 1.0f);
    save(open, d.str("open.gridmap"));
    EXPECT_EQ(run("--map " + d.str("open.gridmap") + " --to 4,0 --png " + d.str("o.png"), out), 0)
        << out;
    EXPECT_NE(out.find(" min_clearance=none "), std::string::npos) << out;
    // More cells than the planner takes (1e8): refused when read, naming the file (30000 x
    // 30000 cells took 9.7 GB before std::bad_alloc).
    mrpt::maps::COccupancyGridMap2D big;
    big.setSize(0, 10001 * 0.05f, 0, 10000 * 0.05f, 0.05f, 0.5f);
    ASSERT_GT(double(big.getSizeX()) * big.getSizeY(), 1e8);
    save(big, d.str("big.gridmap"));
    EXPECT_EQ(run("--map " + d.str("big.gridmap") + " --to 1,1", out), 2) << out;
    EXPECT_NE(out.find(d.str("big.gridmap") + ": the grid map has "), std::string::npos) << out;
    EXPECT_NE(out.find(" cells, more than the planner takes (1e8)"), std::string::npos) << out;
}
