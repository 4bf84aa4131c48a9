#pragma once
/// Global planner: 8-connected A* with an octile heuristic on an MRPT occupancy grid.
///
/// Obstacles (cells with P(free) < occupied_threshold) are inflated: cells closer than the
/// robot radius are lethal; cells closer than radius + margin are allowed only at a high
/// penalty (so a start or goal that sits close to an obstacle is still reachable); beyond
/// that a clearance cost keeps the path away from walls. The heuristic stays admissible
/// because every step costs at least its length.
///
/// Usage:
///   devslam::nav::GridPlanner planner(opts);
///   planner.setMap(grid);                                   // distance transform, once
///   auto path = planner.plan({0, 0}, {8, 3});               // std::nullopt: no path
///   auto wps = decimateWaypoints(planner, *path, 1.5);      // spacing within ref_distance
/// Not thread-safe.
#include <mrpt/config/CConfigFileBase.h>
#include <mrpt/maps/COccupancyGridMap2D.h>
#include <mrpt/math/TPoint2D.h>

#include <cstddef>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace devslam::nav {

/// The most cells a grid the planner takes may have: it keeps several numbers per cell, and
/// MRPT counts a grid's cells in 32 bits (a world's bounds and a --map file alike).
inline constexpr double kMaxGridCells = 1e8;

/// Parameters of the grid A* (INI section [global_planner]).
struct GridPlannerOptions {
    double robot_radius = 0.25;        ///< [m] cells closer than this to an obstacle are lethal
    double inflation_margin = 0.10;    ///< [m] extra inflation, traversable at a penalty
    double inflation_penalty = 20.0;   ///< [-] cost multiplier inside the margin band
    double clearance_distance = 0.50;  ///< [m] beyond radius+margin, below this a cost applies
    double clearance_weight = 2.0;     ///< [-] cost multiplier at the band edge (decays ^2)
    double occupied_threshold = 0.5;   ///< [P(free)] cells below are obstacles
    double waypoint_spacing = 1.5;     ///< [m] max distance between waypoints (< ref_distance)

    /// Reads the keys of `section`; rejects unknown keys (names the source).
    void loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg, const std::string& section,
                            const std::string& source = "INI");
    void saveToConfigFile(mrpt::config::CConfigFileBase& cfg, const std::string& section) const;
    /// Throws std::invalid_argument naming the bad field.
    void validate() const;
};

/// Why a start or goal point cannot be used.
enum class EndpointStatus { Ok, OutsideMap, InsideObstacle, TooCloseToObstacle };
[[nodiscard]] const char* toString(EndpointStatus s);

/// Thrown by plan() for an invalid start or goal; `what()` names the point and the reason.
class PlanningError : public std::invalid_argument {
  public:
    PlanningError(const std::string& msg, EndpointStatus status)
        : std::invalid_argument(msg), status_(status) {}
    [[nodiscard]] EndpointStatus status() const { return status_; }

  private:
    EndpointStatus status_;
};

/// A planned path: cell centres from start to goal (world coordinates).
struct GridPath {
    std::vector<mrpt::math::TPoint2D> points;  ///< [m] start ... goal
    double length = 0;                         ///< [m] geometric length
    double cost = 0;                           ///< [m-equivalent] A* cost
    std::size_t expanded = 0;                  ///< cells expanded by A*
};

class GridPlanner {
  public:
    explicit GridPlanner(GridPlannerOptions opts = {});
    /// Precomputes the obstacle distance transform of `grid` (copied).
    void setMap(const mrpt::maps::COccupancyGridMap2D& grid);
    [[nodiscard]] const GridPlannerOptions& options() const { return opts_; }
    [[nodiscard]] const mrpt::maps::COccupancyGridMap2D& map() const { return grid_; }

    /// Plans from start to goal. Throws PlanningError when start or goal is outside the
    /// map, inside an obstacle or closer than robot_radius to one; std::nullopt when the
    /// two are not connected.
    [[nodiscard]] std::optional<GridPath> plan(const mrpt::math::TPoint2D& start,
                                               const mrpt::math::TPoint2D& goal) const;

    /// Validation of one endpoint without planning.
    [[nodiscard]] EndpointStatus checkEndpoint(const mrpt::math::TPoint2D& p) const;
    /// [m] the clearance of p's cell: the distance from its centre to the nearest obstacle
    /// cell (0 inside an obstacle; a large value if the map has no obstacle), so up to 0.8
    /// cells more than p's own exact distance, or about 1.7 less (docs/nav.md); p must be
    /// inside the map.
    [[nodiscard]] double clearance(const mrpt::math::TPoint2D& p) const;
    /// The centre of the cell nearest to p (within `max_dist` [m] of it) that the robot may
    /// stand in (clearance >= robot_radius): where to plan from when the robot's own cell is
    /// too close to an obstacle on the grid, whose clearances are up to a cell and a half
    /// short of the true distance. p itself when its cell is fine; nullopt when none is near.
    [[nodiscard]] std::optional<mrpt::math::TPoint2D> nearestTraversable(
        const mrpt::math::TPoint2D& p, double max_dist) const;
    /// True when every cell on the segment a-b has at least `min_clearance` [m].
    [[nodiscard]] bool segmentClear(const mrpt::math::TPoint2D& a, const mrpt::math::TPoint2D& b,
                                    double min_clearance) const;

  private:
    [[nodiscard]] double stepMultiplier(int idx) const;
    GridPlannerOptions opts_;
    mrpt::maps::COccupancyGridMap2D grid_;
    std::vector<float> clearance_;  ///< [m] per cell, row-major (x + y*W)
    std::vector<float> mult_;       ///< step cost multiplier per cell, < 0 = lethal
    int w_ = 0, h_ = 0;
};

/// Keeps a subset of the path points: consecutive waypoints at most `max_spacing` [m]
/// apart and joined by straight segments whose clearance is no worse than the path's own
/// (never below robot_radius). The goal is always the last waypoint; the start is dropped.
[[nodiscard]] std::vector<mrpt::math::TPoint2D> decimateWaypoints(const GridPlanner& planner,
                                                                  const GridPath& path,
                                                                  double max_spacing);

/// decimateWaypoints()'s waypoints as indices into `path.points` (increasing).
[[nodiscard]] std::vector<std::size_t> decimateWaypointIndices(const GridPlanner& planner,
                                                               const GridPath& path,
                                                               double max_spacing);

/// Sum of segment lengths of a polyline [m].
[[nodiscard]] double polylineLength(const std::vector<mrpt::math::TPoint2D>& pts);

}  // namespace devslam::nav
