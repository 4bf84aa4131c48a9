#pragma once
/// World files for the simulator (sim_worlds/*.ini): bounds, robot, goal, laser, static
/// obstacles (walls, boxes, wooden blocks, cylinders) and pedestrians. See docs/sim.md for
/// the format. Loading validates everything and names file, section and key in errors; a
/// goal that lies inside (or closer than the robot radius to) an obstacle is rejected.
///
/// Usage:
///   devslam::sim::WorldSpec w = devslam::sim::loadWorld("sim_worlds/paper_fig6.ini");
///   mrpt::maps::COccupancyGridMap2D grid = devslam::sim::rasterize(w);
#include <mrpt/maps/COccupancyGridMap2D.h>
#include <mrpt/math/TPoint2D.h>
#include <mrpt/math/TPose2D.h>

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

namespace mrpt::config {
class CConfigFileBase;
}

namespace devslam::sim {

/// A static obstacle: an oriented box or a vertical cylinder.
struct Obstacle {
    enum class Shape { Box, Cylinder };
    std::string name;
    std::string kind = "box";  ///< box | block | wall | cylinder (drawing and statistics)
    Shape shape = Shape::Box;
    double cx = 0, cy = 0;  ///< [m] centre
    double sx = 1, sy = 1;  ///< [m] box size along its own x and y
    double yaw = 0;         ///< [rad] box orientation
    double radius = 0.2;    ///< [m] cylinder radius
    double height = 1.0;    ///< [m]
};

struct Pedestrian {
    enum class Mode { Scripted, RandomWalk };
    std::string name;
    Mode mode = Mode::Scripted;
    double speed = 1.0;                      ///< [m/s]
    double radius = 0.25;                    ///< [m] body radius
    std::vector<mrpt::math::TPoint2D> path;  ///< [m] scripted: walked back and forth;
                                             ///< random: path[0] is the start
    double start_delay = 0.0;                ///< [s] stands still before walking
};

struct RobotSpec {
    mrpt::math::TPose2D start{0, 0, 0};  ///< [m, m, rad]
    double radius = 0.25;                ///< [m] cylinder radius
    double max_v = 0.6;                  ///< [m/s]
    double max_w = M_PI / 2;             ///< [rad/s] (90 deg/s)
    double max_acc = 1.0;                ///< [m/s^2]
    double max_ang_acc = 3.0;            ///< [rad/s^2]
};

struct LaserSpec {
    double range = 6.0;                 ///< [m] maximum range
    int rays = 181;                     ///< number of rays over the field of view
    double fov = 2 * 3.14159265358979;  ///< [rad] field of view, centred ahead
    double noise_std = 0.01;            ///< [m] Gaussian range noise
    double rate = 10.0;                 ///< [Hz] scan rate
    double height = 0.3;                ///< [m] scan plane height
    bool detect_people = true;          ///< rays hit pedestrians
};

struct WorldSpec {
    std::string name = "world";
    std::string source = "<memory>";                      ///< file it came from (for messages)
    double x_min = 0, x_max = 10, y_min = 0, y_max = 10;  ///< [m] bounds
    bool boundary_walls = true;     ///< add 0.1 m walls just inside the bounds
    double grid_resolution = 0.05;  ///< [m] occupancy grid cell for the planner
    double time_step = 0.01;        ///< [s] physics step
    double timeout = 60.0;          ///< [s] simulated time limit of one run
    uint32_t seed = 1;              ///< noise and random walks
    bool pedestrians_yield = true;  ///< people pause when the robot is right ahead of them
    mrpt::math::TPoint2D goal{1, 1};
    double goal_tolerance = 0.3;  ///< [m]
    RobotSpec robot;
    LaserSpec laser;
    std::vector<Obstacle> obstacles;
    std::vector<Pedestrian> pedestrians;
};

/// Loads and validates a world file. Throws std::invalid_argument / std::runtime_error with
/// "<file> [section] key: problem" messages.
[[nodiscard]] WorldSpec loadWorld(const std::string& path);
/// Same from an already loaded INI (`source` used in messages).
[[nodiscard]] WorldSpec parseWorld(const mrpt::config::CConfigFileBase& cfg,
                                   const std::string& source);
/// Checks bounds, sizes, and that start and goal are free; throws with `w.source`.
void validateWorld(const WorldSpec& w);

/// The static obstacles (incl. boundary walls) as an occupancy grid (P(free): 1 free, 0 occupied).
[[nodiscard]] mrpt::maps::COccupancyGridMap2D rasterize(const WorldSpec& w);
/// All static obstacles including the boundary walls.
[[nodiscard]] std::vector<Obstacle> staticObstacles(const WorldSpec& w);
/// [m] distance from p to the surface of obstacle o (negative inside).
[[nodiscard]] double distanceToObstacle(const Obstacle& o, const mrpt::math::TPoint2D& p);
/// The obstacle whose surface is nearest p (the first of equals); nullptr when there is none.
[[nodiscard]] const Obstacle* nearestObstacle(const std::vector<Obstacle>& obstacles,
                                              const mrpt::math::TPoint2D& p);

}  // namespace devslam::sim
