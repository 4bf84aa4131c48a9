#include <devslam/core/Config.h>
#include <devslam/nav/GridPlanner.h>

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>
#include <sstream>

namespace devslam::nav {

namespace {
constexpr double kSqrt2 = 1.4142135623730951;
constexpr float kNoObstacle = 1e6f;

std::string fmtPoint(const mrpt::math::TPoint2D& p) {
    std::ostringstream os;
    os << "(" << p.x << ", " << p.y << ")";
    return os.str();
}
}  // namespace

void GridPlannerOptions::loadFromConfigFile(const mrpt::config::CConfigFileBase& c,
                                            const std::string& s, const std::string& source) {
    core::requireKnownKeys(
        c, s,
        {"robot_radius", "inflation_margin", "inflation_penalty", "clearance_distance",
         "clearance_weight", "occupied_threshold", "waypoint_spacing"},
        source);
    robot_radius = core::readDouble(c, s, "robot_radius", robot_radius);
    inflation_margin = core::readDouble(c, s, "inflation_margin", inflation_margin);
    inflation_penalty = core::readDouble(c, s, "inflation_penalty", inflation_penalty);
    clearance_distance = core::readDouble(c, s, "clearance_distance", clearance_distance);
    clearance_weight = core::readDouble(c, s, "clearance_weight", clearance_weight);
    occupied_threshold = core::readDouble(c, s, "occupied_threshold", occupied_threshold);
    waypoint_spacing = core::readDouble(c, s, "waypoint_spacing", waypoint_spacing);
    validate();
}

void GridPlannerOptions::saveToConfigFile(mrpt::config::CConfigFileBase& c,
                                          const std::string& s) const {
    core::writeKey(c, s, "robot_radius", robot_radius);
    core::writeKey(c, s, "inflation_margin", inflation_margin);
    core::writeKey(c, s, "inflation_penalty", inflation_penalty);
    core::writeKey(c, s, "clearance_distance", clearance_distance);
    core::writeKey(c, s, "clearance_weight", clearance_weight);
    core::writeKey(c, s, "occupied_threshold", occupied_threshold);
    core::writeKey(c, s, "waypoint_spacing", waypoint_spacing);
}

void GridPlannerOptions::validate() const {
    core::requireValue(robot_radius > 0, "global_planner", "robot_radius", "must be > 0 m");
    core::requireValue(inflation_margin >= 0, "global_planner", "inflation_margin",
                       "must be >= 0 m");
    core::requireValue(inflation_penalty >= 1, "global_planner", "inflation_penalty",
                       "must be >= 1");
    core::requireValue(clearance_distance >= 0, "global_planner", "clearance_distance",
                       "must be >= 0 m");
    core::requireValue(clearance_weight >= 0, "global_planner", "clearance_weight", "must be >= 0");
    core::requireValue(occupied_threshold > 0 && occupied_threshold < 1, "global_planner",
                       "occupied_threshold", "must be in (0, 1)");
    core::requireValue(waypoint_spacing > 0, "global_planner", "waypoint_spacing", "must be > 0 m");
}

const char* toString(EndpointStatus s) {
    switch (s) {
        case EndpointStatus::Ok:
            return "ok";
        case EndpointStatus::OutsideMap:
            return "outside the map";
        case EndpointStatus::InsideObstacle:
            return "inside an obstacle";
        case EndpointStatus::TooCloseToObstacle:
            return "closer to an obstacle than the robot radius";
    }
    return "?";
}

GridPlanner::GridPlanner(GridPlannerOptions opts) : opts_(opts) {
    opts_.validate();
}

void GridPlanner::setMap(const mrpt::maps::COccupancyGridMap2D& grid) {
    grid_ = grid;
    w_ = static_cast<int>(grid_.getSizeX());
    h_ = static_cast<int>(grid_.getSizeY());
    if (w_ <= 0 || h_ <= 0) throw std::invalid_argument("GridPlanner::setMap: empty grid");
    cv::Mat free_mask(h_, w_, CV_8UC1);
    bool any_obstacle = false;
    for (int y = 0; y < h_; y++)
        for (int x = 0; x < w_; x++) {
            const bool occ = grid_.getCell(x, y) < opts_.occupied_threshold;
            free_mask.at<uint8_t>(y, x) = occ ? 0 : 255;
            any_obstacle |= occ;
        }
    clearance_.assign(static_cast<size_t>(w_) * h_, kNoObstacle);
    mult_.assign(clearance_.size(), 1.0f);
    if (!any_obstacle) return;
    cv::Mat dist;
    cv::distanceTransform(free_mask, dist, cv::DIST_L2, cv::DIST_MASK_PRECISE);
    const float res = grid_.getResolution();
    for (int y = 0; y < h_; y++)
        for (int x = 0; x < w_; x++) {
            const float d = dist.at<float>(y, x);
            // distance between cell centres minus half a cell = distance to the cell edge
            clearance_[x + y * w_] = d <= 0 ? 0.f : std::max(0.f, (d - 0.5f) * res);
        }
    for (size_t i = 0; i < clearance_.size(); i++)
        mult_[i] = static_cast<float>(stepMultiplier(static_cast<int>(i)));
}

double GridPlanner::clearance(const mrpt::math::TPoint2D& p) const {
    const int x = grid_.x2idx(p.x), y = grid_.y2idx(p.y);
    if (x < 0 || y < 0 || x >= w_ || y >= h_) return 0.0;
    return clearance_[x + y * w_];
}

std::optional<mrpt::math::TPoint2D> GridPlanner::nearestTraversable(const mrpt::math::TPoint2D& p,
                                                                    double max_dist) const {
    if (w_ == 0) throw std::logic_error("GridPlanner: setMap() was not called");
    const int px = grid_.x2idx(p.x), py = grid_.y2idx(p.y);
    if (px < 0 || py < 0 || px >= w_ || py >= h_) return std::nullopt;
    if (clearance_[px + py * w_] >= opts_.robot_radius) return p;
    const double res = grid_.getResolution();
    const int r = static_cast<int>(std::ceil(max_dist / res));
    std::optional<mrpt::math::TPoint2D> best;
    double best_d = max_dist;
    for (int y = std::max(0, py - r); y <= std::min(h_ - 1, py + r); y++)
        for (int x = std::max(0, px - r); x <= std::min(w_ - 1, px + r); x++) {
            if (clearance_[x + y * w_] < opts_.robot_radius) continue;
            const mrpt::math::TPoint2D c{grid_.idx2x(x), grid_.idx2y(y)};
            const double d = std::hypot(c.x - p.x, c.y - p.y);
            if (d <= best_d) {
                best_d = d;
                best = c;
            }
        }
    return best;
}

EndpointStatus GridPlanner::checkEndpoint(const mrpt::math::TPoint2D& p) const {
    if (w_ == 0) throw std::logic_error("GridPlanner: setMap() was not called");
    if (p.x < grid_.getXMin() || p.x >= grid_.getXMax() || p.y < grid_.getYMin() ||
        p.y >= grid_.getYMax())
        return EndpointStatus::OutsideMap;
    const double c = clearance(p);
    if (c <= 0) return EndpointStatus::InsideObstacle;
    if (c < opts_.robot_radius) return EndpointStatus::TooCloseToObstacle;
    return EndpointStatus::Ok;
}

double GridPlanner::stepMultiplier(int idx) const {
    const double c = clearance_[idx];
    const double lethal = opts_.robot_radius;
    const double inflated = lethal + opts_.inflation_margin;
    if (c < lethal) return -1.0;  // not traversable
    if (c < inflated) return opts_.inflation_penalty;
    if (opts_.clearance_distance <= 0 || c >= inflated + opts_.clearance_distance) return 1.0;
    const double u = 1.0 - (c - inflated) / opts_.clearance_distance;
    return 1.0 + opts_.clearance_weight * u * u;
}

std::optional<GridPath> GridPlanner::plan(const mrpt::math::TPoint2D& start,
                                          const mrpt::math::TPoint2D& goal) const {
    for (const auto& [name, p] : {std::pair{"start", start}, std::pair{"goal", goal}}) {
        const EndpointStatus st = checkEndpoint(p);
        if (st != EndpointStatus::Ok) {
            std::ostringstream os;
            os << "global planner: " << name << " " << fmtPoint(p) << " is " << toString(st);
            if (st != EndpointStatus::OutsideMap)
                os << " (clearance " << clearance(p) << " m on its " << grid_.getResolution()
                   << " m grid, robot radius " << opts_.robot_radius << " m)";
            else
                os << " [" << grid_.getXMin() << ", " << grid_.getXMax() << "] x ["
                   << grid_.getYMin() << ", " << grid_.getYMax() << "]";
            throw PlanningError(os.str(), st);
        }
    }
    const int sx = grid_.x2idx(start.x), sy = grid_.y2idx(start.y);
    const int tx = grid_.x2idx(goal.x), ty = grid_.y2idx(goal.y);
    const int s_idx = sx + sy * w_, t_idx = tx + ty * w_;
    const double res = grid_.getResolution();
    auto heuristic = [&](int x, int y) {  // octile distance, admissible (multiplier >= 1)
        const int dx = std::abs(x - tx), dy = std::abs(y - ty);
        return res * (std::max(dx, dy) + (kSqrt2 - 1.0) * std::min(dx, dy));
    };
    const size_t n = static_cast<size_t>(w_) * h_;
    std::vector<double> g(n, std::numeric_limits<double>::infinity());
    std::vector<int> parent(n, -1);
    std::vector<uint8_t> closed(n, 0);
    using Entry = std::pair<double, int>;
    std::priority_queue<Entry, std::vector<Entry>, std::greater<>> open;
    g[s_idx] = 0;
    open.emplace(heuristic(sx, sy), s_idx);
    GridPath out;
    bool found = false;
    while (!open.empty()) {
        const int cur = open.top().second;
        open.pop();
        if (closed[cur]) continue;
        closed[cur] = 1;
        out.expanded++;
        if (cur == t_idx) {
            found = true;
            break;
        }
        const int cx = cur % w_, cy = cur / w_;
        for (int dy = -1; dy <= 1; dy++)
            for (int dx = -1; dx <= 1; dx++) {
                if (dx == 0 && dy == 0) continue;
                const int nx = cx + dx, ny = cy + dy;
                if (nx < 0 || ny < 0 || nx >= w_ || ny >= h_) continue;
                const int ni = nx + ny * w_;
                if (closed[ni]) continue;
                const double mult = mult_[ni];
                if (mult < 0) continue;
                // no corner cutting: both orthogonal neighbours must be traversable
                if (dx != 0 && dy != 0 && (mult_[cx + dx + cy * w_] < 0 || mult_[cx + ny * w_] < 0))
                    continue;
                const double step = res * ((dx != 0 && dy != 0) ? kSqrt2 : 1.0);
                const double ng = g[cur] + step * 0.5 * (mult + std::max(1.0f, mult_[cur]));
                if (ng < g[ni]) {
                    g[ni] = ng;
                    parent[ni] = cur;
                    open.emplace(ng + heuristic(nx, ny), ni);
                }
            }
    }
    if (!found) return std::nullopt;
    for (int c = t_idx; c != -1; c = parent[c])
        out.points.emplace_back(grid_.idx2x(c % w_), grid_.idx2y(c / w_));
    std::reverse(out.points.begin(), out.points.end());
    // exact endpoints instead of cell centres (start and goal in one cell: both of them)
    if (out.points.size() == 1) out.points.push_back(goal);
    out.points.front() = start;
    out.points.back() = goal;
    out.cost = g[t_idx];
    out.length = polylineLength(out.points);
    return out;
}

bool GridPlanner::segmentClear(const mrpt::math::TPoint2D& a, const mrpt::math::TPoint2D& b,
                               double min_clearance) const {
    const double len = std::hypot(b.x - a.x, b.y - a.y);
    const double step = 0.5 * grid_.getResolution();
    const int n = std::max(1, static_cast<int>(std::ceil(len / step)));
    for (int i = 0; i <= n; i++) {
        const double t = static_cast<double>(i) / n;
        const mrpt::math::TPoint2D p(a.x + t * (b.x - a.x), a.y + t * (b.y - a.y));
        if (checkEndpoint(p) == EndpointStatus::OutsideMap) return false;
        if (clearance(p) + 1e-9 < min_clearance) return false;
    }
    return true;
}

std::vector<std::size_t> decimateWaypointIndices(const GridPlanner& planner, const GridPath& path,
                                                 double max_spacing) {
    if (max_spacing <= 0) throw std::invalid_argument("decimateWaypoints: max_spacing <= 0");
    std::vector<std::size_t> out;
    const auto& p = path.points;
    if (p.size() < 2) {
        for (std::size_t i = 0; i < p.size(); i++) out.push_back(i);
        return out;
    }
    const auto& o = planner.options();
    const double wanted = o.robot_radius + o.inflation_margin;
    size_t anchor = 0;
    while (anchor + 1 < p.size()) {
        size_t best = anchor + 1;
        double path_min = std::min(planner.clearance(p[anchor]), planner.clearance(p[anchor + 1]));
        for (size_t j = anchor + 1; j < p.size(); j++) {
            path_min = std::min(path_min, static_cast<double>(planner.clearance(p[j])));
            const double d = std::hypot(p[j].x - p[anchor].x, p[j].y - p[anchor].y);
            if (d > max_spacing) break;
            const double need = std::max(o.robot_radius, std::min(wanted, path_min));
            if (planner.segmentClear(p[anchor], p[j], need)) best = j;
        }
        out.push_back(best);
        anchor = best;
    }
    return out;
}

std::vector<mrpt::math::TPoint2D> decimateWaypoints(const GridPlanner& planner,
                                                    const GridPath& path, double max_spacing) {
    std::vector<mrpt::math::TPoint2D> out;
    for (const std::size_t i : decimateWaypointIndices(planner, path, max_spacing))
        out.push_back(path.points[i]);
    return out;
}

double polylineLength(const std::vector<mrpt::math::TPoint2D>& pts) {
    double len = 0;
    for (size_t i = 1; i < pts.size(); i++)
        len += std::hypot(pts[i].x - pts[i - 1].x, pts[i].y - pts[i - 1].y);
    return len;
}

}  // namespace devslam::nav
