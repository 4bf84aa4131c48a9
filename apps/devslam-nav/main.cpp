// devslam-nav WORLD.ini: one closed-loop navigation run in the Bullet world.
// Prints one result line, writes a PNG (map, A* path, trajectory, people tracks) and,
// with --navlog, MRPT's .reactivenavlog (open it with MRPT's navlog-viewer).
// devslam-nav --map GRIDMAP --to X,Y: the global route on a map devslam-run built.
#include <devslam/core/Config.h>
#include <devslam/core/GzFile.h>
#include <devslam/core/Interrupt.h>
#include <devslam/core/Parse.h>
#include <devslam/core/Results.h>
#include <devslam/nav/CHolonomicVFHPlus.h>
#include <devslam/nav/MapPlan.h>
#include <devslam/nav/Navigator.h>
#include <devslam/sim/Episode.h>
#include <devslam/sim/RandomWorlds.h>

#include <mrpt/system/filesystem.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <optional>
#include <string>

namespace {
/// A world file, or "random:CATEGORY:SEED" for one of the benchmark's generated worlds.
devslam::sim::WorldSpec loadOrGenerate(const std::string& spec) {
    const std::string prefix = "random:";
    if (spec.rfind(prefix, 0) != 0) return devslam::sim::loadWorld(spec);
    const auto colon = spec.rfind(':');
    const std::string cat = spec.substr(prefix.size(), colon - prefix.size());
    const auto c = devslam::sim::categoryNamed(cat);
    if (!c)
        throw std::invalid_argument("unknown random world category '" + cat +
                                    "' (known: " + devslam::sim::categoryNames() + ")");
    return devslam::sim::randomWorld(
        *c, static_cast<uint32_t>(devslam::core::parseInteger(
                spec.substr(colon + 1), "random world seed in '" + spec + "'", 0, UINT32_MAX)));
}

/// "X,Y" [m].
mrpt::math::TPoint2D parsePoint(const std::string& text, const std::string& what) {
    const auto comma = text.find(',');
    if (comma == std::string::npos)
        throw std::invalid_argument(what + ": expected X,Y in metres, got '" + text + "'");
    return {devslam::core::parseNumber(text.substr(0, comma), what + " x"),
            devslam::core::parseNumber(text.substr(comma + 1), what + " y")};
}

/// Pictures go here unless --png says otherwise (out/ is ignored by git, as devslam-run's).
const std::string kDefaultDir = "out/devslam-nav";

void makeParentDirectory(const std::string& file) {
    const auto parent = std::filesystem::path(file).parent_path();
    if (!parent.empty()) std::filesystem::create_directories(parent);
}

/// Runs `write` (a picture into `png`, after its folder is made); an error names --png and
/// the file, and is thrown after the result was printed, so that it loses nothing.
template <class Write>
void writePicture(const std::string& png, Write&& write) {
    try {
        makeParentDirectory(png);
        write();
    } catch (const std::exception& e) {
        throw std::runtime_error("--png '" + png + "': cannot write the picture: " +
                                 devslam::core::innermostMessage(e.what()));
    }
}

/// A clearance for the result line: "none" where none was measured (nothing of that kind in
/// the world, no step driven, a map without an obstacle), not the placeholder it holds then
/// (EpisodeResult's 1e9 m, the planner's 1e6 m); worlds lie within +-1e4 m.
std::string clearanceText(double v) {
    if (v >= 1e5) return "none";
    char text[32];
    std::snprintf(text, sizeof text, "%.3f m", v);
    return text;
}

/// devslam-nav --map: A* and waypoints on a SLAM grid, one result line and a picture.
int planOnSlamMap(const std::string& map, const std::string& from, const std::string& to,
                  const std::string& config, std::string png) {
    if (to.empty()) throw std::invalid_argument("--map needs --to X,Y (the goal, in metres)");
    const auto ini = devslam::core::loadIni(config);
    auto opts = devslam::nav::NavigatorOptions::fromConfig(*ini, config).planner;
    // The waypoints as the navigator would get them (its spacing was not capped here).
    opts.waypoint_spacing = devslam::core::namingSource(config, [&] {
        return devslam::nav::waypointSpacing(opts.waypoint_spacing,
                                             devslam::nav::refDistanceOf(*ini));
    });
    const auto grid = devslam::nav::loadGridMap(map);
    const auto start = parsePoint(from, "--from"), goal = parsePoint(to, "--to");
    // The planner's refusal names its "start" or "goal": said as the options and the map
    // file ("global planner: goal (100, 0) is outside the map ..." named neither).
    const auto plan = [&] {
        try {
            return devslam::nav::planOnMap(grid, start, goal, opts);
        } catch (const devslam::nav::PlanningError& e) {
            throw std::invalid_argument(map + ", --from " + from + " --to " + to + ": " + e.what());
        }
    }();
    if (png.empty()) png = kDefaultDir + "/plan.png";
    std::printf("map=%s from=(%.2f, %.2f) to=(%.2f, %.2f) ", map.c_str(), plan.from.x,
                plan.from.y, plan.to.x, plan.to.y);
    if (!plan.path) {
        std::printf("result=no_path png=%s\n", png.c_str());
    } else {
        std::printf(
            "result=path length=%.2f m waypoints=%zu min_clearance=%s "
            "unknown=%.0f%% png=%s\n",
            plan.path->length, plan.waypoints.size(), clearanceText(plan.min_clearance).c_str(),
            100.0 * plan.unknown_fraction, png.c_str());
        for (const auto& w : plan.waypoints) std::printf("waypoint %.2f %.2f\n", w.x, w.y);
    }
    std::fflush(stdout);
    writePicture(png, [&] {
        devslam::nav::writeMapPlanPng(grid, plan, png,
                                      std::filesystem::path(map).filename().string());
    });
    return plan.path ? 0 : 1;
}

/// On std::cout when asked for (--help), on std::cerr after a bad command line.
void usage(std::ostream& os = std::cerr) {
    os << "usage: devslam-nav WORLD.ini|random:CATEGORY:SEED [options]\n"
          "  --config FILE   navigation INI (default config_ini/nav_reactive.ini)\n"
          "  --method NAME   holonomic method: CHolonomicVFHPlus, CHolonomicND,\n"
          "                  CHolonomicVFF, CHolonomicFullEval (default: the INI's\n"
          "                  [navigator] holonomic_method)\n"
          "  --png FILE      picture of the run (default out/devslam-nav/nav_<world>.png)\n"
          "  --navlog DIR    also write MRPT's navlog into DIR\n"
          "  --verbose       MRPT navigator messages (DEBUG level)\n"
          "  --max-speed V   [m/s] the robot's top speed: the world's [robot] max_v, the\n"
          "                  INI's robotMax_V_mps and each PTG that ran at the old one\n"
          "       devslam-nav --map GRIDMAP --to X,Y [--from X,Y] [--config FILE] [--png FILE]\n"
          "  the global route (A* and waypoints, [global_planner] of --config) on a map\n"
          "  devslam-run built (its map_grid.gridmap: x forward, y left, metres, the\n"
          "  camera's start at 0,0, the default --from); picture in --png\n"
          "  (default out/devslam-nav/plan.png)\n";
}
}  // namespace

static int appMain(int argc, char** argv) {
    std::string world_path, png, navlog, map, from = "0,0", to;
    std::string config = std::string(DEVSLAM_SOURCE_DIR) + "/config_ini/nav_reactive.ini";
    std::string method;  // empty: the INI's [navigator] holonomic_method
    bool verbose = false;
    bool from_given = false;
    std::optional<double> max_speed;  // [m/s] over the world's and the INI's
    const auto refuse = [](const std::exception& e) {
        std::cerr << "devslam-nav: " << e.what() << "\n";
        usage();
        return 2;
    };
    try {
        devslam::core::refuseRepeatedOptions(argc, argv);
    } catch (const std::exception& e) {
        return refuse(e);
    }
    for (int i = 1; i < argc; i++) {
        const std::string a = argv[i];
        // An empty value (a script's unset variable) was taken as no option: --png '' wrote
        // the default picture, --navlog '' no navlog, --map '' beside a world was dropped.
        auto next = [&] {
            std::string v = devslam::core::optionValue(argc, argv, i);
            if (v.empty()) throw std::invalid_argument(a + " is empty");
            return v;
        };
        try {
            if (a == "--config")
                config = next();
            else if (a == "--method")
                method = next();
            else if (a == "--png")
                png = next();
            else if (a == "--navlog")
                navlog = next();
            else if (a == "--verbose")
                verbose = true;
            else if (a == "--max-speed") {
                max_speed = devslam::core::parseNumber(next(), "--max-speed");
                devslam::nav::requireTopSpeed(*max_speed);
            } else if (a == "--map")
                map = next();
            else if (a == "--from") {
                from = next();
                from_given = true;
            } else if (a == "--to")
                to = next();
            else if (a == "-h" || a == "--help") {
                usage(std::cout);
                return 0;
            } else if (!a.empty() && a[0] == '-')
                throw std::invalid_argument("unknown option " + a);
            else if (world_path.empty())
                world_path = a;
            else
                throw std::invalid_argument("more than one world file given");
        } catch (const std::exception& e) {
            return refuse(e);
        }
    }
    if (!map.empty() && !world_path.empty()) {
        std::cerr << "devslam-nav: give a world or --map, not both\n";
        return 2;
    }
    // --map plans only (no robot drives): these were ignored without a word.
    if (!map.empty())
        for (const auto& [given, option] : {std::pair{!method.empty(), "--method"},
                                            {!navlog.empty(), "--navlog"},
                                            {verbose, "--verbose"},
                                            {max_speed.has_value(), "--max-speed"}})
            if (given) {
                std::cerr << "devslam-nav: " << option
                          << " does not go with --map, which plans a path and drives no robot\n";
                return 2;
            }
    // A world file has its own start and goal: --from and --to were ignored without a word.
    if (map.empty() && (from_given || !to.empty())) {
        std::cerr << "devslam-nav: " << (from_given ? "--from" : "--to")
                  << " needs --map (a world file has its own start and goal)\n";
        return 2;
    }
    if (map.empty() && world_path.empty()) {
        usage();
        return 2;
    }
    try {
        // Known before minutes of work: the picture's format (OpenCV picks it by the name), and
        // a folder it cannot go in (found after the run, its result line naming it).
        if (!png.empty() && !devslam::core::endsWithNoCase(png, ".png"))
            throw std::invalid_argument("--png '" + png + "': the picture's name must end in .png");
        if (!png.empty()) {
            const auto parent = std::filesystem::absolute(png).parent_path();
            const auto up = devslam::core::nearestExisting(parent.string());
            if (!std::filesystem::is_directory(up) || !devslam::core::canMakeFilesIn(up))
                throw std::invalid_argument("--png '" + png + "': cannot write in '" + up.string() +
                                            "'");
        }
        if (!map.empty()) return planOnSlamMap(map, from, to, config, png);
        if (!method.empty()) devslam::nav::requireHolonomicMethod(method, "--method");
        auto world = loadOrGenerate(world_path);
        const auto ini = devslam::core::loadIni(config);
        auto nav_opts = devslam::nav::NavigatorOptions::fromConfig(*ini, config);
        if (max_speed) {  // the robot's, and what MRPT commands and predicts
            world.robot.max_v = *max_speed;
            devslam::nav::setTopSpeed(*ini, *max_speed);
            nav_opts.source += " with --max-speed " + devslam::core::shortestReal(*max_speed);
        }
        nav_opts.verbose = verbose;
        devslam::sim::EpisodeOptions eo;
        eo.holonomic_method = method;
        if (!navlog.empty()) {  // over the INI's [navigator] log_file / log_directory
            // Made here, so that its error names --navlog, not the INI's log_directory.
            std::error_code ec;
            std::filesystem::create_directories(navlog, ec);
            if (!std::filesystem::is_directory(navlog))
                throw std::invalid_argument("--navlog '" + navlog + "': cannot make that folder" +
                                            (ec ? ": " + ec.message() : std::string()));
            nav_opts.log_file = true;
            nav_opts.log_directory = navlog;
        }
        // A line every 5 s of wall time (none for a run shorter than that): a long world
        // (a timeout of hours, thousands of people) ran for minutes without a word.
        const auto wall_start = std::chrono::steady_clock::now();
        auto next_line = wall_start + std::chrono::seconds(5);
        eo.on_step = [&](double t, double to_goal) {
            const auto now = std::chrono::steady_clock::now();
            if (now < next_line) return;
            next_line = now + std::chrono::seconds(5);
            std::fprintf(
                stderr, "devslam-nav: %.0f of %.0f s simulated (%.0f s wall), %.2f m to the goal\n",
                t, world.timeout, std::chrono::duration<double>(now - wall_start).count(), to_goal);
        };
        // Ctrl-C ends the run where it is, with its result line and picture (it left
        // neither), then the program ends by the signal.
        devslam::core::installStopHandler("devslam-nav");
        eo.stop = [] { return devslam::core::stopSignal() != 0; };
        eo.check_ptg_domains = true;
        const auto r = devslam::sim::runEpisode(world, *ini, nav_opts, eo);
        // Speed limits other than the shipped ones can leave targets near the robot that no
        // PTG reaches, where MRPT stops for good ("no way found"): said, before the result.
        if (!r.ptg_domain_gaps.empty()) {
            std::cerr << "devslam-nav: warning: with " << config << "'s PTGs";
            if (max_speed) std::cerr << " at --max-speed " << *max_speed << " m/s";
            std::cerr << ", " << devslam::nav::describePtgDomainGaps(r.ptg_domain_gaps) << "\n";
        }
        if (png.empty()) png = kDefaultDir + "/nav_" + world.name + ".png";
        // The result first: a picture that cannot be written must not lose it.
        std::printf(
            "world=%s method=%s result=%s time=%.2f s path=%.2f m astar=%.2f m "
            "min_clearance_static=%s min_clearance_people=%s collisions_static=%d "
            "collisions_people=%d replans=%d guard_slowed=%zu/%zu png=%s%s%s\n",
            world.name.c_str(), r.holonomic_method.c_str(), devslam::sim::toString(r.outcome),
            r.time, r.path_length, r.astar_length, clearanceText(r.min_clearance_static).c_str(),
            clearanceText(r.min_clearance_people).c_str(), r.static_collisions, r.person_collisions,
            r.replans, r.guard.slowed, r.guard.commands, png.c_str(),
            r.navlog.empty() ? "" : " navlog=", r.navlog.c_str());
        if (!r.reason.empty()) std::printf("reason: %s\n", r.reason.c_str());
        std::fflush(stdout);
        writePicture(png, [&] {
            devslam::sim::writeEpisodePng(world, r, png, world.name + " / " + r.holonomic_method);
        });
        // A navlog asked for and cut short: the run is whole, its log is not.
        if (!r.navlog_error.empty())
            std::fprintf(stderr, "devslam-nav: %s\n", r.navlog_error.c_str());
        if (const int sig = devslam::core::stopSignal()) devslam::core::exitBySignal(sig);
        if (!r.navlog_error.empty()) return 1;
        return r.outcome == devslam::sim::Outcome::Success ? 0 : 1;
    } catch (const std::exception& e) {
        // MRPT's exceptions carry banners and a stack trace around their message.
        std::cerr << "devslam-nav: " << devslam::core::innermostMessage(e.what()) << "\n";
        // (a picture that could not be written after a Ctrl-C'd run: it still ends by it)
        if (const int sig = devslam::core::stopSignal()) devslam::core::exitBySignal(sig);
        return 2;
    }
}

int main(int argc, char** argv) {
    // Before any file is written (--map's plan too): a write past ulimit -f is reported.
    devslam::core::ignoreFileSizeSignal();
    // The figures go to the standard output: one that cannot be written (a full disk behind
    // '>') lost them while the program said 0.
    return devslam::core::withStandardOutput("devslam-nav", appMain(argc, argv));
}
