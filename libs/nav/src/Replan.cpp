#include <devslam/core/Config.h>
#include <devslam/nav/Replan.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace devslam::nav {

void ReplanOptions::loadFromConfigFile(const mrpt::config::CConfigFileBase& c, const std::string& s,
                                       const std::string& source) {
    core::requireKnownKeys(
        c, s,
        {"density_threshold", "density_time", "min_interval", "blocked_lookahead", "blocked_margin",
         "obstacle_inflation", "sensed_range"},
        source);
    density_threshold = core::readDouble(c, s, "density_threshold", density_threshold);
    density_time = core::readDouble(c, s, "density_time", density_time);
    min_interval = core::readDouble(c, s, "min_interval", min_interval);
    blocked_lookahead = core::readDouble(c, s, "blocked_lookahead", blocked_lookahead);
    blocked_margin = core::readDouble(c, s, "blocked_margin", blocked_margin);
    obstacle_inflation = core::readDouble(c, s, "obstacle_inflation", obstacle_inflation);
    sensed_range = core::readDouble(c, s, "sensed_range", sensed_range);
    core::requireValue(density_threshold >= 0, s, "density_threshold", "must be >= 0");
    core::requireValue(density_time >= 0, s, "density_time", "must be >= 0 s");
    core::requireValue(min_interval >= 0, s, "min_interval", "must be >= 0 s");
    core::requireValue(blocked_lookahead > 0, s, "blocked_lookahead", "must be > 0 m");
    core::requireValue(blocked_margin >= 0, s, "blocked_margin", "must be >= 0 m");
    // (1e9 m covered the whole map: every replan fell back to the static map, without a word)
    core::requireValue(obstacle_inflation >= 0 && obstacle_inflation <= 2, s,
                       "obstacle_inflation", "must be in [0, 2] m");
    core::requireValue(sensed_range > 0, s, "sensed_range", "must be > 0 m");
}

void ReplanOptions::saveToConfigFile(mrpt::config::CConfigFileBase& c, const std::string& s) const {
    core::writeKey(c, s, "density_threshold", density_threshold);
    core::writeKey(c, s, "density_time", density_time);
    core::writeKey(c, s, "min_interval", min_interval);
    core::writeKey(c, s, "blocked_lookahead", blocked_lookahead);
    core::writeKey(c, s, "blocked_margin", blocked_margin);
    core::writeKey(c, s, "obstacle_inflation", obstacle_inflation);
    core::writeKey(c, s, "sensed_range", sensed_range);
}

const char* toString(ReplanReason r) {
    switch (r) {
        case ReplanReason::None:
            return "none";
        case ReplanReason::PathBlocked:
            return "path blocked";
        case ReplanReason::HighDensity:
            return "high obstacle density toward the target";
    }
    return "?";
}

void ReplanTrigger::reset(double t) {
    last_replan_ = t;
    dense_since_ = -1;
}

ReplanReason ReplanTrigger::update(const ReplanInput& in) {
    if (in.goal_density > opts_.density_threshold) {
        if (dense_since_ < 0) dense_since_ = in.t;
    } else {
        dense_since_ = -1;
    }
    if (in.t - last_replan_ < opts_.min_interval) return ReplanReason::None;
    ReplanReason r = ReplanReason::None;
    if (in.path_blocked)
        r = ReplanReason::PathBlocked;
    else if (dense_since_ >= 0 && in.t - dense_since_ >= opts_.density_time)
        r = ReplanReason::HighDensity;
    if (r != ReplanReason::None) reset(in.t);
    return r;
}

namespace {
double pointSegmentDistance(const mrpt::math::TPoint2D& p, const mrpt::math::TPoint2D& a,
                            const mrpt::math::TPoint2D& b) {
    const double vx = b.x - a.x, vy = b.y - a.y;
    const double l2 = vx * vx + vy * vy;
    double t = l2 > 0 ? ((p.x - a.x) * vx + (p.y - a.y) * vy) / l2 : 0.0;
    t = std::clamp(t, 0.0, 1.0);
    return std::hypot(p.x - (a.x + t * vx), p.y - (a.y + t * vy));
}
}  // namespace

std::size_t pathProgress(const std::vector<mrpt::math::TPoint2D>& path,
                         const mrpt::math::TPoint2D& robot, std::size_t from, double window) {
    if (path.size() < 2) return 0;
    from = std::min(from, path.size() - 2);
    const auto length = [&](std::size_t i) {
        return std::hypot(path[i + 1].x - path[i].x, path[i + 1].y - path[i].y);
    };
    std::size_t lo = from;  // back to `window` before segment `from` begins
    for (double back = 0; lo > 0 && back + length(lo - 1) <= window; lo--) back += length(lo - 1);
    std::size_t nearest = from;
    double best = std::numeric_limits<double>::infinity();
    double ahead = 0;  // path length from segment `from`'s start to segment i's
    for (std::size_t i = lo; i + 1 < path.size(); i++) {
        if (i > from) ahead += length(i - 1);
        if (ahead > window) break;
        const double d = pointSegmentDistance(robot, path[i], path[i + 1]);
        if (d < best) {
            best = d;
            nearest = i;
        }
    }
    return nearest;
}

std::size_t waypointAhead(const std::vector<std::size_t>& waypoint_path_index,
                          std::size_t segment) {
    if (waypoint_path_index.empty()) return 0;
    const auto it =
        std::upper_bound(waypoint_path_index.begin(), waypoint_path_index.end(), segment);
    if (it == waypoint_path_index.end()) return waypoint_path_index.size() - 1;
    return static_cast<std::size_t>(it - waypoint_path_index.begin());
}

bool pathBlocked(const std::vector<mrpt::math::TPoint2D>& path, std::size_t segment,
                 const std::vector<mrpt::math::TPoint2D>& obstacles, double radius,
                 double lookahead) {
    if (path.size() < 2 || obstacles.empty()) return false;
    double travelled = 0;
    for (size_t i = segment; i + 1 < path.size() && travelled < lookahead; i++) {
        for (const auto& o : obstacles)
            if (pointSegmentDistance(o, path[i], path[i + 1]) < radius) return true;
        travelled += std::hypot(path[i + 1].x - path[i].x, path[i + 1].y - path[i].y);
    }
    return false;
}

std::vector<mrpt::math::TPoint2D> unmappedPoints(const GridPlanner& static_map,
                                                 const std::vector<mrpt::math::TPoint2D>& sensed) {
    // A wall's surface lies in its own (grown) cells or the next: clearance up to half a cell.
    const double mapped_within = static_map.map().getResolution();
    std::vector<mrpt::math::TPoint2D> out;
    for (const auto& p : sensed)
        if (static_map.clearance(p) > mapped_within) out.push_back(p);
    return out;
}

mrpt::maps::COccupancyGridMap2D stampSensedObstacles(
    const mrpt::maps::COccupancyGridMap2D& static_map, const mrpt::math::TPoint2D& robot,
    const mrpt::math::TPoint2D& goal, const std::vector<mrpt::math::TPoint2D>& sensed,
    double robot_radius, const ReplanOptions& o) {
    mrpt::maps::COccupancyGridMap2D m = static_map;
    const double r = o.obstacle_inflation;
    const double keep_out = robot_radius + r + 0.05;
    const double res = m.getResolution();
    const int W = static_cast<int>(m.getSizeX()), H = static_cast<int>(m.getSizeY());
    const auto inGrid = [&](int cx, int cy) { return cx >= 0 && cy >= 0 && cx < W && cy < H; };
    for (const auto& p : sensed) {
        const double d = std::hypot(p.x - robot.x, p.y - robot.y);
        if (d > o.sensed_range || d < keep_out) continue;
        if (std::hypot(p.x - goal.x, p.y - goal.y) < robot_radius + r) continue;
        for (double dy = -r; dy <= r; dy += res)
            for (double dx = -r; dx <= r; dx += res)
                if (dx * dx + dy * dy <= r * r) {
                    const int cx = m.x2idx(p.x + dx), cy = m.y2idx(p.y + dy);
                    if (inGrid(cx, cy)) m.setCell(cx, cy, 0.0f);
                }
    }
    // The planner's clearance at a point is measured from its cell's centre (up to res/sqrt 2
    // away) to the nearest occupied cell's centre, less half a cell: with no stamped cell
    // centre within robot_radius + 1.5 res of the point, it is above robot_radius.
    const double keep = robot_radius + 1.5 * res;
    for (const auto& e : {robot, goal}) {
        const int c0x = m.x2idx(e.x - keep), c1x = m.x2idx(e.x + keep);
        const int c0y = m.y2idx(e.y - keep), c1y = m.y2idx(e.y + keep);
        for (int cy = c0y; cy <= c1y; ++cy)
            for (int cx = c0x; cx <= c1x; ++cx)
                if (inGrid(cx, cy) && std::hypot(m.idx2x(cx) - e.x, m.idx2y(cy) - e.y) <= keep)
                    m.setCell(cx, cy, static_map.getCell(cx, cy));
    }
    return m;
}

}  // namespace devslam::nav
