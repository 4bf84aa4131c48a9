#pragma once
/// One closed-loop navigation run in the Bullet world: A* on the rasterized world, MRPT's
/// reactive navigator with the chosen holonomic method driving SimRobot, mrpt::Clock in
/// simulated time (so MRPT's timeouts follow simulated seconds), fixed physics step, and
/// the measures of the run. Also draws the run as a PNG (map, A* path, driven trajectory,
/// pedestrians' tracks), like Fig. 6 of the paper.
///
/// Usage:
///   auto world = devslam::sim::loadWorld("sim_worlds/paper_fig6.ini");
///   auto ini = devslam::core::loadIni("config_ini/nav_reactive.ini");
///   auto res = devslam::sim::runEpisode(world, *ini, navOpts, {});
///   devslam::sim::writeEpisodePng(world, res, "run.png", "VFH+");
#include <devslam/nav/GridPlanner.h>
#include <devslam/nav/Navigator.h>
#include <devslam/sim/World.h>

#include <functional>
#include <string>
#include <vector>

namespace devslam::sim {

struct EpisodeOptions {
    /// MRPT class name; empty: the navigator options' own ([navigator] holonomic_method)
    std::string holonomic_method;
    double record_period = 0.1;  ///< [s] trajectory / tracks sampling
    /// Called after each navigator step with the simulated time [s] and the robot's distance
    /// to the goal [m] (devslam-nav's progress line); empty: none.
    std::function<void(double t, double to_goal)> on_step;
    /// Asked after each navigator step: true ends the run there as Outcome::Interrupted, with
    /// what it did so far (devslam-nav's Ctrl-C); empty: never.
    std::function<bool()> stop;
    /// Also find the targets near the robot that no PTG reaches (EpisodeResult::ptg_domain_gaps;
    /// about 0.1 s: devslam-nav asks it of its run, the bench of one episode).
    bool check_ptg_domains = false;
};

/// NoPath: no global route at the start; Error: the navigator stopped on an error (the
/// robot did not report its pose); Interrupted: EpisodeOptions::stop ended it.
enum class Outcome { Success, Collision, Timeout, NoPath, Error, Interrupted };
[[nodiscard]] const char* toString(Outcome o);

struct EpisodeResult {
    Outcome outcome = Outcome::Timeout;
    std::string reason;       ///< human-readable detail
    double time = 0;          ///< [s] simulated time at the end
    double path_length = 0;   ///< [m] driven distance
    double astar_length = 0;  ///< [m] first global path after string pulling (line-of-sight
                              ///< shortcuts keeping the path's clearance): the reference length
    double astar_cells_length = 0;      ///< [m] the same path through cell centres (staircase)
    double min_clearance_static = 1e9;  ///< [m] robot edge to nearest static obstacle
    double min_clearance_people = 1e9;  ///< [m] robot edge to nearest person edge
    int static_collisions = 0;          ///< contact events with walls/boxes
    int person_collisions = 0;          ///< contact events with people
    int replans = 0;
    nav::SpeedGuardStats guard;        ///< what the speed guard did (nav::Navigator::guardStats)
    std::string holonomic_method;      ///< the class MRPT's navigator made
    std::vector<double> step_seconds;  ///< wall time of each navigationStep()
    std::vector<mrpt::math::TPose2D> trajectory;
    std::vector<std::vector<mrpt::math::TPoint2D>> pedestrian_tracks;
    nav::GridPath global_path;
    std::vector<mrpt::math::TPoint2D> waypoints;
    std::string navlog;        ///< the navlog written (NavigatorOptions::log_file), else ""
    std::string navlog_error;  ///< why the navlog is cut short (nav::Navigator::closeLog)
    /// With EpisodeOptions::check_ptg_domains: nav::Navigator::targetsNoPtgReaches()
    /// (distance [m], bearing [deg]), the targets 0.30-1.20 m away MRPT cannot aim at.
    std::vector<std::pair<double, int>> ptg_domain_gaps;
};

/// Runs one episode. Throws nav::PlanningError if start/goal are invalid for the planner.
[[nodiscard]] EpisodeResult runEpisode(const WorldSpec& world,
                                       const mrpt::config::CConfigFileBase& nav_ini,
                                       nav::NavigatorOptions nav_opts, const EpisodeOptions& opts);

/// Draws the world and the run; throws std::runtime_error if the file cannot be written.
void writeEpisodePng(const WorldSpec& world, const EpisodeResult& r, const std::string& path,
                     const std::string& title);

}  // namespace devslam::sim
