// devslam-nav-bench: N seeded random worlds per category (open clutter, corridor with
// people, office, obstacle near goal), the same worlds for every holonomic method, tables
// per category written to the `nav` section of docs/RESULTS.md, plus PNGs. Also times one
// VFH+ step and A* on a 400x400 grid. --quick: a smoke test (2 worlds per category, no
// RESULTS.md unless --results is given). Ctrl-C stops after the current episode and prints the
// tables of the episodes done, leaving RESULTS.md and the pictures as they were.
#include <devslam/core/Config.h>
#include <devslam/core/Interrupt.h>
#include <devslam/core/Parse.h>
#include <devslam/core/Picture.h>
#include <devslam/core/Progress.h>
#include <devslam/core/Results.h>
#include <devslam/core/Stats.h>
#include <devslam/nav/BenchFixtures.h>
#include <devslam/nav/CHolonomicVFHPlus.h>
#include <devslam/nav/GridPlanner.h>
#include <devslam/nav/Navigator.h>
#include <devslam/nav/SpeedGuard.h>
#include <devslam/nav/VfhPlus.h>
#include <devslam/sim/Episode.h>
#include <devslam/sim/RandomWorlds.h>

#include <mrpt/system/filesystem.h>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <iostream>
#include <map>
#include <optional>
#include <random>
#include <sstream>

namespace {
using Clock = std::chrono::steady_clock;

/// Thread CPU time [ms]: the timings below do not depend on how loaded the machine is.
double cpuMs() {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return 1e3 * static_cast<double>(ts.tv_sec) + 1e-6 * static_cast<double>(ts.tv_nsec);
}

struct Args {
    int per_category = 50;
    bool quick = false;
    std::string config = std::string(DEVSLAM_SOURCE_DIR) + "/config_ini/nav_reactive.ini";
    std::string results;  // empty: default unless --quick
    std::string png_dir = std::string(DEVSLAM_SOURCE_DIR) + "/docs/images";
    std::vector<std::string> methods{"CHolonomicVFHPlus", "CHolonomicND", "CHolonomicVFF",
                                     "CHolonomicFullEval"};
    uint32_t seed = 1;
    std::optional<double> person_margin;  ///< [m] overrides [navigator] person_margin
    std::optional<double> person_predict;  ///< [s] overrides [navigator] person_predict_horizon
    std::vector<devslam::sim::Category> categories = devslam::sim::allCategories();
    std::optional<double> max_speed;      ///< [m/s] every world's robot and the INI's PTGs
};

/// "a,b": the --methods value that gives `methods`.
std::string methodList(const std::vector<std::string>& methods) {
    std::string s;
    for (const auto& m : methods) s += (s.empty() ? "" : ",") + m;
    return s;
}

/// "a,b": the --categories value that gives `cats`.
std::string categoryList(const std::vector<devslam::sim::Category>& cats) {
    std::string s;
    for (const auto c : cats) s += (s.empty() ? "" : ",") + std::string(devslam::sim::toString(c));
    return s;
}

/// On std::cout when asked for (--help), on std::cerr after a bad command line.
void usage(std::ostream& os = std::cerr) {
    os << "usage: devslam-nav-bench [options]\n"
          "  --per-category N  worlds per category (default 50 -> 200 worlds)\n"
          "  --quick           smoke test: 2 worlds per category, RESULTS.md untouched,\n"
          "                    pictures in out/devslam-nav-bench unless --png-dir\n"
          "  --methods a,b     holonomic methods (default all four)\n"
          "  --config FILE     navigation INI (default config_ini/nav_reactive.ini)\n"
          "  --results FILE    RESULTS.md to update (default docs/RESULTS.md; none: no file)\n"
          "  --png-dir DIR     where PNGs go (default docs/images)\n"
          "  --seed S          first world seed (default 1)\n"
          "  --person-margin M [m] overrides the INI's [navigator] person_margin\n"
          "  --person-predict H\n"
          "                    [s] overrides the INI's [navigator] person_predict_horizon\n"
          "  --categories a,b  only these categories (open_clutter, corridor_people, office,\n"
          "                    obstacle_near_goal; default all)\n"
          "  --max-speed V     [m/s] the robot's top speed: every world's [robot] max_v, the\n"
          "                    INI's robotMax_V_mps and each PTG<i>_v_max_mps equal to it\n";
}

struct Tally {
    int n = 0, success = 0, collision = 0, static_collision = 0, person_collision = 0, timeout = 0;
    int no_run = 0;  ///< no path at the start, or a navigator error (not timeouts)
    std::vector<double> success_time, ratio, score;
    std::vector<double> people_clearance;  ///< [m] each run's minimum, runs with people
};

/// A guide robot should not pass people closer than this (robot edge to person edge).
constexpr double kPersonalSpace = 0.30;  // [m]

std::string pct(int k, int n) {
    char b[32];
    std::snprintf(b, sizeof b, "%.1f%%", n ? 100.0 * k / n : 0.0);
    return b;
}
std::string num(double v, int prec = 2) {
    char b[32];
    std::snprintf(b, sizeof b, "%.*f", prec, v);
    return b;
}
std::string shortName(const std::string& m) {
    return m.rfind("CHolonomic", 0) == 0 ? m.substr(10) : m;
}

/// Median wall time of vfhPlusStep on synthetic 121-sector fields.
double timeVfhStep() {
    std::mt19937 g(3);
    devslam::nav::VfhPlusOptions o;
    devslam::nav::VfhState st;
    std::vector<double> t;
    for (int i = 0; i < 2000; i++) {
        const devslam::nav::VfhInput in = devslam::nav::randomVfhInput(g);
        const double t0 = cpuMs();
        const auto out = devslam::nav::vfhPlusStep(in, st, o);
        t.push_back(cpuMs() - t0);
        st = out.next;
    }
    return devslam::core::median(t);
}

/// Median A* time on a 400x400 grid (20 m x 20 m at 5 cm) with random boxes, corner to corner.
double timeAStar400(double* length) {
    const auto grid = devslam::nav::clutteredGrid400();
    devslam::nav::GridPlanner planner;
    planner.setMap(grid);
    std::vector<double> t;
    for (int i = 0; i < 15; i++) {
        const double t0 = cpuMs();
        const auto p = planner.plan({0.6, 0.6}, {19.4, 19.4});
        t.push_back(cpuMs() - t0);
        if (p && length) *length = p->length;
    }
    return devslam::core::median(t);
}

void writeChart(const std::string& path, const std::vector<devslam::sim::Category>& cats,
                const std::vector<std::string>& methods,
                const std::map<std::pair<int, std::string>, Tally>& tally) {
    const int W = 900, H = 420, left = 60, bottom = 60, top = 40;
    cv::Mat img(H, W, CV_8UC3, cv::Scalar(255, 255, 255));
    const cv::Scalar colours[] = {{40, 40, 220}, {200, 120, 30}, {60, 160, 60}, {150, 60, 150}};
    const int group_w = (W - left - 20) / static_cast<int>(cats.size());
    const int bar_w = (group_w - 20) / static_cast<int>(methods.size());
    const int plot_h = H - bottom - top;
    for (int p = 0; p <= 100; p += 25) {
        const int y = H - bottom - plot_h * p / 100;
        cv::line(img, {left, y}, {W - 10, y}, cv::Scalar(225, 225, 225), 1);
        cv::putText(img, std::to_string(p) + "%", {8, y + 4}, cv::FONT_HERSHEY_SIMPLEX, 0.4,
                    cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
    }
    for (size_t c = 0; c < cats.size(); c++) {
        const int gx = left + static_cast<int>(c) * group_w + 10;
        for (size_t m = 0; m < methods.size(); m++) {
            const auto it = tally.find({static_cast<int>(c), methods[m]});
            const double rate = it == tally.end() || it->second.n == 0
                                    ? 0.0
                                    : static_cast<double>(it->second.success) / it->second.n;
            const int x = gx + static_cast<int>(m) * bar_w;
            const int h = static_cast<int>(plot_h * rate);
            cv::rectangle(img, {x, H - bottom - h}, {x + bar_w - 4, H - bottom}, colours[m % 4],
                          cv::FILLED);
        }
        cv::putText(img, devslam::sim::toString(cats[c]), {gx, H - bottom + 20},
                    cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
    }
    for (size_t m = 0; m < methods.size(); m++) {
        const int x = left + static_cast<int>(m) * 190;
        cv::rectangle(img, {x, H - 25}, {x + 14, H - 11}, colours[m % 4], cv::FILLED);
        cv::putText(img, shortName(methods[m]), {x + 20, H - 13}, cv::FONT_HERSHEY_SIMPLEX, 0.45,
                    cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
    }
    cv::putText(img, "success rate per category (devslam-nav-bench)", {left, 25},
                cv::FONT_HERSHEY_SIMPLEX, 0.55, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
    devslam::core::writePngWhole(path, img);
}
/// Reads the command line into `a`; the exit code when the program should end here (0 after
/// --help, 2 for a bad argument, said on stderr with the usage).
std::optional<int> parseArgs(int argc, char** argv, Args& a) {
    bool results_given = false, per_category_given = false, png_dir_given = false;
    std::vector<std::string> changed;  // options that make another bench than the published one
    try {
        devslam::core::refuseRepeatedOptions(argc, argv);
        for (int i = 1; i < argc; i++) {
            const std::string s = argv[i];
            auto next = [&] { return devslam::core::optionValue(argc, argv, i); };
            if (s == "--per-category") {
                a.per_category =
                    int(devslam::core::parseInteger(next(), "--per-category", 1, 100000));
                per_category_given = true;
            } else if (s == "--quick")
                a.quick = true;
            else if (s == "--config")
                a.config = next();
            else if (s == "--results") {
                a.results = next();
                if (a.results == "none") a.results.clear();
                results_given = true;
            } else if (s == "--png-dir") {
                a.png_dir = next();
                png_dir_given = true;
            } else if (s == "--person-margin")
                a.person_margin = devslam::core::parseNumber(next(), "--person-margin");
            else if (s == "--person-predict") {
                a.person_predict = devslam::core::parseNumber(next(), "--person-predict");
                if (!(*a.person_predict >= 0 &&
                      *a.person_predict <= devslam::nav::kMaxPersonPredictHorizon))
                    throw std::invalid_argument("--person-predict: must be in [0, 5] s");
            } else if (s == "--categories") {
                a.categories.clear();
                std::stringstream ss(next());
                std::string name;
                while (std::getline(ss, name, ',')) {
                    if (name.empty()) continue;
                    const auto c = devslam::sim::categoryNamed(name);
                    if (!c)
                        throw std::invalid_argument("--categories: unknown category '" + name +
                                                    "' (known: " + devslam::sim::categoryNames() +
                                                    ")");
                    if (std::find(a.categories.begin(), a.categories.end(), *c) !=
                        a.categories.end())
                        throw std::invalid_argument("--categories: '" + name + "' is listed twice");
                    a.categories.push_back(*c);
                }
                if (a.categories.empty()) throw std::invalid_argument("--categories is empty");
                // In the bench's own order: the tables, and whether this is RESULTS.md's bench,
                // do not depend on how the list was written.
                std::sort(a.categories.begin(), a.categories.end());
            } else if (s == "--max-speed") {
                a.max_speed = devslam::core::parseNumber(next(), "--max-speed");
                devslam::nav::requireTopSpeed(*a.max_speed);
            } else if (s == "--seed")
                a.seed = static_cast<uint32_t>(
                    devslam::core::parseInteger(next(), "--seed", 0, UINT32_MAX));
            else if (s == "--methods") {
                a.methods.clear();
                std::stringstream ss(next());
                std::string m;
                while (std::getline(ss, m, ','))
                    if (!m.empty()) {
                        devslam::nav::requireHolonomicMethod(m, "--methods");
                        if (std::find(a.methods.begin(), a.methods.end(), m) != a.methods.end())
                            throw std::invalid_argument("--methods: " + m + " is listed twice");
                        a.methods.push_back(m);
                    }
            } else if (s == "-h" || s == "--help") {
                usage(std::cout);
                return 0;
            } else
                throw std::invalid_argument("unknown option " + s);
        }
        if (a.quick && per_category_given)
            throw std::invalid_argument(
                "--quick runs 2 worlds per category: not with "
                "--per-category");
        if (a.quick) a.per_category = 2;
        // A smoke test leaves the committed pictures alone, as it leaves RESULTS.md.
        if (a.quick && !png_dir_given) a.png_dir = "out/devslam-nav-bench";
        // Found now, not after the whole benchmark has run (the folder was made at the end,
        // without its parents, and "" wrote /nav_bench_*.png).
        if (a.png_dir.empty()) throw std::invalid_argument("--png-dir is empty");
        if (std::filesystem::exists(a.png_dir) && !std::filesystem::is_directory(a.png_dir))
            throw std::invalid_argument("--png-dir '" + a.png_dir + "' is a file, not a folder");
        // Nothing is made yet (a refused run leaves no folder): the nearest folder that is
        // there must take the rest.
        const auto up = devslam::core::nearestExisting(a.png_dir);
        if (!std::filesystem::is_directory(up) || !devslam::core::canMakeFilesIn(up))
            throw std::invalid_argument("--png-dir '" + a.png_dir + "': cannot write in '" +
                                        up.string() + "'");
        if (a.methods.empty()) throw std::invalid_argument("--methods is empty");
    } catch (const std::exception& e) {
        std::cerr << "devslam-nav-bench: " << e.what() << "\n";
        usage();
        return 2;
    }
    // The published section and pictures are the default bench's: a run of 1 world per
    // category replaced its 200-world tables, linking pictures outside the repository.
    // Another bench (by its values: the published command line spelled out is the same
    // bench) writes a results file only when named, and its pictures where the smoke test's go.
    {
        const Args d;
        namespace fs = std::filesystem;
        const auto same = [](const std::string& x, const std::string& y) {
            return fs::weakly_canonical(x) == fs::weakly_canonical(y);
        };
        if (a.per_category != d.per_category) changed.push_back("--per-category");
        if (a.methods != d.methods) changed.push_back("--methods");
        if (!same(a.config, d.config)) changed.push_back("--config");
        if (a.seed != d.seed) changed.push_back("--seed");
        if (a.person_margin) changed.push_back("--person-margin");
        if (a.person_predict) changed.push_back("--person-predict");
        if (a.categories != d.categories) changed.push_back("--categories");
        if (a.max_speed) changed.push_back("--max-speed");
        if (!same(a.png_dir, d.png_dir)) changed.push_back("--png-dir");
    }
    if (!results_given && !a.quick && changed.empty())
        a.results = std::string(DEVSLAM_SOURCE_DIR) + "/docs/RESULTS.md";
    else if (!results_given && !a.quick) {
        std::string list;
        for (const auto& o : changed) list += (list.empty() ? "" : ", ") + o;
        if (!png_dir_given) a.png_dir = "out/devslam-nav-bench";
        std::cerr << "devslam-nav-bench: " << list
                  << " make another bench than docs/RESULTS.md's: the tables are printed only "
                     "(--results FILE writes them), the pictures go to "
                  << a.png_dir << "\n";
    }
    return std::nullopt;
}

/// What the episodes gave: a tally per (category, method), the navigator's step times per
/// method, and the first world of each category with its first method's run, to picture.
struct Episodes {
    struct Picture {
        devslam::sim::WorldSpec world;
        devslam::sim::EpisodeResult run;
        std::string method;
    };
    std::map<std::pair<int, std::string>, Tally> tally;
    std::map<std::string, std::vector<double>> step_ms;
    std::map<std::string, devslam::nav::SpeedGuardStats> guard;  ///< summed per method
    std::vector<Picture> pictures;
    std::size_t total = 0, done = 0;
    double sim_seconds = 0, wall = 0;  ///< [s]
    int stopped = 0;                   ///< the signal that stopped them (Ctrl-C), else 0
    std::vector<std::string> errors;   ///< "world / method: message" of each episode that threw
    std::size_t navlogs_cut = 0;       ///< episodes whose navlog ([navigator] log_file) is cut
    std::string first_navlog_error;    ///< the first of them's (nav::Navigator::closeLog)
    /// (category c, method m)'s tally; an empty one where none ran.
    [[nodiscard]] const Tally& of(std::size_t c, const std::string& m) const {
        static const Tally none;
        const auto it = tally.find({static_cast<int>(c), m});
        return it == tally.end() ? none : it->second;
    }
    /// Method m's navigationStep() times [ms]; none where it made no step.
    [[nodiscard]] const std::vector<double>& stepsOf(const std::string& m) const {
        static const std::vector<double> none;
        const auto it = step_ms.find(m);
        return it == step_ms.end() ? none : it->second;
    }
};

/// Adds episode `r` of `world` to `t`.
void count(Tally& t, const devslam::sim::WorldSpec& world, const devslam::sim::EpisodeResult& r) {
    t.n++;
    const double ot = r.astar_length / world.robot.max_v;  // optimal time
    double score = 0;
    switch (r.outcome) {
        case devslam::sim::Outcome::Success:
            t.success++;
            t.success_time.push_back(r.time);
            if (r.astar_length > 0) t.ratio.push_back(r.path_length / r.astar_length);
            score = ot / std::clamp(r.time, ot, 8.0 * ot);
            break;
        case devslam::sim::Outcome::Collision:
            t.collision++;
            break;
        case devslam::sim::Outcome::Timeout:
            t.timeout++;
            break;
        case devslam::sim::Outcome::NoPath:
        case devslam::sim::Outcome::Error:
        case devslam::sim::Outcome::Interrupted:  // (the bench stops between episodes)
            t.no_run++;
            break;
    }
    t.static_collision += r.static_collisions > 0 ? 1 : 0;
    t.person_collision += r.person_collisions > 0 ? 1 : 0;
    t.score.push_back(score);
    // (A run that never started has no closest approach: its 1e9 m would count as one.)
    if (!world.pedestrians.empty() && r.outcome != devslam::sim::Outcome::NoPath)
        t.people_clearance.push_back(r.min_clearance_people);
}

/// Every method on the same seeded worlds of every category, with a progress bar; Ctrl-C
/// stops them before the next episode (Episodes::stopped).
Episodes runEpisodes(const Args& a, const mrpt::config::CConfigFileBase& ini,
                     const devslam::nav::NavigatorOptions& nav_opts,
                     const std::vector<devslam::sim::Category>& cats) {
    Episodes ep;
    ep.total = cats.size() * a.per_category * a.methods.size();
    devslam::core::ProgressBar bar("nav-bench", ep.total);
    const auto t_start = Clock::now();
    // The PTGs come from the INI alone: one episode looks for targets no PTG reaches (about
    // 0.1 s), as devslam-nav does for each run.
    std::atomic_flag domains_checked = ATOMIC_FLAG_INIT;
    // The world as run: with --max-speed its robot's top speed (which the score's optimal
    // time divides by) is that one.
    const auto asRun = [&](devslam::sim::WorldSpec w) {
        if (a.max_speed) w.robot.max_v = *a.max_speed;
        return w;
    };
    devslam::sim::runEpisodeGrid(
        cats, a.per_category, a.seed, a.methods, nav_opts.planner,
        [&](const devslam::sim::WorldSpec& world, const std::string& m) {
            devslam::sim::EpisodeOptions eo;
            eo.holonomic_method = m;
            eo.check_ptg_domains = !domains_checked.test_and_set();
            return devslam::sim::runEpisode(asRun(world), ini, nav_opts, eo);
        },
        [&](const devslam::sim::GridEpisode& g) {
            const auto& r = g.result;
            ep.sim_seconds += r.time;
            count(ep.tally[{static_cast<int>(g.category), g.method}], asRun(*g.world), r);
            for (double s : r.step_seconds) ep.step_ms[g.method].push_back(1e3 * s);
            auto& gs = ep.guard[g.method];
            gs.commands += r.guard.commands;
            gs.slowed += r.guard.slowed;
            gs.stopped += r.guard.stopped;
            gs.by_walkers += r.guard.by_walkers;
            if (g.index == 0 && g.method == a.methods.front())  // pictured after the results
                ep.pictures.push_back({asRun(*g.world), r, g.method});
            // An exception out of the episode, or a run the navigator ended by an error (MRPT
            // refusing a setting mid-run): not results.
            const std::string error = !g.error.empty() ? g.error
                                      : r.outcome == devslam::sim::Outcome::Error ? r.reason
                                                                                 : std::string();
            if (!error.empty())
                ep.errors.push_back(std::string(devslam::sim::toString(cats[g.category])) +
                                    " world " + std::to_string(a.seed + g.index) + " / " +
                                    shortName(g.method) + ": " + error);
            if (!r.navlog_error.empty() && ep.navlogs_cut++ == 0)
                ep.first_navlog_error = r.navlog_error;
            if (!r.ptg_domain_gaps.empty())
                std::cerr << "\ndevslam-nav-bench: warning: with the INI's PTGs, "
                          << devslam::nav::describePtgDomainGaps(r.ptg_domain_gaps) << "\n";
            bar.update(++ep.done, std::string(devslam::sim::toString(cats[g.category])) + " " +
                                      shortName(g.method));
        },
        [&] { return (ep.stopped = devslam::core::stopSignal()) != 0; });
    bar.finish();
    ep.wall = std::chrono::duration<double>(Clock::now() - t_start).count();
    return ep;
}

/// The section's title and how it was measured.
std::string headerMarkdown(const Args& a, const devslam::nav::NavigatorOptions& nav_opts,
                           std::size_t n_categories) {
    std::ostringstream md;
    md << "## Navigation benchmark (`devslam-nav-bench`)\n\n"
       << "Command: `devslam-nav-bench --per-category " << a.per_category << " --seed " << a.seed
       << (a.person_margin ? " --person-margin " + num(*a.person_margin) : std::string())
       << (a.person_predict ? " --person-predict " + num(*a.person_predict) : std::string())
       << (a.max_speed ? " --max-speed " + num(*a.max_speed) : std::string())
       << (a.methods.size() < 4 ? " --methods " + methodList(a.methods) : std::string())
       << (a.categories != devslam::sim::allCategories()
               ? " --categories " + categoryList(a.categories)
               : std::string())
       << (a.quick ? " --quick" : "") << "` (config `"
       << devslam::core::shownPath(a.config, DEVSLAM_SOURCE_DIR) << "`; people get "
       << num(nav_opts.person_margin) << " m more room than walls, `person_margin`"
       << (nav_opts.person_predict_horizon > 0
               ? ", and walkers' paths " + num(nav_opts.person_predict_horizon) +
                     " s ahead are obstacles too, `person_predict_horizon`"
               : std::string())
       << "). " << a.per_category << " seeded random worlds "
       << "per category, " << a.per_category * n_categories
       << " worlds in all, the same worlds for every method; Bullet simulation at 100 Hz, "
          "navigator at 10 Hz, simulated clock. Success: within the goal tolerance before the "
          "timeout without touching anything; a run ends at the first contact. Path ratio = "
          "driven length / A* length, the A* cell path string-pulled (straight shortcuts "
          "that keep its clearance). Score (BARN-style) = success x OT / clip(T, OT, 8 OT) "
          "with OT = A* "
          "length / max speed, averaged over all runs.\n\n";
    return md.str();
}

/// The pictures' folder as the tables link to it: relative to the results file's folder
/// (docs/RESULTS.md -> "images"), or to the working folder when there is none. Written as
/// "images/" whatever --png-dir was, the links of --results elsewhere led nowhere.
std::string imageLink(const Args& a) {
    namespace fs = std::filesystem;
    const fs::path from = a.results.empty()
                              ? fs::current_path()
                              : fs::absolute(a.results).lexically_normal().parent_path();
    const fs::path rel = fs::absolute(a.png_dir).lexically_normal().lexically_relative(from);
    std::string link = rel.empty() ? fs::absolute(a.png_dir).lexically_normal().string()
                                   : rel.generic_string();
    while (link.size() > 1 && link.back() == '/') link.pop_back();
    return link;
}

/// A table per category reached, a row per method that ran there (and its picture, after a
/// whole run).
std::string categoryTables(const Args& a, const std::vector<devslam::sim::Category>& cats,
                           const Episodes& ep) {
    std::ostringstream md;
    for (size_t c = 0; c < cats.size(); c++) {
        // Stopped: a category not reached (its first world's first method did not run).
        if (ep.of(c, a.methods.front()).n == 0) continue;
        const bool people = devslam::sim::hasPeople(cats[c]);
        md << "### " << devslam::sim::toString(cats[c])
           << (people ? " (moving people)" : " (static)") << "\n\n"
           << "| method | success | collision (static / people) | timeout | mean time to goal "
              "(s) | path / A* | score |"
           << (people ? " closest to a person (median / min of runs, m) | runs within " +
                            num(kPersonalSpace) + " m of a person |"
                      : std::string())
           << "\n|---|---|---|---|---|---|---|" << (people ? "---|---|" : "") << "\n";
        for (const auto& m : a.methods) {
            const auto& t = ep.of(c, m);
            if (t.n == 0) continue;  // stopped before this method's first run here
            const auto st = devslam::core::summarize(t.success_time);
            const auto rt = devslam::core::summarize(t.ratio);
            const auto sc = devslam::core::summarize(t.score);
            md << "| " << shortName(m) << " | " << pct(t.success, t.n) << " (" << t.success << "/"
               << t.n << ") | " << pct(t.collision, t.n) << " (" << t.static_collision << " / "
               << t.person_collision << ") | " << pct(t.timeout, t.n)
               << (t.no_run > 0 ? " (+" + std::to_string(t.no_run) + " no path or error)" : "")
               << " | " << (t.success_time.empty() ? "-" : num(st.mean, 1)) << " | "
               << (t.ratio.empty() ? "-" : num(rt.mean, 2)) << " | " << num(sc.mean, 3) << " |";
            if (people && !t.people_clearance.empty()) {
                const auto pc = devslam::core::summarize(t.people_clearance);
                const auto close =
                    std::count_if(t.people_clearance.begin(), t.people_clearance.end(),
                                  [](double d) { return d < kPersonalSpace; });
                md << " " << num(pc.median, 2) << " / " << num(pc.min, 3) << " | "
                   << pct(static_cast<int>(close), static_cast<int>(t.people_clearance.size()))
                   << " |";
            } else if (people)
                md << " - | - |";
            md << "\n";
        }
        md << "\n";
        if (!ep.stopped)  // the pictures are made only by a whole run
            md << "![" << devslam::sim::toString(cats[c]) << "](" << imageLink(a) << "/nav_bench_"
               << devslam::sim::toString(cats[c]) << ".png)\n\n";
    }
    return md.str();
}

/// The timings: one VFH+ step, each method's navigationStep(), A* on a 400x400 grid, and the
/// whole benchmark's simulated and wall time.
std::string timingMarkdown(const Args& a, const Episodes& ep, int ptg_count) {
    double astar_len = 0;
    const double vfh_ms = timeVfhStep();
    const double astar_ms = timeAStar400(&astar_len);
    std::ostringstream md;
    md << "![success rates](" << imageLink(a) << "/nav_bench_success.png)\n\n";
    if (std::any_of(ep.guard.begin(), ep.guard.end(),
                    [](const auto& g) { return g.second.commands > 0; })) {
        // A sentence, not a table: a row per method would read as another result row.
        md << "**Speed guard** (`[navigator] speed_guard`, docs/nav.md): of MRPT's commands "
              "over all runs, those scaled down to what the robot can follow and stop from "
              "(\"for walkers\": lower than the still points alone ask, for where walkers "
              "will be, `guard_walkers`):";
        const char* sep = " ";
        for (const auto& m : a.methods) {
            const auto it = ep.guard.find(m);
            if (it == ep.guard.end()) continue;
            const auto& g = it->second;
            const auto share = [&](std::size_t k) {
                char b[48];
                std::snprintf(b, sizeof b, "%zu (%.2f %%)", k,
                              g.commands ? 100.0 * double(k) / double(g.commands) : 0.0);
                return std::string(b);
            };
            if (g.commands == 0)  // (VFF: MRPT finds no way, and only stops the robot)
                md << sep << shortName(m) << " none sent";
            else
                md << sep << shortName(m) << " " << share(g.slowed) << " of " << g.commands << ", "
                   << g.stopped << " to a stop, " << g.by_walkers << " for walkers";
            sep = "; ";
        }
        md << ".\n\n";
    }
    md << "### Timing (thread CPU time, so shared-machine load does not inflate it)\n\n| "
          "measure | median |\n|---|---|\n"
       << "| one VFH+ step (`vfhPlusStep`, 121 sectors, synthetic fields, 2000 calls) | "
       << num(vfh_ms * 1e3, 1) << " us |\n";
    for (const auto& m : a.methods)
        md << "| one MRPT `navigationStep()` with " << shortName(m)
           << " (" << ptg_count << " PTGs, 181-ray laser, all runs) | "
           << num(devslam::core::median(ep.stepsOf(m)), 3) << " ms |\n";
    md << "| A* on a 400x400 grid (20 m, 5 cm cells, 60 boxes, corner to corner, path "
       << num(astar_len, 1) << " m; 15 plans) | " << num(astar_ms, 1) << " ms |\n"
       << "| whole benchmark: simulated / wall time | " << num(ep.sim_seconds, 0) << " s / "
       << num(ep.wall, 0) << " s |\n\n"
       << devslam::core::measuredOnLine() << "\n";
    return md.str();
}

/// Each category's first world with its first method's run, and the success-rate chart.
void writePictures(const Args& a, const std::vector<devslam::sim::Category>& cats,
                   const Episodes& ep) {
    std::filesystem::create_directories(a.png_dir);
    for (std::size_t c = 0; c < ep.pictures.size(); ++c)
        devslam::sim::writeEpisodePng(
            ep.pictures[c].world, ep.pictures[c].run,
            a.png_dir + "/nav_bench_" + devslam::sim::toString(cats[c]) + ".png",
            ep.pictures[c].world.name + " / " + ep.pictures[c].method);
    writeChart(a.png_dir + "/nav_bench_success.png", cats, a.methods, ep.tally);
}
int appMain(int argc, char** argv) {
    devslam::core::installStopHandler("devslam-nav-bench");
    Args a;
    if (const auto rc = parseArgs(argc, argv, a)) return *rc;
    try {
        // A results file that cannot take the section is found before minutes of work.
        if (!a.results.empty()) devslam::core::checkResultsSection(a.results, "nav");
        devslam::nav::registerNavClasses();
        const auto ini = devslam::core::loadIni(a.config);
        auto nav_opts = devslam::nav::NavigatorOptions::fromConfig(*ini, a.config);
        if (a.person_margin) {
            if (*a.person_margin < 0 || *a.person_margin > devslam::nav::kMaxPersonMargin)
                throw std::invalid_argument("--person-margin: must be in [0, 2] m");
            nav_opts.person_margin = *a.person_margin;
        }
        if (a.person_predict) nav_opts.person_predict_horizon = *a.person_predict;
        // what MRPT commands and predicts: the robot's new top speed
        if (a.max_speed) {
            devslam::nav::setTopSpeed(*ini, *a.max_speed);
            nav_opts.source += " with --max-speed " + devslam::core::shortestReal(*a.max_speed);
        }
        const auto& cats = a.categories;
        const Episodes ep = runEpisodes(a, *ini, nav_opts, cats);
        std::ostringstream md;
        md << headerMarkdown(a, nav_opts, cats.size());
        if (ep.stopped)
            md << "**Interrupted (" << devslam::core::signalName(ep.stopped) << ") after "
               << ep.done << " of " << ep.total
               << " episodes: the tables below cover those only.**\n\n";
        md << categoryTables(a, cats, ep);
        // Episodes ended by an error (a setting MRPT refuses mid-run, a formula that does not
        // compile) are not results: a bench of them printed 0 % success everywhere, exit 0,
        // and wrote that into the results file.
        const bool all_failed = !ep.errors.empty() && ep.errors.size() == std::size_t(ep.done);
        if (!ep.errors.empty()) {
            // Counted in the tables as "no path or error"; said here, as they are not results.
            md << "**" << ep.errors.size() << " episode" << (ep.errors.size() == 1 ? "" : "s")
               << " ended by an error** (counted as \"no path or error\"):\n\n";
            for (const auto& e : ep.errors) md << "- " << e << "\n";
            md << "\n";
            std::cerr << "devslam-nav-bench: " << ep.errors.size()
                      << " episodes ended by an error, listed under the tables\n";
        }
        if (ep.stopped) {
            std::cout << md.str();
            std::cerr << "devslam-nav-bench: interrupted (" << devslam::core::signalName(ep.stopped)
                      << ") after " << ep.done << " of " << ep.total
                      << " episodes; the tables above cover those; "
                      << (a.results.empty() ? std::string() : a.results + " and ")
                      << "the pictures were left as they were\n";
            devslam::core::exitBySignal(ep.stopped);
        }
        md << timingMarkdown(a, ep, ini->read_int("CReactiveNavigationSystem", "PTG_COUNT", 0));
        std::cout << md.str();
        if (!ep.errors.empty()) {
            std::cerr << "devslam-nav-bench: "
                      << (all_failed ? "every episode" : std::to_string(ep.errors.size()) +
                                                             " of " + std::to_string(ep.done) +
                                                             " episodes")
                      << " ended by an error (the first: " << ep.errors.front() << "); "
                      << (a.results.empty() ? std::string() : a.results + " and ")
                      << "the pictures were left as they were\n";
            return 1;
        }
        // The table first: pictures of a table that could not be written would not match it.
        if (!a.results.empty()) {
            devslam::core::replaceResultsSection(a.results, "nav", md.str());
            std::cerr << "devslam-nav-bench: updated section 'nav' of " << a.results << "\n";
        }
        writePictures(a, cats, ep);
        std::cerr << "devslam-nav-bench: pictures in " << a.png_dir << "\n";
        // The INI's log_file asked for navlogs: ones cut short (a full disk) fail the command,
        // after the results, which do not depend on them.
        if (ep.navlogs_cut > 0)
            std::cerr << "devslam-nav-bench: the navlogs of " << ep.navlogs_cut << " of " << ep.done
                      << " episodes are cut short; the first: " << ep.first_navlog_error << "\n";
        // Ctrl-C during the timings: all was written; end by the signal, as a script expects.
        if (const int sig = devslam::core::stopSignal()) devslam::core::exitBySignal(sig);
        return ep.navlogs_cut > 0 ? 1 : 0;
    } catch (const std::exception& e) {
        std::cerr << "devslam-nav-bench: " << e.what() << "\n";
        return 2;
    }
}
}  // namespace

int main(int argc, char** argv) {
    return devslam::core::withStandardOutput("devslam-nav-bench", appMain(argc, argv));
}
