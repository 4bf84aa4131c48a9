#pragma once
/// Global + local navigation glue: A* on the map, waypoints within the PTG reference
/// distance handed to MRPT's CReactiveNavigationSystem (whose holonomic method is chosen by
/// name, e.g. CHolonomicVFHPlus), and replanning when the path is blocked or VFH+ keeps
/// seeing a dense sector toward its target.
///
///   robot (CRobot2NavInterface) <── CReactiveNavigationSystem <── waypoints <── GridPlanner
///                 │ senseObstacles()                                    ▲ replan (ReplanTrigger)
///                 └──────────────────────────────────────────────────────┘
///
/// Usage:
///   devslam::nav::Navigator nav(robot, navIni, NavigatorOptions::fromConfig(navIni));
///   nav.start(map, startPose, goal, 0.3);          // throws PlanningError on a bad start/goal
///   while (...) { nav.step(t); simulate(dt); }    // step at options.nav_period (simulated time)
/// Not thread-safe. Time comes from mrpt::Clock (set it to Simulated in a simulator).
#include <devslam/nav/GridPlanner.h>
#include <devslam/nav/Replan.h>
#include <devslam/nav/SpeedGuard.h>

#include <mrpt/config/CConfigFileMemory.h>
#include <mrpt/math/TPose2D.h>
#include <mrpt/nav/reactive/CRobot2NavInterface.h>

#include <memory>
#include <optional>
#include <string>

namespace mrpt::nav {
class CReactiveNavigationSystem;
}

namespace devslam::nav {

/// The largest [navigator] person_margin [m] and person_predict_horizon [s] taken, by the INI
/// and devslam-nav-bench's overrides alike.
inline constexpr double kMaxPersonMargin = 2.0, kMaxPersonPredictHorizon = 5.0;

/// INI section [navigator] plus the planner ([global_planner]) and replanning ([replan]).
struct NavigatorOptions {
    double nav_period = 0.1;                 ///< [s] period of navigationStep()
    double waypoint_allowed_distance = 0.5;  ///< [m] intermediate waypoint reached radius
    std::string holonomic_method = "CHolonomicVFHPlus";  ///< overrides the INI's choice
    double robot_radius = 0.25;  ///< [m] circle used for the PTG robot polygon (16 sides)
    /// [m] extra room kept from people: the robot interface surrounds each sensed point it
    /// knows to be on a person with a ring of points this far out (SimRobot; 0 = off).
    double person_margin = 0.10;
    /// [s] how far ahead walkers' paths are sensed as obstacles: the robot interface tracks
    /// the people it sees and reports each moving one's points along its velocity that far
    /// (PeopleTracker.h; SimRobot; 0 = off).
    double person_predict_horizon = 1.0;
    bool log_file = false;  ///< write an MRPT .reactivenavlog
    std::string log_directory = "reactivenav.logs";
    std::string ptg_cache_directory = "";  ///< "" = a folder in the system temp dir
    bool verbose = false;  ///< MRPT navigator log level INFO instead of ERROR (not in INI)
    /// The INI these options and MRPT's sections came from, for messages (fromConfig sets it).
    std::string source = "the navigation INI";
    /// [navigator] speed_guard, max_acc, max_ang_acc_deg, guard_margin: the robot's
    /// acceleration limits, which MRPT's PTGs ignore (SpeedGuard.h; the simulator sets them
    /// from the world's [robot]).
    SpeedGuardOptions guard;
    GridPlannerOptions planner;
    ReplanOptions replan;

    /// Reads [navigator], [global_planner] and [replan] from `cfg` (unknown keys rejected).
    [[nodiscard]] static NavigatorOptions fromConfig(const mrpt::config::CConfigFileBase& cfg,
                                                     const std::string& source = "INI");
};

/// [m] MRPT's TP-Space distance, [CAbstractPTGBasedReactive] ref_distance of a navigation
/// INI (required): its PTGs see no farther.
[[nodiscard]] double refDistanceOf(const mrpt::config::CConfigFileBase& nav_ini);
/// Throws std::invalid_argument("OPTION: must be in (0, 5] m/s") unless 0 < v <=
/// kMaxRobotSpeed (the world files' own bound): the check of `--max-speed` in both apps.
void requireTopSpeed(double v, const std::string& option = "--max-speed");

/// Sets a navigation INI's top speed to `v` [m/s] (in (0, kMaxRobotSpeed]): MRPT's
/// robotMax_V_mps, and each PTG's v_max_mps that was the old top speed. A PTG slower on purpose
/// (the shipped PTG3, 0.3 m/s for its tight turns behind the robot) keeps its speed: raised, its
/// turns widened and left targets near the robot in no PTG's domain. `--max-speed` of
/// devslam-nav and devslam-nav-bench; throws std::invalid_argument naming `option` for a bad v.
void setTopSpeed(mrpt::config::CConfigFileBase& nav_ini, double v,
                 const std::string& option = "--max-speed");

/// [m] the spacing of the waypoints the navigator gets: `waypoint_spacing`, at most
/// 0.9 x `ref_distance` (a waypoint beyond the PTGs' reach cannot be aimed at).
[[nodiscard]] double waypointSpacing(double waypoint_spacing, double ref_distance);

/// The distances Navigator::targetsNoPtgReaches() looks at [m]: from the goal tolerance of the
/// shipped worlds out to where PTG0 and PTG2 reach every bearing.
inline constexpr double kPtgGapMinDistance = 0.30, kPtgGapMaxDistance = 1.20;

/// "N targets 0.30-1.20 m from the robot (every 5 cm and degree) lie in no PTG's domain, the
/// first D m away at B deg; MRPT stops when its target is there (...)": the warning the apps
/// give for Navigator::targetsNoPtgReaches()'s result (not empty).
[[nodiscard]] std::string describePtgDomainGaps(const std::vector<std::pair<double, int>>& gaps);

/// Outcome of one step.
enum class NavState { Idle, Navigating, GoalReached, Error };
[[nodiscard]] const char* toString(NavState s);

class Navigator {
  public:
    /// `nav_ini` holds MRPT's reactive sections ([CAbstractPTGBasedReactive], PTGs, the
    /// holonomic methods); robot shape, ref distance and method are set from `opts`.
    Navigator(mrpt::nav::CRobot2NavInterface& robot, const mrpt::config::CConfigFileBase& nav_ini,
              NavigatorOptions opts);
    ~Navigator();
    Navigator(const Navigator&) = delete;
    Navigator& operator=(const Navigator&) = delete;

    /// Plans on `map` and starts the reactive navigator. Throws PlanningError for a bad
    /// start/goal; returns false (and stays Idle) when no path exists.
    [[nodiscard]] bool start(const mrpt::maps::COccupancyGridMap2D& map,
                             const mrpt::math::TPose2D& start, const mrpt::math::TPoint2D& goal,
                             double goal_tolerance);
    /// One navigation step at time t [s]; call every nav_period.
    NavState step(double t);

    [[nodiscard]] const GridPath& globalPath() const { return first_path_; }
    [[nodiscard]] const std::vector<mrpt::math::TPoint2D>& waypoints() const { return waypoints_; }
    [[nodiscard]] int replanCount() const { return replans_; }
    /// Thread CPU time [s] of the last navigationStep() (independent of machine load).
    [[nodiscard]] double lastStepSeconds() const { return last_step_s_; }
    [[nodiscard]] std::string lastError() const { return last_error_; }
    [[nodiscard]] double refDistance() const { return ref_distance_; }
    /// The class of the holonomic method MRPT's navigator made (e.g. "CHolonomicVFHPlus").
    [[nodiscard]] std::string holonomicMethod() const;
    [[nodiscard]] mrpt::nav::CReactiveNavigationSystem& reactive();
    /// What the speed guard did so far (commands all 0 with the guard off).
    [[nodiscard]] const SpeedGuardStats& guardStats() const { return guarded_->stats(); }
    /// Targets kPtgGapMinDistance..kPtgGapMaxDistance m from the robot (every 5 cm, every
    /// degree of bearing) that no PTG reaches (inverseMap_WS2TP false for all), as (distance
    /// [m], bearing [deg]). MRPT's navigator cannot aim at such a target: it stops ("no way
    /// found") until it moves. The shipped INI has none; other speed limits can.
    [[nodiscard]] std::vector<std::pair<double, int>> targetsNoPtgReaches();
    /// The navlog being written (NavigatorOptions::log_file), "" when none is.
    [[nodiscard]] const std::string& logPath() const { return log_path_; }
    /// Closes the navlog and returns what went wrong writing it ("cannot write navlog
    /// 'PATH': No space left on device; ..."), "" when nothing did or none is written. A write
    /// that fails during the run ends the log there and the robot drives on (MRPT writes it
    /// inside navigationStep(), whose error handler stopped the robot at every step).
    std::string closeLog();

  private:
    bool replan(const mrpt::math::TPose2D& pose, const std::vector<mrpt::math::TPoint2D>& sensed);
    /// The current path and its waypoints, decimated on the map planner_ holds.
    void setPath(const GridPath& p);
    /// Sends waypoints_ from index `first` on (the last one at least) to MRPT.
    void sendWaypoints(std::size_t first);
    /// Throws std::invalid_argument naming the PTG when one of its paths ends under 1 m along.
    void requirePathsOfOneMetre(const mrpt::config::CConfigFileBase& cfg) const;
    mrpt::nav::CRobot2NavInterface& robot_;
    NavigatorOptions opts_;
    std::unique_ptr<GuardedRobot> guarded_;  ///< what nav_ drives: robot_ through the guard
    std::unique_ptr<mrpt::nav::CReactiveNavigationSystem> nav_;
    class NavlogStream;
    NavlogStream* navlog_ = nullptr;  ///< owned by nav_ (its log stream); null when none
    std::string log_path_;
    GridPlanner planner_;
    mrpt::maps::COccupancyGridMap2D static_map_;
    ReplanTrigger trigger_;
    GridPath first_path_, path_;
    std::size_t path_segment_ = 0;  ///< the robot's progress along path_ (pathProgress)
    std::vector<mrpt::math::TPoint2D> waypoints_;
    std::vector<std::size_t> waypoint_path_index_;  ///< each waypoint's index in path_.points
    mrpt::math::TPoint2D goal_;
    double goal_tolerance_ = 0.3;
    double ref_distance_ = 2.0;
    int replans_ = 0;
    double last_step_s_ = 0;
    bool active_ = false;
    std::string last_error_;
};

}  // namespace devslam::nav
