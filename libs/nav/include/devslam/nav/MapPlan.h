#pragma once
/// A route on a map the SLAM built: A* (GridPlanner) on the occupancy grid `devslam-run`
/// writes (`map_grid.gridmap`, the "nav" frame of the first keyframe: x forward, y left,
/// the camera's start at (0, 0)), its waypoints, and a picture of both.
///
/// The SLAM's grid is made from sparse landmarks, so much of it is unknown (P(free) = 0.5):
/// the planner treats unknown as free unless `occupied_threshold` is above 0.5, and the
/// result says how much of the route crosses unknown cells.
///
/// Usage:
///   auto grid = devslam::nav::loadGridMap("out/devslam-run/map_grid.gridmap");
///   auto plan = devslam::nav::planOnMap(grid, {0, 0}, {2.5, 1.0}, opts);
///   devslam::nav::writeMapPlanPng(grid, plan, "plan.png", "fr1_xyz_first37");
#include <devslam/nav/GridPlanner.h>

#include <mrpt/maps/COccupancyGridMap2D.h>
#include <mrpt/math/TPoint2D.h>

#include <optional>
#include <string>
#include <vector>

namespace devslam::nav {

/// Reads a `.gridmap` file (a gz MRPT archive holding one COccupancyGridMap2D). Throws
/// std::runtime_error naming the file when it is missing or holds no such grid.
[[nodiscard]] mrpt::maps::COccupancyGridMap2D loadGridMap(const std::string& path);

struct MapPlan {
    mrpt::math::TPoint2D from, to;
    std::optional<GridPath> path;                 ///< nullopt: the two are not connected
    /// Decimated at opts.waypoint_spacing; as the navigator gets them when that is
    /// nav::waypointSpacing(...) (devslam-nav --map passes it).
    std::vector<mrpt::math::TPoint2D> waypoints;
    double min_clearance = 0;                     ///< [m] smallest clearance along the path
    double unknown_fraction = 0;                  ///< of the path's cells with P(free) = 0.5
};

/// Plans from `from` to `to` on `grid`. Throws PlanningError (naming the point) when one of
/// them is outside the map, in an obstacle or closer to one than the robot radius.
[[nodiscard]] MapPlan planOnMap(const mrpt::maps::COccupancyGridMap2D& grid,
                                const mrpt::math::TPoint2D& from, const mrpt::math::TPoint2D& to,
                                const GridPlannerOptions& opts);

/// The grid (white free, black occupied, grey unknown), the A* path and waypoints (blue),
/// start (green) and goal (red), a 1 m grid and a title. Throws std::runtime_error when the
/// file cannot be written.
void writeMapPlanPng(const mrpt::maps::COccupancyGridMap2D& grid, const MapPlan& plan,
                     const std::string& path, const std::string& title);

}  // namespace devslam::nav
