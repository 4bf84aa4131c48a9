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
    core::requireValue(density_time >= 0, s, "density_time", "must be >= 0 s");
    core::requireValue(min_interval >= 0, s, "min_interval", "must be >= 0 s");
    core::requireValue(blocked_lookahead > 0, s, "blocked_lookahead", "must be > 0 m");
    core::requireValue(obstacle_inflation >= 0, s, "obstacle_inflation", "must be >= 0 m");
}

void ReplanOptions::saveToConfigFile(mrpt::config::CConfigFileBase& c, const std::string& s) const {
    c.write(s, "density_threshold", density_threshold);
    c.write(s, "density_time", density_time);
    c.write(s, "min_interval", min_interval);
    c.write(s, "blocked_lookahead", blocked_lookahead);
    c.write(s, "blocked_margin", blocked_margin);
    c.write(s, "obstacle_inflation", obstacle_inflation);
    c.write(s, "sensed_range", sensed_range);
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

bool pathBlocked(const std::vector<mrpt::math::TPoint2D>& path, const mrpt::math::TPoint2D& robot,
                 const std::vector<mrpt::math::TPoint2D>& obstacles, double radius,
                 double lookahead) {
    if (path.size() < 2 || obstacles.empty()) return false;
    // closest segment to the robot
    size_t first = 0;
    double best = std::numeric_limits<double>::infinity();
    for (size_t i = 0; i + 1 < path.size(); i++) {
        const double d = pointSegmentDistance(robot, path[i], path[i + 1]);
        if (d < best) {
            best = d;
            first = i;
        }
    }
    double travelled = 0;
    for (size_t i = first; i + 1 < path.size() && travelled < lookahead; i++) {
        for (const auto& o : obstacles)
            if (pointSegmentDistance(o, path[i], path[i + 1]) < radius) return true;
        travelled += std::hypot(path[i + 1].x - path[i].x, path[i + 1].y - path[i].y);
    }
    return false;
}

}  // namespace devslam::nav
