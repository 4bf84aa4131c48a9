#include <devslam/sim/Episode.h>
#include <devslam/sim/SimRobot.h>
#include <devslam/sim/Simulator.h>

#include <devslam/core/Config.h>
#include <devslam/core/Picture.h>
#include <devslam/nav/GridPlanner.h>
#include <devslam/nav/RoutePicture.h>

#include <mrpt/core/Clock.h>
#include <mrpt/core/bits_math.h>
#include <mrpt/nav/reactive/CAbstractPTGBasedReactive.h>
#include <mrpt/nav/reactive/CReactiveNavigationSystem.h>

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace devslam::sim {

namespace {
constexpr double kClockEpoch = 1.7e9;  // [s] simulated clock origin (0 is INVALID_TIMESTAMP)

/// Switches mrpt::Clock to simulated time for its lifetime.
class SimulatedClock {
  public:
    SimulatedClock() : previous_(mrpt::Clock::getActiveClock()) {
        mrpt::Clock::setSimulatedTime(mrpt::Clock::fromDouble(kClockEpoch));
        mrpt::Clock::setActiveClock(mrpt::Clock::Simulated);
    }
    ~SimulatedClock() { mrpt::Clock::setActiveClock(previous_); }
    void set(double t) { mrpt::Clock::setSimulatedTime(mrpt::Clock::fromDouble(kClockEpoch + t)); }
    SimulatedClock(const SimulatedClock&) = delete;
    SimulatedClock& operator=(const SimulatedClock&) = delete;

  private:
    mrpt::Clock::Source previous_;
};

/// Why a run that timed out never left its start, "" when it did (moved more than 2 cm).
/// MRPT's navigator does not drive off a start within its secure distance of an obstacle
/// (`secure_distance_start` x `ref_distance` of free path: 12.5 cm with the shipped INI,
/// which stopped a robot whose edge started 1-6 cm from a wall, docs/sim.md). The world
/// check cannot refuse such a start, as it does not see the navigation INI; before this the
/// run only said "not at the goal". `sent_none`: MRPT sent no motion command in the whole
/// run (known with the speed guard on, which counts them), as when a score formula gave every
/// motion inf or NaN.
std::string standingReason(double farthest, const mrpt::math::TPoint2D& start, double radius,
                           const std::vector<Obstacle>& statics, double secure, bool sent_none) {
    if (farthest > 0.02) return "";
    std::ostringstream why;
    why.precision(2);
    why << std::fixed << ": the robot never left its start (it moved " << farthest * 100 << " cm)";
    const Obstacle* nearest = nearestObstacle(statics, start);
    const double edge = nearest ? distanceToObstacle(*nearest, start) - radius : 0;  // [m]
    if (nearest && edge < secure)
        why << "; its edge starts " << edge * 100 << " cm from obstacle '" << nearest->name
            << "', less than the navigator's secure distance (secure_distance_start x "
               "ref_distance = "
            << secure * 100 << " cm of free path to move): start it farther away";
    else if (sent_none)
        why << "; MRPT's navigator sent no motion command: none of its candidate motions "
               "scored as usable (its INI's score formulas?), and --verbose prints its reason "
               "at each step";
    return why.str();
}
}  // namespace

const char* toString(Outcome o) {
    switch (o) {
        case Outcome::Success:
            return "success";
        case Outcome::Collision:
            return "collision";
        case Outcome::Timeout:
            return "timeout";
        case Outcome::NoPath:
            return "no_path";
        case Outcome::Error:
            return "error";
        case Outcome::Interrupted:
            return "interrupted";
    }
    return "?";
}

EpisodeResult runEpisode(const WorldSpec& world, const mrpt::config::CConfigFileBase& nav_ini,
                         nav::NavigatorOptions nav_opts, const EpisodeOptions& opts) {
    SimulatedClock clock;
    EpisodeResult res;
    nav_opts.robot_radius = world.robot.radius;
    nav_opts.planner.robot_radius = world.robot.radius;
    nav_opts.guard.max_acc = world.robot.max_acc;
    nav_opts.guard.max_ang_acc = world.robot.max_ang_acc;
    if (!opts.holonomic_method.empty()) nav_opts.holonomic_method = opts.holonomic_method;

    Simulator sim(world);
    SimRobot robot(sim, nav_opts.person_margin, nav_opts.person_predict_horizon);
    const auto grid = rasterize(world);
    const auto statics = staticObstacles(world);
    {  // A band above the laser's plane (min_obstacles_height 0.5) left the robot blind: it
       // drove into the first wall, and nothing said why.
        const mrpt::nav::CReactiveNavigationSystem::TReactiveNavigatorParams d;
        const std::string s = "CReactiveNavigationSystem";
        const double lo = core::namingSource(nav_opts.source, [&] {
            return core::readDouble(nav_ini, s, "min_obstacles_height", d.min_obstacles_height);
        });
        const double hi = core::namingSource(nav_opts.source, [&] {
            return core::readDouble(nav_ini, s, "max_obstacles_height", d.max_obstacles_height);
        });
        // As SimRobot gives the points to MRPT: a float (0.3f is 0.30000001, above a band
        // that ends at 0.3, which passed as a double and left the robot blind).
        const double h = static_cast<float>(world.laser.height);
        if (!(h >= lo && h <= hi)) {
            std::ostringstream m;
            m << nav_opts.source << " [" << s << "] min_obstacles_height " << lo
              << " m, max_obstacles_height " << hi
              << " m: the band leaves out the laser's plane at " << world.laser.height << " m ("
              << (world.source.empty() ? world.name : world.source)
              << " [laser] height), so the robot would see no obstacle";
            throw std::invalid_argument(m.str());
        }
    }
    {  // MRPT commands up to the INI's speeds and predicts the robot's motion from them: a
       // slower robot is not the robot it navigates (the simulator scales such a command
       // down, keeping its arc, so the robot lags MRPT's predictions).
        const std::string s = "CAbstractPTGBasedReactive";
        const double v = core::namingSource(nav_opts.source, [&] {
            return core::readDouble(nav_ini, s, "robotMax_V_mps", 0.0, true);
        });
        const double w = core::namingSource(nav_opts.source, [&] {
            return core::readDouble(nav_ini, s, "robotMax_W_degps", 0.0, true);
        });
        const auto refuse = [&](const std::string& key, double have, const std::string& unit,
                                const std::string& ini_key, double ini) {
            std::ostringstream m;
            m << (world.source.empty() ? world.name : world.source) << " [robot] " << key << " "
              << have << unit << " is below " << nav_opts.source << " [" << s << "] " << ini_key
              << " " << ini
              << ": the navigator would command speeds the robot cannot reach; give them the "
                 "same value";
            throw std::invalid_argument(m.str());
        };
        if (world.robot.max_v < v * (1 - 1e-9))
            refuse("max_v", world.robot.max_v, " m/s", "robotMax_V_mps", v);
        if (world.robot.max_w < mrpt::DEG2RAD(w) * (1 - 1e-9))
            refuse("max_w_deg", mrpt::RAD2DEG(world.robot.max_w), " deg/s", "robotMax_W_degps", w);
    }
    nav::Navigator navigator(robot, nav_ini, nav_opts);
    if (opts.check_ptg_domains) res.ptg_domain_gaps = navigator.targetsNoPtgReaches();
    res.holonomic_method = navigator.holonomicMethod();
    // [m] the free path MRPT's navigator needs to move at all (its default where unset).
    const double secure =
        core::readDouble(nav_ini, "CAbstractPTGBasedReactive", "secure_distance_start",
                         mrpt::nav::CAbstractPTGBasedReactive::TAbstractPTGNavigatorParams()
                             .secure_distance_start) *
        navigator.refDistance();
    res.navlog = navigator.logPath();
    // Closed at every return: a navlog cut short is said, with the run.
    const auto closeLog = [&] { res.navlog_error = navigator.closeLog(); };
    bool started = false;
    try {
        started = navigator.start(grid, world.robot.start, world.goal, world.goal_tolerance);
    } catch (const nav::PlanningError& e) {  // a start or goal the planner cannot stand on
        res.outcome = Outcome::NoPath;
        res.reason = (world.source.empty() ? world.name : world.source) + ": " + e.what();
        closeLog();
        return res;
    }
    if (!started) {
        res.outcome = Outcome::NoPath;
        res.reason = navigator.lastError();
        closeLog();
        return res;
    }
    res.global_path = navigator.globalPath();
    res.astar_cells_length = res.global_path.length;
    {
        // any-angle reference: string-pull the cell path (no spacing limit)
        nav::GridPlanner ref(nav_opts.planner);
        ref.setMap(grid);
        auto pulled = nav::decimateWaypoints(ref, res.global_path, 1e9);
        pulled.insert(pulled.begin(), res.global_path.points.front());
        res.astar_length = nav::polylineLength(pulled);
    }
    res.waypoints = navigator.waypoints();
    res.pedestrian_tracks.resize(world.pedestrians.size());

    double next_nav = 0, next_rec = 0;
    auto prev = sim.robotPose();
    const auto start = prev;
    double farthest = 0;  // [m] from the start: a timeout standing there is said
    const double r = world.robot.radius;
    while (true) {
        const double t = sim.time();
        const auto p = sim.robotPose();
        res.path_length += std::hypot(p.x - prev.x, p.y - prev.y);
        farthest = std::max(farthest, std::hypot(p.x - start.x, p.y - start.y));
        prev = p;
        for (const auto& o : statics)
            res.min_clearance_static =
                std::min(res.min_clearance_static, distanceToObstacle(o, {p.x, p.y}) - r);
        const auto peds = sim.pedestrianPositions();
        for (size_t i = 0; i < peds.size(); i++)
            res.min_clearance_people =
                std::min(res.min_clearance_people, std::hypot(peds[i].x - p.x, peds[i].y - p.y) -
                                                       r - world.pedestrians[i].radius);
        if (t + 1e-9 >= next_rec) {
            res.trajectory.push_back(p);
            for (size_t i = 0; i < peds.size(); i++) res.pedestrian_tracks[i].push_back(peds[i]);
            next_rec += opts.record_period;
        }
        const auto& col = sim.collisions();
        if (col.static_events > 0 || col.person_events > 0) {
            res.outcome = Outcome::Collision;
            res.reason = col.static_events > 0 ? "touched a static obstacle" : "touched a person";
            break;
        }
        if (std::hypot(p.x - world.goal.x, p.y - world.goal.y) <= world.goal_tolerance) {
            res.outcome = Outcome::Success;
            break;
        }
        if (t >= world.timeout) {
            res.outcome = Outcome::Timeout;
            std::ostringstream why;  // "60 s", not to_string's "60.000000 s"
            why << "not at the goal after " << world.timeout << " s"
                << standingReason(farthest, {start.x, start.y}, r, statics, secure,
                                  nav_opts.guard.enabled && navigator.guardStats().commands == 0);
            res.reason = why.str();
            break;
        }
        if (t + 1e-9 >= next_nav) {
            clock.set(t);
            const auto st = navigator.step(t);
            res.step_seconds.push_back(navigator.lastStepSeconds());
            next_nav += nav_opts.nav_period;
            if (st == nav::NavState::Error) {
                res.outcome = Outcome::Error;  // (was counted as a timeout)
                res.reason = "navigator error: " + navigator.lastError();
                break;
            }
            if (opts.on_step) opts.on_step(t, std::hypot(p.x - world.goal.x, p.y - world.goal.y));
            if (opts.stop && opts.stop()) {
                res.outcome = Outcome::Interrupted;
                std::ostringstream why;
                why << "interrupted at t = " << t << " s";
                res.reason = why.str();
                break;
            }
        }
        sim.step();
        clock.set(sim.time());
    }
    res.time = sim.time();
    res.static_collisions = sim.collisions().static_events;
    res.person_collisions = sim.collisions().person_events;
    res.replans = navigator.replanCount();
    res.guard = navigator.guardStats();
    res.trajectory.push_back(sim.robotPose());
    closeLog();
    return res;
}

void writeEpisodePng(const WorldSpec& w, const EpisodeResult& r, const std::string& path,
                     const std::string& title) {
    // 20-100 px per metre, and at most 4000 px across (a 5 km world made a 30 GB picture).
    const double longest = std::max(w.x_max - w.x_min, w.y_max - w.y_min);
    const double ppm = std::min(std::clamp(1000.0 / longest, 20.0, 100.0), 4000.0 / longest);
    const int W = static_cast<int>(std::ceil((w.x_max - w.x_min) * ppm));
    const int H = static_cast<int>(std::ceil((w.y_max - w.y_min) * ppm)) + nav::kTitleBandHeight;
    cv::Mat img(H, W, CV_8UC3, cv::Scalar(255, 255, 255));
    const nav::ToPixel px = [&](const mrpt::math::TPoint2D& q) {
        return cv::Point(static_cast<int>(std::lround((q.x - w.x_min) * ppm)),
                         H - 1 - static_cast<int>(std::lround((q.y - w.y_min) * ppm)));
    };
    nav::drawMetreGrid(img, px, w.x_min, w.x_max, w.y_min, w.y_max, cv::Scalar(235, 235, 235));
    for (const auto& o : staticObstacles(w)) {
        cv::Scalar colour = o.kind == "block"  ? cv::Scalar(60, 120, 180)  // wood (BGR)
                            : o.kind == "wall" ? cv::Scalar(70, 70, 70)
                                               : cv::Scalar(110, 110, 140);
        if (o.shape == Obstacle::Shape::Cylinder) {
            cv::circle(img, px({o.cx, o.cy}), static_cast<int>(o.radius * ppm), colour, cv::FILLED,
                       cv::LINE_AA);
            continue;
        }
        std::vector<cv::Point> poly;
        const double c = std::cos(o.yaw), s = std::sin(o.yaw);
        for (auto [u, v] : {std::pair{-1, -1}, {1, -1}, {1, 1}, {-1, 1}}) {
            const double lx = u * o.sx / 2, ly = v * o.sy / 2;
            poly.push_back(px({o.cx + c * lx - s * ly, o.cy + s * lx + c * ly}));
        }
        cv::fillConvexPoly(img, poly, colour, cv::LINE_AA);
    }
    auto polyline = [&](const std::vector<cv::Point>& pts, const cv::Scalar& col, int th) {
        if (pts.size() >= 2) cv::polylines(img, pts, false, col, th, cv::LINE_AA);
    };
    // pedestrians' tracks (orange) with their final position
    for (size_t i = 0; i < r.pedestrian_tracks.size(); i++) {
        std::vector<cv::Point> pts;
        for (const auto& q : r.pedestrian_tracks[i]) pts.push_back(px({q.x, q.y}));
        polyline(pts, cv::Scalar(0, 140, 255), 2);
        if (!pts.empty())
            cv::circle(img, pts.back(), static_cast<int>(w.pedestrians[i].radius * ppm),
                       cv::Scalar(0, 140, 255), 2, cv::LINE_AA);
    }
    nav::drawRoute(img, px, r.global_path.points, r.waypoints);
    // driven trajectory (red) and robot footprints every 2 s
    std::vector<cv::Point> tp;
    for (const auto& q : r.trajectory) tp.push_back(px({q.x, q.y}));
    polyline(tp, cv::Scalar(30, 30, 220), 2);
    for (size_t i = 0; i < r.trajectory.size(); i += 20)
        cv::circle(img, tp[i], static_cast<int>(w.robot.radius * ppm), cv::Scalar(120, 120, 230), 1,
                   cv::LINE_AA);
    nav::drawStartGoal(img, px, {w.robot.start.x, w.robot.start.y}, {w.goal.x, w.goal.y});
    cv::circle(img, px({w.goal.x, w.goal.y}), static_cast<int>(w.goal_tolerance * ppm),
               cv::Scalar(0, 0, 210), 1, cv::LINE_AA);
    std::ostringstream os;
    os.precision(3);
    os << title << ": " << toString(r.outcome) << ", " << r.time << " s, path " << r.path_length
       << " m (A* " << r.astar_length << " m)";
    nav::drawTitleBand(
        img, os.str(),
        "blue: A* + waypoints   red: robot   orange: people   green: start   star: goal");
    core::writePngWhole(path, img);
}

}  // namespace devslam::sim
