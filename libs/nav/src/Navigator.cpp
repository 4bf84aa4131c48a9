#include <devslam/core/Config.h>
#include <devslam/core/GzFile.h>
#include <devslam/core/Parse.h>
#include <devslam/nav/CHolonomicVFHPlus.h>
#include <devslam/nav/Navigator.h>

#include "MrptSections.h"

#include <mrpt/core/bits_math.h>
#include <mrpt/maps/CSimplePointsMap.h>
#include <mrpt/nav/reactive/CReactiveNavigationSystem.h>
#include <mrpt/poses/CPose2D.h>
#include <mrpt/system/filesystem.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <functional>
#include <iostream>
#include <map>
#include <mutex>
#include <sstream>
#include <string_view>
#include <utility>

namespace devslam::nav {

namespace {
/// A PTG cache file cut short (a full disk, a run killed while writing it): MRPT printed its
/// read exception with a stack trace, naming no file, then rebuilt it. Removed first, it is
/// rebuilt without the noise. A file found whole is not read again in this process while its
/// size and time stay the same: a bench makes a navigator per episode, and MRPT reads each
/// file whole after this anyway.
void removeDamagedCacheFiles(const std::string& dir, bool verbose) {
    namespace fs = std::filesystem;
    static std::mutex mu;
    static std::map<std::string, std::pair<std::uintmax_t, fs::file_time_type>> whole;
    const std::lock_guard<std::mutex> lock(mu);
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(dir, ec)) {
        const std::string f = e.path().string();
        if (!core::endsWithNoCase(f, ".dat.gz")) continue;
        const auto time = fs::last_write_time(e.path(), ec);
        if (ec) continue;
        const auto size = fs::file_size(e.path(), ec);
        // (one written in the last minute may be another process's, still being written)
        if (ec || fs::file_time_type::clock::now() - time < std::chrono::minutes(1)) continue;
        if (const auto it = whole.find(f); it != whole.end() && it->second == std::pair{size, time})
            continue;
        if (core::gzipDamage(f).empty()) {
            whole[f] = {size, time};
            continue;
        }
        fs::remove(e.path(), ec);
        whole.erase(f);
        if (verbose)
            std::cerr << "navigator: removed the damaged PTG cache file " << f
                      << " (MRPT builds it again)\n";
    }
}

/// An MRPT log message on one line: its first non-blank line, then the innermost "Message:"
/// of the exception it carries (MRPT prints that with its location and call stack, 15 lines
/// that name no file, before the navigator's own one-line reason), or else its other lines
/// joined.
std::string oneLine(std::string_view msg) {
    std::vector<std::string> lines;
    std::istringstream in{std::string(msg)};
    for (std::string l; std::getline(in, l);) {
        while (!l.empty() && std::isspace(static_cast<unsigned char>(l.back()))) l.pop_back();
        if (l.find_first_not_of(" \t") != std::string::npos) lines.push_back(l);
    }
    if (lines.empty()) return {};
    std::string head = lines.front();
    if (lines.size() == 1) return head;
    while (!head.empty() && (head.back() == ':' || head.back() == ' ')) head.pop_back();
    const std::string rest(msg.substr(msg.find(lines.front()) + lines.front().size()));
    if (rest.find("Message:") != std::string::npos)
        return head + ": " + core::innermostMessage(rest);
    for (std::size_t i = 1; i < lines.size(); ++i)
        head += (i == 1 ? ": " : " ") + lines[i].substr(lines[i].find_first_not_of(" \t"));
    return head;
}

/// CPU time of the calling thread [s]: step timings that do not depend on machine load.
double threadCpuSeconds() {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

/// Exposes the per-PTG holonomic objects and silences MRPT's timing table.
class ReactiveNav : public mrpt::nav::CReactiveNavigationSystem {
  public:
    /// The navlog is enabled later (enableLogFile), after the logging level is set: enabled
    /// here, MRPT printed DEBUG lines whatever the level.
    ReactiveNav(mrpt::nav::CRobot2NavInterface& r, const std::string& dir)
        : CReactiveNavigationSystem(r, false, false, dir) {
        m_timlog_delays.enable(false);
    }
    /// Notes how many steps each VFH+ instance has made, before a navigationStep().
    void markVfhSteps() {
        vfh_steps_.clear();
        for (const auto& h : m_holonomicMethod) {
            const auto* v = dynamic_cast<const CHolonomicVFHPlus*>(h.get());
            vfh_steps_.push_back(v ? v->steps() : 0);
        }
    }
    /// Lowest VFH+ target density over the PTGs whose VFH+ ran since markVfhSteps() (-1 if
    /// none did). MRPT runs a PTG's method only when the target is in that PTG's domain: the
    /// others' outputs are older steps', and a backward PTG's density 0 from the one step
    /// the target was behind the robot held the minimum at 0 for the rest of the run.
    double vfhTargetDensity() const {
        double d = -1;
        for (std::size_t i = 0; i < m_holonomicMethod.size(); ++i) {
            const auto* v = dynamic_cast<const CHolonomicVFHPlus*>(m_holonomicMethod[i].get());
            if (!v || v->lastOutput().primary.empty()) continue;
            if (i < vfh_steps_.size() && v->steps() == vfh_steps_[i]) continue;  // not run
            d = d < 0 ? v->lastOutput().target_density
                      : std::min(d, v->lastOutput().target_density);
        }
        return d;
    }
    /// Writes the navlog into `s` (m_logFile, MRPT's own; a stream of MRPT's closed first).
    void useLogStream(std::unique_ptr<mrpt::io::CStream> s) { m_logFile = std::move(s); }
    /// As the INI names it: "mrpt::nav::CHolonomicND" -> "CHolonomicND".
    std::string holonomicClass() const {
        if (m_holonomicMethod.empty() || !m_holonomicMethod.front()) return {};
        const std::string name = m_holonomicMethod.front()->GetRuntimeClass()->className;
        const auto colon = name.rfind("::");
        return colon == std::string::npos ? name : name.substr(colon + 2);
    }

    /// Compiles MRPT's score formulas before the first step. MRPT 2.5 compiles them on the
    /// first candidate motion it scores, PTG0's, with that motion's variables only; a PTG
    /// whose domain does not hold the target gives its motion none, so a first target that
    /// PTG0 cannot reach (close beside or behind the start) ended the run at its first step
    /// ("Undefined symbol: 'target_d_norm'"). Compiled once, the formulas stay, and a later
    /// motion without variables scores 0, as every out-of-domain PTG's does at every step.
    /// Here MRPT's own scorer gives one motion of PTG0, toward a point on its middle path, its
    /// variables, so they are exactly those of a real step. A formula that does not compile is
    /// found here, before the run.
    void compileScoreFormulas() {
        auto* ptg = getPTG(0);
        ASSERT_(ptg != nullptr && ptg->isInitialized());
        const uint16_t k = static_cast<uint16_t>(ptg->getPathCount() / 2);
        const mrpt::math::TPose2D at = ptg->getPathPose(k, ptg->getPathStepCount(k) / 2);
        PTGTarget tp;
        tp.valid_TP = ptg->inverseMap_WS2TP(at.x, at.y, tp.target_k, tp.target_dist);
        ASSERT_(tp.valid_TP);
        tp.target_alpha = ptg->index2alpha(tp.target_k);
        tp.TP_Target = {std::cos(tp.target_alpha) * tp.target_dist,
                        std::sin(tp.target_alpha) * tp.target_dist};
        std::vector<double> free_space;
        ptg->initTPObstacles(free_space);
        for (auto& d : free_space) d /= ptg->getRefDistance();  // normalised, as in a step
        mrpt::nav::ClearanceDiagram clearance;
        // (as a step does: only with evaluate_clearance, which asserts more of the PTG)
        if (params_abstract_ptg_navigator.evaluate_clearance) ptg->initClearanceDiagram(clearance);
        std::vector<mrpt::nav::TCandidateMovementPTG> motion(1);
        motion[0].PTG = ptg;
        motion[0].direction = tp.target_alpha;
        motion[0].speed = 1.0;
        mrpt::nav::CLogFileRecord record;
        mrpt::nav::CLogFileRecord::TInfoPerPTG info;
        calc_move_candidate_scores(motion[0], free_space, clearance, {at}, {tp}, info, record,
                                   false, mrpt::math::TPose2D(0, 0, 0), 0, mrpt::Clock::now(),
                                   nullptr);
        // Not evaluated (MRPT scores a motion of speed <= 0 as 0): compiling needs only the
        // variables' names, and a formula evaluated with this made-up motion's values (the
        // robot's pose is not known yet) could come out NaN, which MRPT throws on.
        motion[0].speed = -1.0;
        // A step adds this one after the scorer (build_movement_candidate), and formulas may
        // use it (CAbstractPTGBasedReactive.h lists it).
        motion[0].props["original_col_free_dist"] = motion[0].props["collision_free_distance"];
        mrpt::nav::CMultiObjectiveMotionOptimizerBase::TResultInfo decided;
        (void)m_multiobjopt->decide(motion, decided);
    }

  private:
    std::vector<std::uint64_t> vfh_steps_;  // per PTG, at markVfhSteps()
};

/// The first free "DIR/log_NNN.reactivenavlog", NNN from 000: MRPT's own names.
std::string freeNavlogName(const std::string& dir) {
    for (unsigned k = 0;; ++k) {
        char name[64];
        std::snprintf(name, sizeof name, "log_%03u.reactivenavlog", k);
        const auto path = std::filesystem::path(dir) / name;
        std::error_code ec;
        if (!std::filesystem::exists(std::filesystem::symlink_status(path, ec)))
            return path.string();
    }
}
}  // namespace

/// MRPT's navlog through core::GzOutputStream (a gzip stream like MRPT's own, so
/// navlog-viewer reads it), whose failed write ends the log instead of throwing: MRPT writes
/// the log inside navigationStep(), and its handler of the exception its own stream threw on a
/// full disk stopped the robot, at every step, with a stack trace each.
class Navigator::NavlogStream : public mrpt::io::CStream {
  public:
    explicit NavlogStream(const std::string& path) : gz_(path, 1, "navlog") {}
    size_t Read(void* buf, size_t n) override { return gz_.Read(buf, n); }
    /// All taken, as MRPT's archive needs: after a failure the rest is dropped.
    size_t Write(const void* buf, size_t n) override {
        if (error_.empty() && gz_.Write(buf, n) != n)
            error_ = "cannot write navlog '" + gz_.path() + "': " + gz_.lastError() +
                     "; it ends there, the run went on without it";
        return n;
    }
    uint64_t Seek(int64_t off, TSeekOrigin o) override { return gz_.Seek(off, o); }
    uint64_t getTotalBytesCount() const override { return gz_.getTotalBytesCount(); }
    uint64_t getPosition() const override { return gz_.getPosition(); }
    /// Closes the file; what went wrong writing it, "" when nothing did.
    std::string close() {
        try {
            gz_.close();
        } catch (const std::exception& e) {
            if (error_.empty()) error_ = std::string(e.what()) + ": " + gz_.lastError();
        }
        return error_;
    }

  private:
    core::GzOutputStream gz_;
    std::string error_;
};

namespace {
void copyConfig(const mrpt::config::CConfigFileBase& from, mrpt::config::CConfigFileMemory& to) {
    std::vector<std::string> sections;
    from.getAllSections(sections);
    for (const auto& s : sections) {
        std::vector<std::string> keys;
        from.getAllKeys(s, keys);
        for (const auto& k : keys) to.write(s, k, from.read_string(s, k, "", false));
    }
}

NavigatorOptions readNavigatorOptions(const mrpt::config::CConfigFileBase& c,
                                      const std::string& source) {
    // Ours, then those MRPT's reactive navigator and its holonomic methods read.
    core::requireKnownSections(
        c,
        {"navigator", "global_planner", "replan", "CAbstractNavigator", "CWaypointsNavigator",
         "CAbstractPTGBasedReactive", "CReactiveNavigationSystem", "CHolonomicVFHPlus",
         "CHolonomicND", "CHolonomicVFF", "CHolonomicFullEval",
         "CMultiObjectiveMotionOptimizerBase", "CMultiObjMotionOpt_Scalarization",
         "CPointCloudFilterByDistance"},
        source);
    // MRPT's navigator needs these two (the PTGs and the robot); the Navigator checks again
    // for options made in code, where no file is known.
    for (const char* needed : {"CAbstractPTGBasedReactive", "CReactiveNavigationSystem"})
        if (!c.sectionExists(needed))
            throw std::invalid_argument(source + ": no [" + needed +
                                        "] section (MRPT's navigator needs it; see "
                                        "config_ini/nav_reactive.ini)");
    NavigatorOptions o;
    o.source = source;
    const std::string s = "navigator";
    core::requireKnownKeys(
        c, s,
        {"nav_period", "waypoint_allowed_distance", "holonomic_method", "robot_radius",
         "person_margin", "person_predict_horizon", "log_file", "log_directory", "speed_guard",
         "max_acc", "max_ang_acc_deg", "guard_margin", "guard_walkers"},
        source);
    o.nav_period = core::readDouble(c, s, "nav_period", o.nav_period);
    o.waypoint_allowed_distance =
        core::readDouble(c, s, "waypoint_allowed_distance", o.waypoint_allowed_distance);
    o.holonomic_method = c.read_string(s, "holonomic_method", o.holonomic_method);
    requireHolonomicMethod(o.holonomic_method, "[" + s + "] holonomic_method");
    o.robot_radius = core::readDouble(c, s, "robot_radius", o.robot_radius);
    o.person_margin = core::readDouble(c, s, "person_margin", o.person_margin);
    o.person_predict_horizon =
        core::readDouble(c, s, "person_predict_horizon", o.person_predict_horizon);
    o.log_file = core::readBool(c, s, "log_file", o.log_file);
    o.log_directory = c.read_string(s, "log_directory", o.log_directory);
    o.guard.enabled = core::readBool(c, s, "speed_guard", o.guard.enabled);
    o.guard.max_acc = core::readDouble(c, s, "max_acc", o.guard.max_acc);
    o.guard.max_ang_acc = mrpt::DEG2RAD(
        core::readDouble(c, s, "max_ang_acc_deg", mrpt::RAD2DEG(o.guard.max_ang_acc)));
    o.guard.margin = core::readDouble(c, s, "guard_margin", o.guard.margin);
    o.guard.walkers = core::readBool(c, s, "guard_walkers", o.guard.walkers);
    // At a period of seconds the robot drove blind into what it had not yet seen; a reached
    // radius of kilometres skipped every waypoint of the route.
    core::requireValue(o.nav_period > 0 && o.nav_period <= 1.0, s, "nav_period",
                       "must be in (0, 1] s");
    core::requireValue(o.waypoint_allowed_distance > 0 && o.waypoint_allowed_distance <= 10.0, s,
                       "waypoint_allowed_distance", "must be in (0, 10] m");
    core::requireValue(o.robot_radius > 0, s, "robot_radius", "must be > 0 m");
    core::requireValue(o.person_margin >= 0 && o.person_margin <= kMaxPersonMargin, s,
                       "person_margin", "must be in [0, 2] m");
    // Beyond a few seconds a walker's straight path is a guess that walls the corridor off.
    core::requireValue(
        o.person_predict_horizon >= 0 && o.person_predict_horizon <= kMaxPersonPredictHorizon, s,
        "person_predict_horizon", "must be in [0, 5] s");
    // (the world files' own bounds)
    core::requireValue(o.guard.max_acc > 0 && o.guard.max_acc <= kMaxRobotAcc, s, "max_acc",
                       "must be in (0, 20] m/s^2");
    core::requireValue(
        o.guard.max_ang_acc > 0 && o.guard.max_ang_acc <= mrpt::DEG2RAD(kMaxRobotAngAccDeg) + 1e-9,
        s, "max_ang_acc_deg", "must be in (0, 3600] deg/s^2");
    core::requireValue(o.guard.margin >= 0 && o.guard.margin <= 1.0, s, "guard_margin",
                       "must be in [0, 1] m");
    checkMrptSections(c, source);
    o.planner.loadFromConfigFile(c, "global_planner", source);
    o.replan.loadFromConfigFile(c, "replan", source);
    // Read again by the Navigator, from the same INI; checked here, where the file is known
    // (the route's waypoints are spaced by 0.9 x ref_distance: decimateWaypoints would only
    // fail at the first plan, naming no key).
    if (c.keyExists("CAbstractPTGBasedReactive", "ref_distance"))
        core::requireValue(
            core::readDouble(c, "CAbstractPTGBasedReactive", "ref_distance", 0.0) > 0,
            "CAbstractPTGBasedReactive", "ref_distance", "must be > 0 m");
    return o;
}
}  // namespace

NavigatorOptions NavigatorOptions::fromConfig(const mrpt::config::CConfigFileBase& c,
                                              const std::string& source) {
    // A bad value's message names the file ("nav.ini [navigator] nav_period: ...").
    return core::namingSource(source, [&] { return readNavigatorOptions(c, source); });
}

const char* toString(NavState s) {
    switch (s) {
        case NavState::Idle:
            return "idle";
        case NavState::Navigating:
            return "navigating";
        case NavState::GoalReached:
            return "goal reached";
        case NavState::Error:
            return "error";
    }
    return "?";
}

Navigator::Navigator(mrpt::nav::CRobot2NavInterface& robot,
                     const mrpt::config::CConfigFileBase& nav_ini, NavigatorOptions opts)
    : robot_(robot), opts_(std::move(opts)), planner_(opts_.planner), trigger_(opts_.replan) {
    registerNavClasses();
    mrpt::config::CConfigFileMemory cfg;
    copyConfig(nav_ini, cfg);
    const std::string sec_ptg = "CAbstractPTGBasedReactive";
    const std::string sec_rns = "CReactiveNavigationSystem";
    if (!cfg.sectionExists(sec_ptg) || !cfg.sectionExists(sec_rns))
        throw std::invalid_argument("Navigator: the navigation INI lacks [" + sec_ptg + "] or [" +
                                    sec_rns + "]");
    cfg.write(sec_ptg, "holonomic_method", opts_.holonomic_method);
    ref_distance_ = refDistanceOf(cfg);
    // robot polygon: 16-gon circumscribing the robot circle
    std::vector<double> xs, ys;
    const int nv = 16;
    const double rv = opts_.robot_radius / std::cos(M_PI / nv);
    for (int i = 0; i < nv; i++) {
        xs.push_back(rv * std::cos(2 * M_PI * i / nv));
        ys.push_back(rv * std::sin(2 * M_PI * i / nv));
    }
    cfg.write(sec_rns, "RobotModel_shape2D_xs", xs);
    cfg.write(sec_rns, "RobotModel_shape2D_ys", ys);

    guarded_ =
        std::make_unique<GuardedRobot>(robot_, opts_.robot_radius, opts_.nav_period, opts_.guard);
    nav_ = std::make_unique<ReactiveNav>(*guarded_, opts_.log_directory);
    nav_->setMinLoggingLevel(opts_.verbose ? mrpt::system::LVL_DEBUG : mrpt::system::LVL_ERROR);
    if (!opts_.verbose) {  // (--verbose keeps MRPT's own printing, call stacks and all)
        nav_->logging_enable_console_output = false;
        nav_->setVerbosityLevelForCallbacks(mrpt::system::LVL_ERROR);
        nav_->logRegisterCallback([](std::string_view msg, mrpt::system::VerbosityLevel level,
                                     std::string_view, const mrpt::Clock::time_point&) {
            if (level >= mrpt::system::LVL_ERROR) std::cerr << "MRPT: " << oneLine(msg) << "\n";
        });
    }
    if (opts_.log_file) {
        // Its parents too (a missing one was a std::filesystem error naming no option).
        std::error_code ec;
        std::filesystem::create_directories(opts_.log_directory, ec);
        if (!std::filesystem::is_directory(opts_.log_directory))
            throw std::runtime_error((opts_.source.empty() ? "" : opts_.source + " ") +
                                     "[navigator] log_directory: cannot create '" +
                                     opts_.log_directory + "'" +
                                     (ec ? ": " + ec.message() : std::string()));
        log_path_ = freeNavlogName(opts_.log_directory);
        auto log = std::make_unique<NavlogStream>(log_path_);
        navlog_ = log.get();
        static_cast<ReactiveNav&>(*nav_).useLogStream(std::move(log));
    }
    std::string cache = opts_.ptg_cache_directory;
    if (cache.empty()) {
        // PTG collision grids depend on the PTG section and the robot shape only.
        std::vector<std::string> keys;
        cfg.getAllKeys(sec_rns, keys);
        std::ostringstream os;
        for (const auto& k : keys) os << k << "=" << cfg.read_string(sec_rns, k, "") << ";";
        os << cfg.read_string(sec_ptg, "ref_distance", "");
        // (Not mrpt::system::getTempFileName(): it creates a file, left behind by every run.)
        cache = (std::filesystem::temp_directory_path() /
                 ("devslam_ptg_cache_" + std::to_string(std::hash<std::string>{}(os.str()))))
                    .string();
    }
    mrpt::system::createDirectory(cache);
    removeDamagedCacheFiles(cache, opts_.verbose);
    nav_->params_abstract_ptg_navigator.ptg_cache_files_directory = cache;
    // What only MRPT itself can tell (a motion decider class it does not know, a holonomic
    // method's section that is missing, a FullEval phase without its factors) it throws here,
    // naming no file and often with a stack trace: said with the INI's name.
    try {
        nav_->loadConfigFile(cfg);
        nav_->initialize();
        static_cast<ReactiveNav&>(*nav_).compileScoreFormulas();
    } catch (const std::exception& e) {
        throw std::invalid_argument(opts_.source + ": MRPT's navigator refuses these settings: " +
                                    core::innermostMessage(e.what()));
    }
    requirePathsOfOneMetre(cfg);
}

void Navigator::requirePathsOfOneMetre(const mrpt::config::CConfigFileBase& cfg) const {
    // MRPT 2.5 scores a candidate motion at the point of its path a normalised distance (up to
    // 1) along, which it takes for metres: on a path that ends sooner, as a tight turn's does
    // (v_max / w_max small), that step failed ("Assert condition failed: pt_in_range"), in the
    // middle of a run, the first time such a motion was scored (the shipped PTGs at --max-speed
    // 0.2, whose tightest arcs end 0.997 m along). Every path's length is known once the PTGs
    // are built (the shipped PTG3's, of refDistance 1 m, end 1.0000007 m along).
    for (std::size_t p = 0; p < nav_->getPTG_count(); p++) {
        const auto* ptg = nav_->getPTG(p);
        double shortest = std::numeric_limits<double>::infinity();
        for (uint16_t k = 0; k < ptg->getPathCount(); k++)
            shortest = std::min(shortest, ptg->getPathDist(k, ptg->getPathStepCount(k) - 1));
        if (shortest >= 1.0) continue;
        const std::string s = "CReactiveNavigationSystem", i = "PTG" + std::to_string(p);
        std::ostringstream m;
        m.precision(4);
        m << opts_.source << ": " << i << " (" << cfg.read_string(s, i + "_Type", "?") << ", v_max "
          << cfg.read_double(s, i + "_v_max_mps", 0) << " m/s, w_max "
          << cfg.read_double(s, i + "_w_max_dps", 0) << " deg/s, [" << s << "] " << i
          << "_*): its shortest path ends " << shortest
          << " m along, short of the 1 m along every path at which MRPT 2.5 scores a motion "
             "(it would stop the run with 'pt_in_range'): ";
        // (no path is longer than refDistance: then neither speed helps; a differential-drive
        // PTG's under 1 m is refused when the INI is read, this is for any other kind)
        if (ptg->getRefDistance() < 1.0)
            m << "its refDistance " << ptg->getRefDistance() << " m must be at least 1 m";
        else
            m << "its tightest turn (v_max / w_max) is too tight; raise its v_max or lower its "
                 "w_max";
        throw std::invalid_argument(m.str());
    }
}

Navigator::~Navigator() = default;

std::string Navigator::closeLog() {
    if (navlog_ == nullptr) return "";
    std::string why = navlog_->close();
    navlog_ = nullptr;
    nav_->enableLogFile(false);  // MRPT's reference to the closed stream goes too
    return why;
}

std::vector<std::pair<double, int>> Navigator::targetsNoPtgReaches() {
    std::vector<std::pair<double, int>> out;
    const auto& rns = *nav_;
    const int n = static_cast<int>(
        std::lround((kPtgGapMaxDistance - kPtgGapMinDistance) / 0.05));
    for (int i = 0; i <= n; i++)
        for (int deg = -179; deg <= 180; deg++) {
            const double d = kPtgGapMinDistance + 0.05 * i, a = deg * M_PI / 180;
            bool reached = false;
            for (std::size_t p = 0; p < rns.getPTG_count() && !reached; p++) {
                int k = 0;
                double nd = 0;
                reached = rns.getPTG(p)->inverseMap_WS2TP(d * std::cos(a), d * std::sin(a), k, nd);
            }
            if (!reached) out.emplace_back(d, deg);
        }
    return out;
}

std::string describePtgDomainGaps(const std::vector<std::pair<double, int>>& gaps) {
    if (gaps.empty()) return {};
    char text[320];
    std::snprintf(text, sizeof text,
                  "%zu targets %.2f-%.2f m from the robot (every 5 cm and degree) lie in no PTG's "
                  "domain, the first %.2f m away at %d deg; MRPT stops when its target is there, "
                  "until a PTG of a smaller turning radius reaches it (docs/nav.md, \"A target "
                  "close behind\")",
                  gaps.size(), kPtgGapMinDistance, kPtgGapMaxDistance, gaps.front().first,
                  gaps.front().second);
    return text;
}

std::string Navigator::holonomicMethod() const {
    return static_cast<const ReactiveNav&>(*nav_).holonomicClass();
}

mrpt::nav::CReactiveNavigationSystem& Navigator::reactive() {
    return *nav_;
}

bool Navigator::start(const mrpt::maps::COccupancyGridMap2D& map, const mrpt::math::TPose2D& start,
                      const mrpt::math::TPoint2D& goal, double goal_tolerance) {
    static_map_ = map;
    goal_ = goal;
    goal_tolerance_ = goal_tolerance;
    planner_.setMap(map);
    auto p = planner_.plan({start.x, start.y}, goal);  // throws PlanningError
    if (!p) {
        last_error_ = "no path from start to goal";
        return false;
    }
    first_path_ = *p;
    setPath(*p);
    replans_ = 0;
    trigger_.reset(0.0);
    sendWaypoints(0);
    active_ = true;
    return true;
}

double refDistanceOf(const mrpt::config::CConfigFileBase& nav_ini) {
    return core::readDouble(nav_ini, "CAbstractPTGBasedReactive", "ref_distance", 0.0, true);
}

void requireTopSpeed(double v, const std::string& option) {
    if (!(v > 0 && v <= kMaxRobotSpeed))
        throw std::invalid_argument(option + ": must be in (0, 5] m/s");
}

void setTopSpeed(mrpt::config::CConfigFileBase& nav_ini, double v, const std::string& option) {
    requireTopSpeed(v, option);
    const double top = nav_ini.read_double("CAbstractPTGBasedReactive", "robotMax_V_mps", 0);
    nav_ini.write("CAbstractPTGBasedReactive", "robotMax_V_mps", v);
    const int n = nav_ini.read_int("CReactiveNavigationSystem", "PTG_COUNT", 0);
    for (int i = 0; i < n; ++i) {
        const std::string key = "PTG" + std::to_string(i) + "_v_max_mps";
        const double ptg = nav_ini.read_double("CReactiveNavigationSystem", key, top);
        if (std::abs(ptg - top) <= 1e-9 * std::max(1.0, top))
            nav_ini.write("CReactiveNavigationSystem", key, v);
    }
}

double waypointSpacing(double waypoint_spacing, double ref_distance) {
    return std::min(waypoint_spacing, 0.9 * ref_distance);
}

void Navigator::setPath(const GridPath& p) {
    path_ = p;
    path_segment_ = 0;
    // planner_ holds the map the path was planned on: a replanned path's shortcuts are checked
    // against the sensed obstacles it went round, not only the static map's walls.
    waypoint_path_index_ = decimateWaypointIndices(
        planner_, path_, waypointSpacing(opts_.planner.waypoint_spacing, ref_distance_));
    waypoints_.clear();
    for (const std::size_t i : waypoint_path_index_) waypoints_.push_back(path_.points[i]);
}

void Navigator::sendWaypoints(std::size_t first) {
    if (waypoints_.empty()) return;  // decimateWaypoints keeps at least the goal
    mrpt::nav::TWaypointSequence seq;
    for (size_t i = std::min(first, waypoints_.size() - 1); i < waypoints_.size(); i++) {
        const bool last = i + 1 == waypoints_.size();
        seq.waypoints.emplace_back(waypoints_[i].x, waypoints_[i].y,
                                   last ? goal_tolerance_ : opts_.waypoint_allowed_distance, !last);
    }
    nav_->navigateWaypoints(seq);
}

bool Navigator::replan(const mrpt::math::TPose2D& pose,
                       const std::vector<mrpt::math::TPoint2D>& sensed) {
    // static map + sensed obstacles (people, unmapped objects) stamped as discs
    mrpt::maps::COccupancyGridMap2D m = stampSensedObstacles(
        static_map_, {pose.x, pose.y}, goal_, sensed, opts_.planner.robot_radius, opts_.replan);
    std::optional<GridPath> p;
    for (const auto* mp : {&m, &static_map_}) {
        planner_.setMap(*mp);
        // A robot pressed against a wall (when MRPT gives up) stands in a cell the grid
        // calls too close: planning from there failed every time, and it waited for the
        // timeout. It plans from the nearest cell it may stand in, a robot radius away at most.
        const auto start = planner_.nearestTraversable({pose.x, pose.y}, opts_.planner.robot_radius)
                               .value_or(mrpt::math::TPoint2D{pose.x, pose.y});
        try {
            p = planner_.plan(start, goal_);
        } catch (const PlanningError& e) {
            last_error_ = e.what();
            p.reset();
        }
        if (p) {
            setPath(*p);
            break;
        }
    }
    planner_.setMap(static_map_);
    if (!p) return false;
    replans_++;
    sendWaypoints(0);
    return true;
}

NavState Navigator::step(double t) {
    if (!active_) return NavState::Idle;
    mrpt::math::TPose2D pose, odo;
    mrpt::math::TTwist2D vel;
    mrpt::system::TTimeStamp ts;
    std::string frame;
    if (!robot_.getCurrentPoseAndSpeeds(pose, vel, ts, odo, frame)) {
        last_error_ = "robot did not report its pose";
        return NavState::Error;
    }
    auto& reactive = static_cast<ReactiveNav&>(*nav_);
    reactive.markVfhSteps();
    const double t0 = threadCpuSeconds();
    nav_->navigationStep();
    last_step_s_ = threadCpuSeconds() - t0;

    const double goal_dist = std::hypot(pose.x - goal_.x, pose.y - goal_.y);
    const auto st = nav_->getCurrentState();
    // Within the tolerance the run counts as arrived (sim::runEpisode): idle short of it,
    // MRPT is sent on again below.
    if (st == mrpt::nav::CAbstractNavigator::IDLE && goal_dist <= goal_tolerance_) {
        active_ = false;
        return NavState::GoalReached;
    }

    // sensed obstacles in the world frame (for the blocked-path check and replanning)
    mrpt::maps::CSimplePointsMap local;
    std::vector<mrpt::math::TPoint2D> sensed;
    if (robot_.senseObstacles(local, ts)) {
        const mrpt::poses::CPose2D P(pose);
        const auto& xs = local.getPointsBufferRef_x();
        const auto& ys = local.getPointsBufferRef_y();
        for (size_t i = 0; i < xs.size(); i++) {
            double gx, gy;
            P.composePoint(xs[i], ys[i], gx, gy);
            sensed.emplace_back(gx, gy);
        }
    }
    // Progress moves by at most the lookahead a step (forward, or back where people pushed the
    // robot back): the nearest segment anywhere can be one of a path folding back past the
    // robot, not the ones ahead of it.
    path_segment_ =
        pathProgress(path_.points, {pose.x, pose.y}, path_segment_, opts_.replan.blocked_lookahead);
    // An exception inside MRPT's step (an exprtk formula that does not compile, a FullEval
    // factor index out of range) makes it stop the robot as in an emergency: replanned, the
    // run met it again at every step until its timeout, the robot standing. It comes from the
    // settings, which no replan changes: the run ends with it. (MRPT also stops so when the
    // robot cannot give its pose or its obstacles, which SimRobot always gives.) MRPT 2.5
    // leaves its state NAVIGATING then: the reason, kept until the next navigate(), tells.
    if (const auto& why = nav_->getErrorReason();
        why.error_code == mrpt::nav::CAbstractNavigator::ERR_EMERGENCY_STOP ||
        why.error_code == mrpt::nav::CAbstractNavigator::ERR_OTHER) {
        const std::string msg = core::innermostMessage(why.error_msg);
        last_error_ = "MRPT's navigation step failed (settings in " + opts_.source + "?): " + msg;
        // (MRPT's pt_in_range, a path shorter than the 1 m it scores at, is refused when the
        // navigator is made: requirePathsOfOneMetre)
        active_ = false;
        return NavState::Error;
    }
    if (st == mrpt::nav::CAbstractNavigator::NAV_ERROR ||
        st == mrpt::nav::CAbstractNavigator::IDLE) {
        // MRPT gave up ("not approaching target") or ended short of the goal: replan
        if (st == mrpt::nav::CAbstractNavigator::NAV_ERROR) nav_->resetNavError();
        trigger_.reset(t);
        if (!replan(pose, sensed)) {
            // Keep trying with the previous path, from the waypoint ahead of the robot's
            // progress along it: from its first, MRPT would drive back to where the path began.
            sendWaypoints(waypointAhead(waypoint_path_index_, path_segment_));
        }
        return NavState::Navigating;
    }
    // The path is blocked only by what the static map does not hold (people, objects missing
    // from it): the walls the route already keeps clear of made the check replan the same
    // route again. The replanning map takes every sensed point: stamped walls keep a replanned
    // route off them (stamping only the unmapped points gave FullEval 45 of 50 corridor_people
    // worlds instead of 48, docs/nav.md).
    const auto unmapped = unmappedPoints(planner_, sensed);
    const double radius = opts_.planner.robot_radius + opts_.replan.blocked_margin;
    const bool blocked =
        pathBlocked(path_.points, path_segment_, unmapped, radius, opts_.replan.blocked_lookahead);
    const double density = reactive.vfhTargetDensity();
    const ReplanReason why = trigger_.update({t, blocked, std::max(0.0, density)});
    if (why != ReplanReason::None) (void)replan(pose, sensed);
    return NavState::Navigating;
}

}  // namespace devslam::nav
