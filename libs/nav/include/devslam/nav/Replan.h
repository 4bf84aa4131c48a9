#pragma once
/// When should the global planner intervene? Two triggers (paper section 3.2):
///  - the remaining global path is blocked by a sensed obstacle (a person stepping in,
///    an obstacle missing from the map),
///  - VFH+ reports a high obstacle density toward its target for some time.
/// A minimum interval between replans prevents thrashing.
///
/// Usage:
///   ReplanTrigger trigger(opts);
///   if (auto r = trigger.update({t, blocked, density}); r != ReplanReason::None) replan();
#include <devslam/nav/GridPlanner.h>

#include <mrpt/config/CConfigFileBase.h>
#include <mrpt/maps/COccupancyGridMap2D.h>
#include <mrpt/math/TPoint2D.h>

#include <string>
#include <vector>

namespace devslam::nav {

/// INI section [replan].
struct ReplanOptions {
    double density_threshold = 0.6;    ///< [-] VFH+ primary density toward the target
    double density_time = 3.0;         ///< [s] the density must stay above for this long
    double min_interval = 2.0;         ///< [s] minimum time between two replans
    double blocked_lookahead = 2.0;    ///< [m] path length ahead checked for blockage
    double blocked_margin = 0.05;      ///< [m] added to the robot radius for the blocked check
    double obstacle_inflation = 0.30;  ///< [m] radius stamped around sensed points when replanning
    double sensed_range = 3.0;         ///< [m] sensed points farther than this are not stamped

    void loadFromConfigFile(const mrpt::config::CConfigFileBase& c, const std::string& s,
                            const std::string& source = "INI");
    void saveToConfigFile(mrpt::config::CConfigFileBase& c, const std::string& s) const;
};

enum class ReplanReason { None, PathBlocked, HighDensity };
[[nodiscard]] const char* toString(ReplanReason r);

struct ReplanInput {
    double t = 0;               ///< [s] current time
    bool path_blocked = false;  ///< from pathBlocked()
    double goal_density = 0;    ///< [-] VFH+ target_density (0 if unknown)
};

/// Small state machine over ReplanInput; not thread-safe.
class ReplanTrigger {
  public:
    explicit ReplanTrigger(ReplanOptions o = {}) : opts_(o) {}
    /// Returns the reason to replan now, or None. Records the replan time when not None.
    [[nodiscard]] ReplanReason update(const ReplanInput& in);
    void reset(double t);

  private:
    ReplanOptions opts_;
    double last_replan_ = -1e9;
    double dense_since_ = -1;  ///< time the density went above threshold, -1 if below
};

/// The robot's progress along `path`: the segment (i: path[i] -> path[i+1]) nearest `robot`
/// among those that begin within `window` [m] of path length before or after segment `from`
/// begins (the first of equally near ones). Called each step with the last result as `from`,
/// it follows the robot along the path, forward or pushed back, a window at a time: on a path
/// that folds back past the robot (round a pillar, into a room beside the corridor), the
/// nearest segment anywhere is one the robot has not reached, and the segments really ahead
/// of it would go unchecked. 0 for a path of fewer than 2 points.
[[nodiscard]] std::size_t pathProgress(const std::vector<mrpt::math::TPoint2D>& path,
                                       const mrpt::math::TPoint2D& robot, std::size_t from,
                                       double window);

/// The waypoint the robot heads for at progress `segment` (pathProgress()), given each
/// waypoint's index into the path (increasing, decimateWaypointIndices()): the first beyond
/// the segment's start, else the last; 0 when there is none. Nearest the robot anywhere would
/// be, on a path folding back past it, a waypoint on the way back, across what the path goes
/// round.
[[nodiscard]] std::size_t waypointAhead(const std::vector<std::size_t>& waypoint_path_index,
                                        std::size_t segment);

/// True when a point of `obstacles` (world frame) lies within `radius` [m] of the path
/// polyline, looking ahead `lookahead` [m] of path length from the start of segment
/// `segment` (pathProgress()).
[[nodiscard]] bool pathBlocked(const std::vector<mrpt::math::TPoint2D>& path, std::size_t segment,
                               const std::vector<mrpt::math::TPoint2D>& obstacles, double radius,
                               double lookahead);

/// The points of `sensed` (world frame) that the static map does not explain: farther than
/// one cell from its obstacles. The laser sees the walls the plan already keeps clear of; only
/// people and objects missing from the map block a path (pathBlocked).
/// `static_map` holds the static map (GridPlanner::setMap).
[[nodiscard]] std::vector<mrpt::math::TPoint2D> unmappedPoints(
    const GridPlanner& static_map, const std::vector<mrpt::math::TPoint2D>& sensed);

/// The map to replan on: `static_map` with a disc of `o.obstacle_inflation` stamped around
/// each point of `sensed` within `o.sensed_range` of `robot` (none closer than the robot's
/// own radius plus the disc plus 5 cm, nor on the goal). The cells around `robot` and `goal`
/// keep their static values, so that a disc never takes the planner's clearance there below
/// `robot_radius`: the plan then starts and ends where the robot and goal are, instead of
/// failing and falling back to the static map without the sensed obstacles.
[[nodiscard]] mrpt::maps::COccupancyGridMap2D stampSensedObstacles(
    const mrpt::maps::COccupancyGridMap2D& static_map, const mrpt::math::TPoint2D& robot,
    const mrpt::math::TPoint2D& goal, const std::vector<mrpt::math::TPoint2D>& sensed,
    double robot_radius, const ReplanOptions& o);

}  // namespace devslam::nav
