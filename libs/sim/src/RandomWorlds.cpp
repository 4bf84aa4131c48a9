#include <devslam/sim/RandomWorlds.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

namespace devslam::sim {

const char* toString(Category c) {
    switch (c) {
        case Category::OpenClutter:
            return "open_clutter";
        case Category::CorridorPeople:
            return "corridor_people";
        case Category::Office:
            return "office";
        case Category::ObstacleNearGoal:
            return "obstacle_near_goal";
    }
    return "?";
}

std::vector<Category> allCategories() {
    return {Category::OpenClutter, Category::CorridorPeople, Category::Office,
            Category::ObstacleNearGoal};
}

std::optional<Category> categoryNamed(const std::string& name) {
    for (const auto c : allCategories())
        if (name == toString(c)) return c;
    return std::nullopt;
}

std::string categoryNames() {
    std::string s;
    for (const auto c : allCategories()) s += (s.empty() ? "" : ", ") + std::string(toString(c));
    return s;
}

bool hasPeople(Category c) {
    return c == Category::CorridorPeople;
}

namespace {
using Rng = std::mt19937;
double uni(Rng& g, double a, double b) {
    return std::uniform_real_distribution<double>(a, b)(g);
}
int uniInt(Rng& g, int a, int b) {
    return std::uniform_int_distribution<int>(a, b)(g);
}

Obstacle box(const std::string& name, const std::string& kind, double cx, double cy, double sx,
             double sy, double yaw) {
    Obstacle o;
    o.name = name;
    o.kind = kind;
    o.cx = cx;
    o.cy = cy;
    o.sx = sx;
    o.sy = sy;
    o.yaw = yaw;
    o.height = kind == "block" ? 0.4 : 1.0;
    return o;
}

Obstacle cylinder(const std::string& name, double cx, double cy, double r) {
    Obstacle o;
    o.name = name;
    o.kind = "cylinder";
    o.shape = Obstacle::Shape::Cylinder;
    o.cx = cx;
    o.cy = cy;
    o.radius = r;
    return o;
}

bool farFrom(const Obstacle& o, const mrpt::math::TPoint2D& p, double d) {
    return distanceToObstacle(o, p) > d;
}

void scatter(WorldSpec& w, Rng& g, int count, double x0, double x1, double y0, double y1,
             double keep_out) {
    const mrpt::math::TPoint2D s(w.robot.start.x, w.robot.start.y);
    for (int i = 0, tries = 0; i < count && tries < 500; tries++) {
        Obstacle o;
        const std::string name = "clutter_" + std::to_string(i);
        const double cx = uni(g, x0, x1), cy = uni(g, y0, y1);
        const int kind = uniInt(g, 0, 2);
        if (kind == 0)
            o = box(name, "box", cx, cy, uni(g, 0.3, 0.9), uni(g, 0.3, 0.9), uni(g, 0, M_PI));
        else if (kind == 1)
            o = box(name, "block", cx, cy, uni(g, 0.2, 0.6), uni(g, 0.15, 0.3), uni(g, 0, M_PI));
        else
            o = cylinder(name, cx, cy, uni(g, 0.12, 0.35));
        if (!farFrom(o, s, keep_out) || !farFrom(o, w.goal, keep_out)) continue;
        w.obstacles.push_back(o);
        i++;
    }
}

WorldSpec base(const std::string& name, double x_max, double y_max, double timeout) {
    WorldSpec w;
    w.name = name;
    w.x_min = 0;
    w.y_min = 0;
    w.x_max = x_max;
    w.y_max = y_max;
    w.timeout = timeout;
    w.laser.rays = 181;
    return w;
}

WorldSpec openClutter(Rng& g) {
    WorldSpec w = base("open_clutter", 10, 8, 60);
    w.robot.start = {1.0, uni(g, 1.5, 6.5), uni(g, -0.5, 0.5)};
    w.goal = {9.0, uni(g, 1.5, 6.5)};
    scatter(w, g, uniInt(g, 10, 16), 2.2, 7.8, 0.5, 7.5, 1.0);
    return w;
}

WorldSpec corridorPeople(Rng& g) {
    WorldSpec w = base("corridor_people", 16, 3.2, 90);
    w.robot.start = {1.0, 1.6, 0.0};
    w.goal = {15.0, uni(g, 1.2, 2.0)};
    // a few objects against the walls (benches, bins)
    for (int i = 0; i < 2; i++) {
        const double cx = uni(g, 4.0, 12.0);
        const bool south = uniInt(g, 0, 1) == 0;
        const double sy = uni(g, 0.3, 0.5);
        w.obstacles.push_back(box("bench_" + std::to_string(i), "box", cx,
                                  south ? 0.1 + sy / 2 : 3.1 - sy / 2, uni(g, 0.6, 1.2), sy, 0));
    }
    const int n = uniInt(g, 3, 5);
    for (int i = 0; i < n; i++) {
        Pedestrian p;
        p.name = "person_" + std::to_string(i);
        p.radius = 0.22;
        p.speed = uni(g, 0.5, 1.0);
        p.start_delay = uni(g, 0.0, 4.0);
        const double y = uni(g, 0.6, 2.6);
        const bool towards = i % 2 == 0;  // half walk toward the robot
        const double xa = uni(g, 4.0, 14.5);
        if (i == n - 1) {
            p.mode = Pedestrian::Mode::RandomWalk;
            p.speed = uni(g, 0.3, 0.6);
            p.path = {{uni(g, 5.0, 12.0), y}};
        } else {
            p.mode = Pedestrian::Mode::Scripted;
            // turn-around points stay 1.5 m clear of the start and the goal: a person who
            // parks on the goal would make the world unsolvable for every method
            p.path = towards ? std::vector<mrpt::math::TPoint2D>{{xa, y}, {2.5, uni(g, 0.6, 2.6)}}
                             : std::vector<mrpt::math::TPoint2D>{{xa - 2.0, y},
                                                                 {13.5, uni(g, 0.6, 2.6)}};
            p.path[0].x = std::clamp(p.path[0].x, 3.0, 13.5);
        }
        w.pedestrians.push_back(p);
    }
    return w;
}

WorldSpec office(Rng& g) {
    WorldSpec w = base("office", 12, 10, 90);
    // partition wall at x = 6 with one door
    const double door_w = uni(g, 1.1, 1.5), door_y = uni(g, 2.0, 8.0);
    const double lo = door_y - door_w / 2, hi = door_y + door_w / 2;
    w.obstacles.push_back(box("partition_s", "wall", 6.0, lo / 2, 0.15, lo, 0));
    w.obstacles.push_back(box("partition_n", "wall", 6.0, (hi + 10.0) / 2, 0.15, 10.0 - hi, 0));
    w.robot.start = {uni(g, 0.8, 1.5), uni(g, 1.0, 9.0), uni(g, -1.0, 1.0)};
    w.goal = {uni(g, 10.0, 11.2), uni(g, 1.0, 9.0)};
    // desks in each room
    for (int room = 0; room < 2; room++) {
        const int nd = uniInt(g, 3, 5);
        for (int i = 0, tries = 0; i < nd && tries < 200; tries++) {
            const double x0 = room == 0 ? 2.2 : 7.2, x1 = room == 0 ? 5.0 : 9.6;
            const bool rot = uniInt(g, 0, 1) == 1;
            Obstacle d = box("desk_" + std::to_string(room) + "_" + std::to_string(i), "box",
                             uni(g, x0, x1), uni(g, 1.0, 9.0), rot ? 0.7 : 1.4, rot ? 1.4 : 0.7, 0);
            if (!farFrom(d, {w.robot.start.x, w.robot.start.y}, 1.0) || !farFrom(d, w.goal, 1.0))
                continue;
            if (!farFrom(d, {6.0, door_y}, 1.2)) continue;  // keep the door usable
            bool overlap = false;
            for (const auto& o : w.obstacles)
                if (distanceToObstacle(o, {d.cx, d.cy}) < 1.3) overlap = true;
            if (overlap) continue;
            w.obstacles.push_back(d);
            i++;
        }
    }
    // a chair (block) near some desks
    w.obstacles.push_back(cylinder("bin", uni(g, 2.5, 4.5), uni(g, 0.5, 9.5), 0.15));
    return w;
}

WorldSpec obstacleNearGoal(Rng& g) {
    WorldSpec w = base("obstacle_near_goal", 10, 8, 60);
    w.robot.start = {1.0, uni(g, 1.5, 6.5), uni(g, -0.5, 0.5)};
    w.goal = {uni(g, 7.5, 8.8), uni(g, 1.5, 6.5)};
    // the obstacle right next to the goal: its surface at radius + [0.05, 0.25] m
    const double gap = w.robot.radius + uni(g, 0.05, 0.25);
    const double side = uni(g, -M_PI, M_PI);
    const double sx = uni(g, 0.5, 1.0), sy = uni(g, 0.3, 0.8);
    const double cx = w.goal.x + (gap + sx / 2) * std::cos(side);
    const double cy = w.goal.y + (gap + sx / 2) * std::sin(side);
    w.obstacles.push_back(
        box("near_goal", uniInt(g, 0, 1) ? "box" : "block", cx, cy, sx, sy, side));
    scatter(w, g, uniInt(g, 4, 8), 2.2, 7.0, 0.5, 7.5, 1.0);
    return w;
}
}  // namespace

WorldSpec randomWorld(Category c, uint32_t seed, const nav::GridPlannerOptions& planner) {
    Rng g(seed * 7919u + static_cast<uint32_t>(c) * 104729u + 17u);
    for (int attempt = 0; attempt < 200; attempt++) {
        WorldSpec w;
        switch (c) {
            case Category::OpenClutter:
                w = openClutter(g);
                break;
            case Category::CorridorPeople:
                w = corridorPeople(g);
                break;
            case Category::Office:
                w = office(g);
                break;
            case Category::ObstacleNearGoal:
                w = obstacleNearGoal(g);
                break;
        }
        w.seed = seed;
        w.name = std::string(toString(c)) + "_" + std::to_string(seed);
        w.source = "random world " + w.name;
        try {
            validateWorld(w);
        } catch (const std::invalid_argument&) {
            continue;
        }
        // Planned as sim::runEpisode will: with the world's robot radius, not the INI's.
        auto po = planner;
        po.robot_radius = w.robot.radius;
        nav::GridPlanner pl(po);
        pl.setMap(rasterize(w));
        try {
            if (pl.plan({w.robot.start.x, w.robot.start.y}, w.goal)) return w;
        } catch (const nav::PlanningError&) {
        }
    }
    throw std::runtime_error(std::string("randomWorld: no valid ") + toString(c) +
                             " world for seed " + std::to_string(seed));
}

std::size_t runEpisodeGrid(
    const std::vector<Category>& categories, int per_category, uint32_t first_seed,
    const std::vector<std::string>& methods, const nav::GridPlannerOptions& planner,
    const std::function<EpisodeResult(const WorldSpec&, const std::string&)>& episode,
    const std::function<void(const GridEpisode&)>& done, const std::function<bool()>& stop) {
    std::size_t n = 0;
    for (std::size_t c = 0; c < categories.size(); c++) {
        for (int i = 0; i < per_category; i++) {
            const uint32_t seed = first_seed + static_cast<uint32_t>(i);
            const std::string where =
                std::string(toString(categories[c])) + " world of seed " + std::to_string(seed);
            WorldSpec world;
            std::string world_error;
            try {
                world = randomWorld(categories[c], seed, planner);
            } catch (const std::exception& e) {
                if (i == 0) throw std::runtime_error(where + ": " + e.what());
                world_error = e.what();
            }
            for (const auto& m : methods) {
                if (stop()) return n;
                GridEpisode g{c, i, m, &world, {}, {}};
                try {
                    if (!world_error.empty()) throw std::runtime_error(world_error);
                    g.result = episode(world, m);
                } catch (const std::exception& e) {
                    if (c == 0 && i == 0)
                        throw std::runtime_error(where + ", " + m +
                                                 " (its first episode): " + e.what());
                    g.error = e.what();
                    g.result = EpisodeResult{};
                    g.result.outcome = Outcome::Error;
                    g.result.reason = g.error;
                    g.result.holonomic_method = m;
                }
                done(g);
                ++n;
            }
        }
    }
    return n;
}

}  // namespace devslam::sim
