#include <devslam/core/Config.h>
#include <devslam/core/Parse.h>
#include <devslam/nav/GridPlanner.h>
#include <devslam/nav/SpeedGuard.h>
#include <devslam/sim/World.h>

#include <mrpt/config/CConfigFileBase.h>
#include <mrpt/core/bits_math.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <sstream>
#include <stdexcept>
#include <tuple>

namespace devslam::sim {

namespace {
[[noreturn]] void fail(const std::string& source, const std::string& section,
                       const std::string& key, const std::string& what) {
    throw std::invalid_argument(source + " [" + section + "]" + (key.empty() ? "" : " " + key) +
                                ": " + what);
}

std::vector<std::string> splitWords(const std::string& s) {
    std::istringstream is(s);
    std::vector<std::string> out;
    std::string w;
    while (is >> w) out.push_back(w);
    return out;
}

/// The numbers after the first `from` words (an obstacle's or pedestrian's kind).
std::vector<double> parseNumbers(const std::vector<std::string>& words, size_t from,
                                 const std::string& source, const std::string& section,
                                 const std::string& key) {
    std::string rest;
    for (size_t i = from; i < words.size(); i++) rest += words[i] + " ";
    return core::parseNumberList(rest, source + " [" + section + "] " + key);
}

}  // namespace

WorldSpec loadWorld(const std::string& path) {
    auto cfg = core::loadIni(path);
    return parseWorld(*cfg, path);
}

namespace {

void parseWorldSection(const mrpt::config::CConfigFileBase& c, const std::string& source,
                       WorldSpec& w) {
    const std::string s = "world";
    core::requireKnownKeys(c, s,
                           {"name", "x_min", "x_max", "y_min", "y_max", "boundary_walls",
                            "grid_resolution", "time_step", "timeout", "seed", "pedestrians_yield"},
                           source);
    w.name = c.read_string(s, "name", w.name);
    w.x_min = core::readDouble(c, s, "x_min", 0.0, true);
    w.x_max = core::readDouble(c, s, "x_max", 0.0, true);
    w.y_min = core::readDouble(c, s, "y_min", 0.0, true);
    w.y_max = core::readDouble(c, s, "y_max", 0.0, true);
    w.boundary_walls = core::readBool(c, s, "boundary_walls", w.boundary_walls);
    w.grid_resolution = core::readDouble(c, s, "grid_resolution", w.grid_resolution);
    w.time_step = core::readDouble(c, s, "time_step", w.time_step);
    w.timeout = core::readDouble(c, s, "timeout", w.timeout);
    const std::uint64_t seed = core::readUint64(c, s, "seed", w.seed);
    if (seed > UINT32_MAX) fail(source, s, "seed", "must be < 2^32, got " + std::to_string(seed));
    w.seed = static_cast<uint32_t>(seed);
    w.pedestrians_yield = core::readBool(c, s, "pedestrians_yield", w.pedestrians_yield);
}

void parseRobotGoalLaser(const mrpt::config::CConfigFileBase& c, const std::string& source,
                         WorldSpec& w) {
    std::string s = "robot";
    core::requireKnownKeys(c, s,
                           {"start_x", "start_y", "start_yaw_deg", "radius", "max_v", "max_w_deg",
                            "max_acc", "max_ang_acc_deg"},
                           source);
    w.robot.start.x = core::readDouble(c, s, "start_x", 0.0, true);
    w.robot.start.y = core::readDouble(c, s, "start_y", 0.0, true);
    w.robot.start.phi = mrpt::DEG2RAD(core::readDouble(c, s, "start_yaw_deg", 0.0));
    w.robot.radius = core::readDouble(c, s, "radius", w.robot.radius);
    w.robot.max_v = core::readDouble(c, s, "max_v", w.robot.max_v);
    w.robot.max_w =
        mrpt::DEG2RAD(core::readDouble(c, s, "max_w_deg", mrpt::RAD2DEG(w.robot.max_w)));
    w.robot.max_acc = core::readDouble(c, s, "max_acc", w.robot.max_acc);
    w.robot.max_ang_acc = mrpt::DEG2RAD(
        core::readDouble(c, s, "max_ang_acc_deg", mrpt::RAD2DEG(w.robot.max_ang_acc)));

    s = "goal";
    core::requireKnownKeys(c, s, {"x", "y", "tolerance"}, source);
    w.goal.x = core::readDouble(c, s, "x", 0.0, true);
    w.goal.y = core::readDouble(c, s, "y", 0.0, true);
    w.goal_tolerance = core::readDouble(c, s, "tolerance", w.goal_tolerance);

    s = "laser";
    core::requireKnownKeys(
        c, s, {"range", "rays", "fov_deg", "noise_std", "rate_hz", "height", "detect_people"},
        source);
    w.laser.range = core::readDouble(c, s, "range", w.laser.range);
    w.laser.rays = core::readInt(c, s, "rays", w.laser.rays);
    w.laser.fov = mrpt::DEG2RAD(core::readDouble(c, s, "fov_deg", mrpt::RAD2DEG(w.laser.fov)));
    w.laser.noise_std = core::readDouble(c, s, "noise_std", w.laser.noise_std);
    w.laser.rate = core::readDouble(c, s, "rate_hz", w.laser.rate);
    w.laser.height = core::readDouble(c, s, "height", w.laser.height);
    w.laser.detect_people = core::readBool(c, s, "detect_people", w.laser.detect_people);
}

/// [obstacles] key = "box|block|wall cx cy size_x size_y [yaw_deg]" or "cylinder cx cy radius".
Obstacle parseObstacle(const mrpt::config::CConfigFileBase& c, const std::string& source,
                       const std::string& k) {
    const std::string s = "obstacles";
    const auto words = splitWords(c.read_string(s, k, ""));
    if (words.empty()) fail(source, s, k, "empty obstacle");
    const auto v = parseNumbers(words, 1, source, s, k);
    Obstacle o;
    o.name = k;
    o.kind = words[0];
    if (o.kind == "box" || o.kind == "block" || o.kind == "wall") {
        if (v.size() != 4 && v.size() != 5)
            fail(source, s, k, "expected '" + o.kind + " cx cy size_x size_y [yaw_deg]'");
        o.shape = Obstacle::Shape::Box;
        o.cx = v[0];
        o.cy = v[1];
        o.sx = v[2];
        o.sy = v[3];
        o.yaw = v.size() == 5 ? mrpt::DEG2RAD(v[4]) : 0.0;
        // Bullet takes the angle in single precision: 1e9 deg turned its box ~0.5 rad off the
        // one the grid and the checks here use.
        if (!(std::abs(o.yaw) <= 2 * M_PI + 1e-9))
            fail(source, s, k, "yaw_deg must be in [-360, 360] deg");
        // 1e300 reached the rasterizer's integer cell indices
        if (!(o.sx > 0 && o.sy > 0 && o.sx <= 1000 && o.sy <= 1000))
            fail(source, s, k, "sizes must be in (0, 1000] m");
        o.height = o.kind == "block" ? 0.4 : 1.0;
    } else if (o.kind == "cylinder") {
        if (v.size() != 3) fail(source, s, k, "expected 'cylinder cx cy radius'");
        o.shape = Obstacle::Shape::Cylinder;
        o.cx = v[0];
        o.cy = v[1];
        o.radius = v[2];
        if (!(o.radius > 0 && o.radius <= 1000))
            fail(source, s, k, "radius must be in (0, 1000] m");
    } else {
        fail(source, s, k,
             "unknown obstacle kind '" + o.kind + "' (known: box, block, wall, cylinder)");
    }
    return o;
}

/// [pedestrians] key = "scripted speed radius delay x1 y1 x2 y2 [...]" or
/// "random speed radius delay x y".
Pedestrian parsePedestrian(const mrpt::config::CConfigFileBase& c, const std::string& source,
                           const std::string& k) {
    const std::string s = "pedestrians";
    const auto words = splitWords(c.read_string(s, k, ""));
    if (words.empty()) fail(source, s, k, "empty pedestrian");
    Pedestrian p;
    p.name = k;
    const auto v = parseNumbers(words, 1, source, s, k);
    if (words[0] == "scripted") {
        // scripted speed radius delay x1 y1 x2 y2 ...
        if (v.size() < 7 || (v.size() - 3) % 2 != 0)
            fail(source, s, k,
                 "expected 'scripted speed radius delay x1 y1 x2 y2 [...]' (>= 2 points)");
        p.mode = Pedestrian::Mode::Scripted;
    } else if (words[0] == "random") {
        if (v.size() != 5) fail(source, s, k, "expected 'random speed radius delay x y'");
        p.mode = Pedestrian::Mode::RandomWalk;
    } else {
        fail(source, s, k, "unknown pedestrian mode '" + words[0] + "' (known: scripted, random)");
    }
    p.speed = v[0];
    p.radius = v[1];
    p.start_delay = v[2];
    for (size_t i = 3; i + 1 < v.size(); i += 2) p.path.emplace_back(v[i], v[i + 1]);
    if (p.speed < 0 || p.radius <= 0 || p.start_delay < 0)
        fail(source, s, k, "speed and delay must be >= 0, radius > 0");
    // Only a person's centre is checked against the obstacles: a 3 m person overlapped the
    // walls and desks it walked past.
    if (p.radius > 1) fail(source, s, k, "radius must be at most 1 m (a person)");
    return p;
}

WorldSpec parseWorldFields(const mrpt::config::CConfigFileBase& c, const std::string& source) {
    WorldSpec w;
    w.source = source;
    for (const char* s : {"world", "robot", "goal"})
        if (!c.sectionExists(s)) fail(source, s, "", "required section is missing");
    parseWorldSection(c, source, w);
    parseRobotGoalLaser(c, source, w);
    std::vector<std::string> keys;
    c.getAllKeys("obstacles", keys);
    for (const auto& k : keys) w.obstacles.push_back(parseObstacle(c, source, k));
    keys.clear();
    c.getAllKeys("pedestrians", keys);
    for (const auto& k : keys) w.pedestrians.push_back(parsePedestrian(c, source, k));
    validateWorld(w);
    return w;
}

}  // namespace

WorldSpec parseWorld(const mrpt::config::CConfigFileBase& c, const std::string& source) {
    core::requireKnownSections(c, {"world", "robot", "goal", "laser", "obstacles", "pedestrians"},
                               source);
    return core::namingSource(source, [&] { return parseWorldFields(c, source); });
}

namespace {

/// Half extents [m] of the obstacle's axis-aligned bounding box.
std::pair<double, double> halfExtents(const Obstacle& o) {
    if (o.shape == Obstacle::Shape::Cylinder) return {o.radius, o.radius};
    const double c = std::abs(std::cos(o.yaw)), s = std::abs(std::sin(o.yaw));
    return {0.5 * (c * o.sx + s * o.sy), 0.5 * (s * o.sx + c * o.sy)};
}

bool insideBounds(const WorldSpec& w, const mrpt::math::TPoint2D& p) {
    return p.x > w.x_min && p.x < w.x_max && p.y > w.y_min && p.y < w.y_max;
}

/// [world]: the bounds, the grid and the physics step, and what they cost to run.
void validateBoundsAndTiming(const WorldSpec& w) {
    const auto& src = w.source;
    if (!(w.x_max > w.x_min)) fail(src, "world", "x_max", "must be > x_min");
    if (!(w.y_max > w.y_min)) fail(src, "world", "y_max", "must be > y_min");
    // The name makes the default picture's file name (out/nav_<name>.png): "../../x" wrote
    // outside out/, "a/b" into a folder.
    // An empty one named the picture "nav_.png" and left the result line's world= blank.
    // A blank split the result line's world= field ("world=my world").
    if (w.name.empty() || w.name == "." || w.name == ".." ||
        w.name.find_first_of("/\\ \t") != std::string::npos)
        fail(src, "world", "name",
             "must be a file name: not empty, '.' or '..', no '/', '\\' or blank");
    // (300 characters made a picture name over the file system's 255: refused after the run)
    if (w.name.size() > 100) fail(src, "world", "name", "must be at most 100 characters");
    // Bullet simulates in single precision: at 1e6 m one float step is 6 cm, more than the
    // robot moves in a physics step, and it never moved.
    constexpr double kMaxCoordinate = 1e4;
    for (const auto& [key, v] :
         {std::pair{"x_min", w.x_min}, {"x_max", w.x_max}, {"y_min", w.y_min}, {"y_max", w.y_max}})
        if (std::abs(v) > kMaxCoordinate)
            fail(src, "world", key, "must be within +-10000 m (Bullet's single precision)");
    if (w.grid_resolution <= 0 || w.grid_resolution > 0.5)
        fail(src, "world", "grid_resolution", "must be in (0, 0.5] m");
    // The occupancy grid holds every cell of the bounds.
    const double cells =
        (w.x_max - w.x_min) / w.grid_resolution * ((w.y_max - w.y_min) / w.grid_resolution);
    if (cells > nav::kMaxGridCells) {
        std::ostringstream m;
        m << "bounds " << w.x_max - w.x_min << " x " << w.y_max - w.y_min << " m at "
          << w.grid_resolution << " m make " << cells << " grid cells (at most 1e8)";
        fail(src, "world", "grid_resolution", m.str());
    }
    if (w.time_step <= 0 || w.time_step > 0.1)
        fail(src, "world", "time_step", "must be in (0, 0.1] s");
    if (w.timeout <= 0) fail(src, "world", "timeout", "must be > 0 s");
    // A run steps the physics timeout / time_step times with nothing printed on the way.
    constexpr double kMaxSteps = 1e6;
    if (w.timeout / w.time_step > kMaxSteps) {
        std::ostringstream m;
        m << "timeout " << w.timeout << " s at time_step " << w.time_step << " s makes "
          << w.timeout / w.time_step << " physics steps (at most 1e6)";
        fail(src, "world", "timeout", m.str());
    }
}

/// [robot], [laser] and the goal's tolerance.
void validateRobotAndLaser(const WorldSpec& w) {
    const auto& src = w.source;
    if (w.robot.radius <= 0) fail(src, "robot", "radius", "must be > 0 m");
    // MRPT builds its PTGs' collision grids for the robot's shape: 2 m took 75 s, 5 m 136 s,
    // with nothing printed. A guide robot is well under a metre.
    if (w.robot.radius > 1) fail(src, "robot", "radius", "must be at most 1 m");
    for (const auto& [key, v] : {std::pair{"max_v", w.robot.max_v},
                                 {"max_w_deg", w.robot.max_w},
                                 {"max_acc", w.robot.max_acc},
                                 {"max_ang_acc_deg", w.robot.max_ang_acc}})
        if (!(v > 0)) fail(src, "robot", key, "speed and acceleration limits must be > 0");
    // Unbounded, these ran: a yaw of 1e300 deg gave path=-nan, max_v = 1e9 m/s and
    // max_w_deg = 1e12 a robot that jumps across the world in one step.
    if (!(std::abs(w.robot.start.phi) <= 2 * M_PI + 1e-9))
        fail(src, "robot", "start_yaw_deg", "must be in [-360, 360] deg");
    if (w.robot.max_v > nav::kMaxRobotSpeed) fail(src, "robot", "max_v", "must be at most 5 m/s");
    if (w.robot.max_acc > nav::kMaxRobotAcc)
        fail(src, "robot", "max_acc", "must be at most 20 m/s^2");
    if (w.robot.max_ang_acc > mrpt::DEG2RAD(nav::kMaxRobotAngAccDeg) + 1e-9)
        fail(src, "robot", "max_ang_acc_deg", "must be at most 3600 deg/s^2");
    if (w.robot.max_w > mrpt::DEG2RAD(720.0) + 1e-9)
        fail(src, "robot", "max_w_deg", "must be at most 720 deg/s");
    // (1e39 made every ray's end inf in Bullet's floats: nothing was ever hit)
    if (!(w.laser.range > 0 && w.laser.range <= 100))
        fail(src, "laser", "range", "must be in (0, 100] m");
    if (w.laser.rays < 2 || w.laser.rays > 100000)
        fail(src, "laser", "rays", "must be in [2, 100000]");
    if (!(w.laser.rate > 0)) fail(src, "laser", "rate_hz", "must be > 0");
    // The scan plane must cut every obstacle: above the 0.4 m blocks (or at 0 or below) the
    // robot was blind to them while its planner steered round them.
    if (!(w.laser.height > 0 && w.laser.height < 0.4))
        fail(src, "laser", "height", "must be in (0, 0.4) m, below the top of the lowest obstacle");
    // (100 m of noise on a 6 m laser was accepted)
    if (!(w.laser.noise_std >= 0 && w.laser.noise_std <= 0.1 * w.laser.range))
        fail(src, "laser", "noise_std", "must be in [0, range / 10] m");
    if (!(w.laser.fov > 0) || w.laser.fov > 2 * M_PI + 1e-9)
        fail(src, "laser", "fov_deg", "must be in (0, 360]");
    // Each ray is a Bullet ray cast (about 1 us): 1e8 of them are a minute and a half.
    constexpr double kMaxRays = 1e8;
    // The simulator scans at most once per physics step.
    const double scans_per_s = std::min(w.laser.rate, 1.0 / w.time_step);
    if (const double casts = double(w.laser.rays) * scans_per_s * w.timeout; casts > kMaxRays) {
        std::ostringstream m;
        m << w.laser.rays << " rays at " << scans_per_s << " Hz over the " << w.timeout
          << " s timeout are " << casts << " ray casts (at most 1e8)";
        fail(src, "laser", "rays", m.str());
    }
    if (w.goal_tolerance <= 0) fail(src, "goal", "tolerance", "must be > 0 m");
    // A tolerance of 1000 m was a success at t = 0.
    if (w.goal_tolerance > 2) fail(src, "goal", "tolerance", "must be at most 2 m");
    if (std::hypot(w.goal.x - w.robot.start.x, w.goal.y - w.robot.start.y) <= w.goal_tolerance)
        fail(src, "goal", "tolerance",
             "the robot's start is within it of the goal: the run would end at once");
}

/// Each obstacle reaches into the bounds (one wholly outside was accepted, and did nothing).
void validateObstacles(const WorldSpec& w) {
    for (const auto& o : w.obstacles) {
        const auto [hx, hy] = halfExtents(o);
        if (o.cx + hx <= w.x_min || o.cx - hx >= w.x_max || o.cy + hy <= w.y_min ||
            o.cy - hy >= w.y_max)
            fail(w.source, "obstacles", o.name, "lies entirely outside the world bounds");
    }
}

/// What the obstacles cost: rasterize() tests each grid cell of each obstacle's bounding
/// box, and a run measures the robot's clearance to every obstacle at every physics step.
/// Neither was bounded: 1000 boxes of 1000 m ran for minutes before printing anything, and
/// 100 000 boxes simulated a second in 1.7 s of wall time (a 10 000 s timeout, some 5 hours).
void validateObstacleCost(const WorldSpec& w, const std::vector<Obstacle>& statics) {
    if (statics.empty()) return;
    const double res = w.grid_resolution;
    const double nx = std::ceil((w.x_max - w.x_min) / res),
                 ny = std::ceil((w.y_max - w.y_min) / res);
    double cells = 0;
    for (const auto& o : statics) {  // the cells rasterize() visits, at most the grid's
        const auto [hx, hy] = halfExtents(o);
        cells += std::min(2 * hx / res + 2, nx) * std::min(2 * hy / res + 2, ny);
    }
    // A cell test is some 10 ns: 3e8 are a few seconds, done twice (here and for the run).
    constexpr double kMaxCellTests = 3e8;
    if (cells > kMaxCellTests) {
        std::ostringstream m;
        m.precision(3);
        m << "the " << statics.size() << " obstacles cover " << cells << " grid cells of " << res
          << " m (counted per obstacle, at most 3e8): fewer or smaller obstacles, or a "
          << "coarser [world] grid_resolution";
        fail(w.source, "obstacles", "", m.str());
    }
    // About 0.15 us an obstacle a step (measured with 100 000 boxes): 3e8 are under a minute.
    constexpr double kMaxObstacleSteps = 3e8;
    if (const double tests = double(statics.size()) * (w.timeout / w.time_step);
        tests > kMaxObstacleSteps) {
        std::ostringstream m;
        m.precision(3);
        m << statics.size() << " obstacles over " << w.timeout / w.time_step
          << " physics steps are " << tests << " clearance tests (at most 3e8): fewer "
          << "obstacles, or a shorter [world] timeout";
        fail(w.source, "obstacles", "", m.str());
    }
}

/// The start and the goal: inside the bounds, off the obstacles, and usable on the planner's
/// grid.
void validateEndpoints(const WorldSpec& w, const std::vector<Obstacle>& statics) {
    const auto& src = w.source;
    // The coordinate that is out names the key (x first when both are).
    const auto outKey = [&](const mrpt::math::TPoint2D& p, const char* kx, const char* ky) {
        return p.x > w.x_min && p.x < w.x_max ? ky : kx;
    };
    if (!insideBounds(w, {w.robot.start.x, w.robot.start.y}))
        fail(src, "robot", outKey({w.robot.start.x, w.robot.start.y}, "start_x", "start_y"),
             "start is outside the world bounds");
    if (!insideBounds(w, w.goal))
        fail(src, "goal", outKey(w.goal, "x", "y"), "goal is outside the world bounds");
    for (const auto& o : statics) {
        const double dg = distanceToObstacle(o, w.goal);
        if (dg <= 0) fail(src, "goal", "x", "the goal lies inside obstacle '" + o.name + "'");
        if (dg < w.robot.radius)
            fail(src, "goal", "x",
                 "the goal is " + std::to_string(dg) + " m from obstacle '" + o.name +
                     "', closer than the robot radius " + std::to_string(w.robot.radius) +
                     " m: the robot cannot stand on it");
        if (distanceToObstacle(o, {w.robot.start.x, w.robot.start.y}) < w.robot.radius)
            fail(src, "robot", "start_x",
                 "the robot starts inside or touching obstacle '" + o.name + "'");
    }
    // The planner sees the world on its grid, where clearance is measured between cell centres
    // and obstacles grow to whole cells: up to about 1.7 cells less than the exact distance.
    // A goal or start the exact test passes can still be one the planner refuses; say so here,
    // in the world file's terms, rather than as a planning error when the run starts.
    // MRPT's grid covers the bounds rounded to whole cells: a goal or start in the sliver
    // it leaves out was refused only when the run started, as a planning error naming no file.
    const auto grid = rasterize(w);
    const mrpt::math::TPoint2D start{w.robot.start.x, w.robot.start.y};
    for (const auto& [what, section, key, p] : {std::tuple{"goal", "goal", "x", w.goal},
                                                std::tuple{"start", "robot", "start_x", start}}) {
        const int ix = grid.x2idx(p.x), iy = grid.y2idx(p.y);
        if (ix >= 0 && iy >= 0 && ix < static_cast<int>(grid.getSizeX()) &&
            iy < static_cast<int>(grid.getSizeY()))
            continue;
        std::ostringstream m;
        m << "the " << what << " (" << p.x << ", " << p.y << ") lies outside the planner's grid ["
          << grid.getXMin() << ", " << grid.getXMax() << "] x [" << grid.getYMin() << ", "
          << grid.getYMax() << "] m (the bounds in whole cells of grid_resolution "
          << w.grid_resolution << " m): move it inside, or widen the bounds";
        fail(src, section, key, m.str());
    }
    if (!statics.empty()) {
        nav::GridPlannerOptions po;
        po.robot_radius = w.robot.radius;
        nav::GridPlanner planner(po);
        planner.setMap(grid);
        for (const auto& [what, section, key, p] :
             {std::tuple{"goal", "goal", "x", w.goal},
              std::tuple{"start", "robot", "start_x", start}}) {
            const double c = planner.clearance(p);
            if (c >= w.robot.radius) continue;
            const Obstacle* nearest = nearestObstacle(statics, p);  // statics is not empty
            std::ostringstream m;
            m << "the " << what << " is " << distanceToObstacle(*nearest, p) << " m from obstacle '"
              << nearest->name << "', but on the planner's " << w.grid_resolution
              << " m grid (grid_resolution) it has " << c
              << " m of clearance, less than the robot radius " << w.robot.radius
              << " m: move it at least " << w.robot.radius - c
              << " m further off, or use a finer grid";
            fail(src, section, key, m.str());
        }
    }
}

/// Whether the segment a-b enters the inside of `o` (touching its edge does not count). Exact:
/// the path check sampled every 2 cm and let a person walk through a 1 cm wall.
bool segmentEntersObstacle(const Obstacle& o, const mrpt::math::TPoint2D& a,
                           const mrpt::math::TPoint2D& b) {
    const double dx = b.x - a.x, dy = b.y - a.y;
    if (o.shape == Obstacle::Shape::Cylinder) {
        const double len2 = dx * dx + dy * dy;
        const double t =
            len2 > 0 ? std::clamp(((o.cx - a.x) * dx + (o.cy - a.y) * dy) / len2, 0.0, 1.0) : 0.0;
        return std::hypot(a.x + t * dx - o.cx, a.y + t * dy - o.cy) < o.radius;
    }
    // In the box's frame, the part of the segment strictly inside |x| < sx/2, |y| < sy/2
    // (Liang-Barsky clipping): it enters when that part has a length.
    const double c = std::cos(o.yaw), s = std::sin(o.yaw);
    const double ax = c * (a.x - o.cx) + s * (a.y - o.cy),
                 ay = -s * (a.x - o.cx) + c * (a.y - o.cy);
    const double ux = c * dx + s * dy, uy = -s * dx + c * dy;
    double lo = 0, hi = 1;
    for (const auto& [p0, d, half] : {std::tuple{ax, ux, o.sx / 2}, std::tuple{ay, uy, o.sy / 2}}) {
        if (d == 0) {
            if (!(std::abs(p0) < half)) return false;
            continue;
        }
        double t0 = (-half - p0) / d, t1 = (half - p0) / d;
        if (t0 > t1) std::swap(t0, t1);
        lo = std::max(lo, t0);
        hi = std::min(hi, t1);
    }
    return lo < hi;
}

/// Each pedestrian: inside the bounds, off the robot's start, and never through an obstacle.
void validatePedestrians(const WorldSpec& w, const std::vector<Obstacle>& statics) {
    const auto& src = w.source;
    const auto at = [](const mrpt::math::TPoint2D& q) {
        std::ostringstream m;
        m << "(" << q.x << ", " << q.y << ")";
        return m.str();
    };
    // Each physics step tests every person against every obstacle and person (about 6 ns a
    // pair): 2000 people among 2000 obstacles passed every other check and simulated 5 s in
    // 25 s of wall time (0.01 s steps), a 1e6-step run some 14 hours. 1e10 pair tests are
    // about a minute.
    if (const double pairs = double(w.pedestrians.size()) *
                             double(statics.size() + w.pedestrians.size()) *
                             (w.timeout / w.time_step);
        pairs > 1e10) {
        std::ostringstream m;
        m << w.pedestrians.size() << " people among " << statics.size() << " obstacles over "
          << w.timeout / w.time_step << " physics steps are " << pairs
          << " person-obstacle tests (at most 1e10): fewer people or obstacles, or a shorter "
             "[world] timeout";
        fail(src, "pedestrians", w.pedestrians.front().name, m.str());
    }
    for (const auto& p : w.pedestrians) {
        if (p.path.empty()) fail(src, "pedestrians", p.name, "no position given");
        if (p.speed > 5) fail(src, "pedestrians", p.name, "speed must be at most 5 m/s");
        // Bullet tests contacts at the steps only (no continuous detection): a person and
        // the robot closing in by more than the smaller radius in one step could pass
        // through each other unseen.
        if (const double closing = (p.speed + w.robot.max_v) * w.time_step;
            closing > std::min(p.radius, w.robot.radius)) {
            std::ostringstream m;
            m << "speed " << p.speed << " m/s and the robot's max_v " << w.robot.max_v
              << " m/s close " << closing << " m in one time_step of " << w.time_step
              << " s, more than the smaller radius (" << std::min(p.radius, w.robot.radius)
              << " m): a contact could be missed; lower [world] time_step";
            fail(src, "pedestrians", p.name, m.str());
        }
        if (p.start_delay > w.timeout) {
            std::ostringstream m;
            m << "delay must be at most the world's timeout (" << w.timeout << " s)";
            fail(src, "pedestrians", p.name, m.str());
        }
        for (const auto& q : p.path)
            if (!insideBounds(w, q))
                fail(src, "pedestrians", p.name, "a point is outside the world bounds");
        const auto& p0 = p.path.front();
        if (std::hypot(p0.x - w.robot.start.x, p0.y - w.robot.start.y) < p.radius + w.robot.radius)
            fail(src, "pedestrians", p.name,
                 "starts at " + at(p0) + ", on the robot (its start is within the two radii)");
        // A person who never moves, standing where the robot would have to stand to arrive:
        // the run waited out its timeout, saying only "not at the goal".
        if (p.speed == 0 &&
            std::hypot(p0.x - w.goal.x, p0.y - w.goal.y) + w.goal_tolerance <
                p.radius + w.robot.radius) {
            std::ostringstream m;
            m << "stands still (speed 0) at " << at(p0) << ", on the goal: no place within the "
              << "goal's tolerance (" << w.goal_tolerance << " m) keeps the robot clear of them";
            fail(src, "pedestrians", p.name, m.str());
        }
        // The simulated people are kinematic: a scripted one walks through whatever lies on
        // its path (brushing past an edge is allowed), and a random walker never leaves an
        // obstacle it starts in. Both are mistakes in the world file.
        const std::size_t legs = p.mode == Pedestrian::Mode::Scripted ? p.path.size() - 1 : 0;
        for (const auto& o : statics) {
            if (distanceToObstacle(o, p0) < 0)
                fail(src, "pedestrians", p.name,
                     "starts at " + at(p0) + ", inside obstacle '" + o.name + "'");
            for (std::size_t k = 0; k < legs; ++k) {
                const auto &a = p.path[k], &b = p.path[k + 1];
                if (segmentEntersObstacle(o, a, b))
                    fail(src, "pedestrians", p.name,
                         "its path from " + at(a) + " to " + at(b) + " runs through obstacle '" +
                             o.name + "'");
            }
        }
    }
}

}  // namespace

void validateWorld(const WorldSpec& w) {
    validateBoundsAndTiming(w);
    validateRobotAndLaser(w);
    validateObstacles(w);
    const auto statics = staticObstacles(w);
    validateObstacleCost(w, statics);
    validateEndpoints(w, statics);
    validatePedestrians(w, statics);
}

std::vector<Obstacle> staticObstacles(const WorldSpec& w) {
    std::vector<Obstacle> out = w.obstacles;
    if (w.boundary_walls) {
        const double t = 0.1, cx = 0.5 * (w.x_min + w.x_max), cy = 0.5 * (w.y_min + w.y_max);
        const double lx = w.x_max - w.x_min, ly = w.y_max - w.y_min;
        auto wall = [&](const char* n, double x, double y, double sx, double sy) {
            Obstacle o;
            o.name = n;
            o.kind = "wall";
            o.cx = x;
            o.cy = y;
            o.sx = sx;
            o.sy = sy;
            out.push_back(o);
        };
        wall("boundary_south", cx, w.y_min + t / 2, lx, t);
        wall("boundary_north", cx, w.y_max - t / 2, lx, t);
        wall("boundary_west", w.x_min + t / 2, cy, t, ly);
        wall("boundary_east", w.x_max - t / 2, cy, t, ly);
    }
    return out;
}

double distanceToObstacle(const Obstacle& o, const mrpt::math::TPoint2D& p) {
    const double dx = p.x - o.cx, dy = p.y - o.cy;
    if (o.shape == Obstacle::Shape::Cylinder) return std::hypot(dx, dy) - o.radius;
    const double c = std::cos(o.yaw), s = std::sin(o.yaw);
    const double lx = c * dx + s * dy, ly = -s * dx + c * dy;  // box frame
    const double qx = std::abs(lx) - o.sx / 2, qy = std::abs(ly) - o.sy / 2;
    const double outside = std::hypot(std::max(qx, 0.0), std::max(qy, 0.0));
    return outside + std::min(std::max(qx, qy), 0.0);
}

const Obstacle* nearestObstacle(const std::vector<Obstacle>& obstacles,
                                const mrpt::math::TPoint2D& p) {
    const Obstacle* nearest = nullptr;
    double d_min = 0;
    for (const auto& o : obstacles) {
        const double d = distanceToObstacle(o, p);
        if (!nearest || d < d_min) nearest = &o, d_min = d;
    }
    return nearest;
}

mrpt::maps::COccupancyGridMap2D rasterize(const WorldSpec& w) {
    mrpt::maps::COccupancyGridMap2D g;
    g.setSize(w.x_min, w.x_max, w.y_min, w.y_max, static_cast<float>(w.grid_resolution), 1.0f);
    const double half = 0.5 * w.grid_resolution;
    for (const auto& o : staticObstacles(w)) {
        // Only cells within half a cell of the obstacle are marked: its bounding box, grown by
        // that, holds their centres (a long wall's bounding square held the whole grid).
        const auto [hx, hy] = halfExtents(o);
        const int x0 = std::max(0, g.x2idx(o.cx - hx - half)),
                  x1 = std::min(int(g.getSizeX()) - 1, g.x2idx(o.cx + hx + half));
        const int y0 = std::max(0, g.y2idx(o.cy - hy - half)),
                  y1 = std::min(int(g.getSizeY()) - 1, g.y2idx(o.cy + hy + half));
        for (int y = y0; y <= y1; y++)
            for (int x = x0; x <= x1; x++)
                if (distanceToObstacle(o, {g.idx2x(x), g.idx2y(y)}) <= half * 0.999)
                    g.setCell(x, y, 0.0f);
    }
    return g;
}

}  // namespace devslam::sim
