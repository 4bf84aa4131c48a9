#include "MrptSections.h"

#include <devslam/core/Config.h>
#include <devslam/core/GzFile.h>
#include <devslam/core/Parse.h>
#include <devslam/nav/VfhPlus.h>

#include <mrpt/config/CConfigFileMemory.h>
#include <mrpt/maps/CPointCloudFilterByDistance.h>
#include <mrpt/nav/holonomic/CHolonomicFullEval.h>
#include <mrpt/nav/holonomic/CHolonomicND.h>
#include <mrpt/nav/holonomic/CHolonomicVFF.h>
#include <mrpt/nav/reactive/CAbstractPTGBasedReactive.h>
#include <mrpt/nav/reactive/CMultiObjMotionOpt_Scalarization.h>
#include <mrpt/nav/reactive/CMultiObjectiveMotionOptimizerBase.h>
#include <mrpt/nav/reactive/CReactiveNavigationSystem.h>
#include <mrpt/nav/reactive/CWaypointsNavigator.h>
#include <mrpt/nav/tpspace/CParameterizedTrajectoryGenerator.h>
#include <mrpt/rtti/CObject.h>
#include <mrpt/system/string_utils.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <map>
#include <regex>
#include <sstream>
#include <stdexcept>

namespace devslam::nav {
namespace {

/// What MRPT's default of a key tells about its values: one integer ("3"), one number
/// ("0.600000"), a list of numbers ("[0 2]", "1.00 0.50"), a boolean, or text (formulas,
/// class names), which is not checked.
enum class Kind { Integer, Number, Numbers, Bool, Text };

/// Known keys of one section: name as MRPT writes it, and the kind of its value.
using Keys = std::map<std::string, std::pair<std::string, Kind>>;  // lower-case name -> ...

/// The keys `save` writes into a section (MRPT's saveToConfigFile pads names and appends a
/// `// comment`, which its own getAllKeys keeps: the text is read line by line here).
template <class Save>
Keys savedKeys(Save&& save, const std::string& prefix = "") {
    mrpt::config::CConfigFileMemory m;
    save(m, "s");
    std::string text;
    m.getContent(text);
    Keys keys;
    std::istringstream in(text);
    for (std::string line; std::getline(in, line);) {
        const auto eq = line.find('=');
        if (eq == std::string::npos || line[0] == '#' || line[0] == '[') continue;
        const std::string name = prefix + core::trimmed(line.substr(0, eq));
        std::string value = line.substr(eq + 1);
        value = core::trimmed(value.substr(0, value.find("//")));
        Kind kind = Kind::Text;
        if (value == "true" || value == "false") {
            kind = Kind::Bool;
        } else if (!value.empty()) {
            try {
                const auto v = core::parseNumberList(value, "");
                const bool list = v.size() > 1 || value.find('[') != std::string::npos;
                kind = list                                              ? Kind::Numbers
                       : value.find_first_of(".eE") == std::string::npos ? Kind::Integer
                                                                         : Kind::Number;
                if (v.empty()) kind = Kind::Text;
            } catch (const std::invalid_argument&) {
            }
        }
        if (!name.empty()) keys[core::lowercase(name)] = {name, kind};
    }
    return keys;
}

/// Keys known by a pattern (numbered ones, whose count is another key's value).
struct Pattern {
    std::regex re;
    Kind kind;
};

/// Checks the keys of `section` against `known`, and those `patterns` match.
void checkSection(const mrpt::config::CConfigFileBase& c, const std::string& section,
                  const Keys& known, const std::string& source,
                  const std::vector<Pattern>& patterns = {}) {
    std::vector<std::string> keys;
    c.getAllKeys(section, keys);
    for (const auto& key : keys) {
        const std::string where = source + " [" + section + "] " + key;
        Kind kind = Kind::Text;
        if (const auto it = known.find(core::lowercase(key)); it != known.end()) {
            kind = it->second.second;
        } else {
            const auto p = std::find_if(patterns.begin(), patterns.end(), [&](const Pattern& q) {
                return std::regex_match(key, q.re);
            });
            if (p == patterns.end()) {
                std::string list;
                for (const auto& [k, v] : known) list += (list.empty() ? "" : ", ") + v.first;
                throw std::invalid_argument(source + " [" + section + "]: unknown key '" + key +
                                            "' (MRPT's navigator knows: " + list + ")");
            }
            kind = p->kind;
        }
        const std::string value = c.read_string(section, key, "");
        switch (kind) {
            case Kind::Integer:
                (void)core::parseInteger(value, where);
                break;
            case Kind::Number:
                (void)core::parseNumber(value, where);
                break;
            case Kind::Numbers:
                if (core::parseNumberList(value, where).empty())
                    throw std::invalid_argument(where + ": expected numbers, got '" + value + "'");
                break;
            case Kind::Bool: {
                // MRPT's read_bool knows true/false/yes/no and reads anything else as an
                // integer ("on" as false): only what it reads as meant.
                const std::string v = core::lowercase(core::trimmed(value));
                if (v != "true" && v != "false" && v != "yes" && v != "no" && v != "1" && v != "0")
                    throw std::invalid_argument(where + ": expected true or false, got '" + value +
                                                "'");
                break;
            }
            case Kind::Text:
                break;
        }
    }
}

}  // namespace

void checkMrptSections(const mrpt::config::CConfigFileBase& c, const std::string& source) {
    using namespace mrpt::nav;
    const auto save = [](const auto& params) {
        return savedKeys([&](auto& m, const std::string& s) { params.saveToConfigFile(m, s); });
    };
    if (c.sectionExists("CAbstractNavigator"))
        checkSection(c, "CAbstractNavigator", save(CAbstractNavigator::TAbstractNavigatorParams()),
                     source);
    if (c.sectionExists("CWaypointsNavigator"))
        checkSection(c, "CWaypointsNavigator",
                     save(CWaypointsNavigator::TWaypointsNavigatorParams()), source);
    if (c.sectionExists("CAbstractPTGBasedReactive"))
        checkSection(c, "CAbstractPTGBasedReactive",
                     save(CAbstractPTGBasedReactive::TAbstractPTGNavigatorParams()), source);
    if (c.sectionExists("CHolonomicND"))
        checkSection(c, "CHolonomicND", save(CHolonomicND::TOptions()), source);
    if (c.sectionExists("CHolonomicFullEval"))  // as many PHASE<i>_* as PHASE_COUNT says
        checkSection(c, "CHolonomicFullEval", save(CHolonomicFullEval::TOptions()), source,
                     {{std::regex("PHASE[0-9]+_FACTORS", std::regex::icase), Kind::Numbers},
                      {std::regex("PHASE[0-9]+_THRESHOLD", std::regex::icase), Kind::Number}});
    if (c.sectionExists("CPointCloudFilterByDistance"))  // with enable_obstacle_filtering
        checkSection(c, "CPointCloudFilterByDistance",
                     save(mrpt::maps::CPointCloudFilterByDistance::TOptions()), source);
    if (c.sectionExists("CHolonomicVFF"))
        checkSection(c, "CHolonomicVFF", save(CHolonomicVFF::TOptions()), source);
    if (c.sectionExists("CMultiObjMotionOpt_Scalarization"))
        checkSection(c, "CMultiObjMotionOpt_Scalarization",
                     save(CMultiObjMotionOpt_Scalarization::TParams()), source);
    if (c.sectionExists("CMultiObjectiveMotionOptimizerBase")) {
        // Numbered lists of exprtk formulas: names only.
        Keys base;
        base["scores_to_normalize"] = {"scores_to_normalize", Kind::Text};
        checkSection(
            c, "CMultiObjectiveMotionOptimizerBase", base, source,
            {{std::regex("score[0-9]+_(name|formula)|movement_assert[0-9]+", std::regex::icase),
              Kind::Text}});
        // A name no score has was ignored without a word (MRPT normalises the ones it finds).
        const std::string mo = "CMultiObjectiveMotionOptimizerBase";
        std::vector<std::string> names;
        for (int i = 1; c.keyExists(mo, "score" + std::to_string(i) + "_name"); ++i)
            names.push_back(c.read_string(mo, "score" + std::to_string(i) + "_name", ""));
        // (split as MRPT splits it)
        std::vector<std::string> listed;
        mrpt::system::tokenize(c.read_string(mo, "scores_to_normalize", ""), ", \t", listed);
        for (const auto& w : listed)
            if (std::find(names.begin(), names.end(), w) == names.end())
                core::namingSource(source, [&] {
                    std::string known;
                    for (const auto& n : names) known += (known.empty() ? "" : ", ") + n;
                    core::requireValue(false, mo, "scores_to_normalize",
                                       "no score is named '" + w + "' (scores: " + known + ")");
                });
    }
    // exprtk's constant inf in a formula scored every motion inf or NaN: MRPT found "no way"
    // at each step, and the run said only that the robot never left its start (nan and 1e400
    // are refused where a value is a number; a formula is text).
    core::namingSource(source, [&] {
        // (a digit before it is exprtk's implicit product, "2inf"; a movement_assert may
        // compare with inf, a truth value and no score)
        static const std::regex inf("(^|[^a-z_])inf(inity)?($|[^a-z0-9_])", std::regex::icase);
        static const std::regex formula("score[0-9]+_formula", std::regex::icase);
        const auto check = [&](const std::string& sec, const std::string& key) {
            core::requireValue(!std::regex_search(c.read_string(sec, key, ""), inf), sec, key,
                               "uses exprtk's constant inf: a score of inf or NaN leaves MRPT "
                               "no motion to choose");
        };
        const std::string sc = "CMultiObjMotionOpt_Scalarization";
        if (c.keyExists(sc, "scalar_score_formula")) check(sc, "scalar_score_formula");
        const std::string mo = "CMultiObjectiveMotionOptimizerBase";
        std::vector<std::string> keys;
        c.getAllKeys(mo, keys);
        for (const auto& k : keys)
            if (std::regex_match(k, formula)) check(mo, k);
    });
    // Values MRPT asserts on only while navigating (a speed limit of 0 or below printed an
    // MRPT stack trace at every step, and the robot still got there) or with a message that
    // names no file and stops mid-sentence (factorWeights of the wrong length).
    core::namingSource(source, [&] {
        const std::string ptg = "CAbstractPTGBasedReactive";
        for (const char* k : {"robotMax_V_mps", "robotMax_W_degps"})
            if (c.keyExists(ptg, k))
                core::requireValue(core::readDouble(c, ptg, k, 0.0) > 0, ptg, k, "must be > 0");
        // (below 0 MRPT's speed filter divided by a negative sum: NaN commands, path -nan m;
        // 1e9 s let the robot creep until the timeout; 1e5 s still ran)
        if (c.keyExists(ptg, "speedfilter_tau")) {
            const double tau = core::readDouble(c, ptg, "speedfilter_tau", 0.0);
            core::requireValue(tau >= 0 && tau <= 1e4, ptg, "speedfilter_tau",
                               "must be in [0, 1e4] s");
        }
        // Taken unchecked until 2026-12-07 (a bad-input sweep): a timeout of 0 or below gave
        // up on the target at once; a negative count of steps means nothing (0 is "at once").
        const std::string an = "CAbstractNavigator", wn = "CWaypointsNavigator";
        if (c.keyExists(an, "alarm_seems_not_approaching_target_timeout"))
            core::requireValue(
                core::readDouble(c, an, "alarm_seems_not_approaching_target_timeout", 0.0) > 0, an,
                "alarm_seems_not_approaching_target_timeout", "must be > 0 s");
        if (c.keyExists(wn, "min_timesteps_confirm_skip_waypoints"))
            core::requireValue(core::readInt(c, wn, "min_timesteps_confirm_skip_waypoints", 0) >= 0,
                               wn, "min_timesteps_confirm_skip_waypoints", "must be >= 0 [steps]");
        // MRPT asserts end > start in every step (a run of stack traces, ended as an error).
        {
            const CAbstractPTGBasedReactive::TAbstractPTGNavigatorParams d;
            const double start =
                core::readDouble(c, ptg, "secure_distance_start", d.secure_distance_start);
            const double end = core::readDouble(c, ptg, "secure_distance_end", d.secure_distance_end);
            core::requireValue(start >= 0, ptg, "secure_distance_start", "must be >= 0");
            std::ostringstream why;
            why << "must be > secure_distance_start (" << start << ")";
            core::requireValue(end > start, ptg, "secure_distance_end", why.str());
            // (normalised by each PTG's refDistance: 5 slowed the robot for obstacles five
            // reference distances away, and it timed out)
            core::requireValue(end <= 1, ptg, "secure_distance_end",
                               "must be at most 1 (a fraction of each PTG's refDistance)");
        }
        for (const auto& [section, n] :
             {std::pair{std::string("CHolonomicND"), CHolonomicND::TOptions().factorWeights.size()},
              {std::string("CHolonomicFullEval"),
               CHolonomicFullEval::TOptions().factorWeights.size()}})
            if (c.keyExists(section, "factorWeights")) {
                const auto w = core::parseNumberList(c.read_string(section, "factorWeights", ""),
                                                     "[" + section + "] factorWeights");
                core::requireValue(w.size() == n, section, "factorWeights",
                                   "expected " + std::to_string(n) + " numbers, got " +
                                       std::to_string(w.size()));
            }
        // FullEval's phases: MRPT indexes factorWeights with PHASE<i>_FACTORS and asserts
        // PHASE_COUNT >= 1 only inside each navigation step.
        const std::string fe = "CHolonomicFullEval";
        const CHolonomicFullEval::TOptions fe_defaults;
        const std::size_t n_factors = fe_defaults.factorWeights.size();
        std::vector<double> fe_weights(fe_defaults.factorWeights.begin(),
                                       fe_defaults.factorWeights.end());
        if (c.keyExists(fe, "factorWeights"))
            fe_weights = core::parseNumberList(c.read_string(fe, "factorWeights", ""),
                                               "[" + fe + "] factorWeights");
        if (c.keyExists(fe, "PHASE_COUNT")) {
            const int phases = core::readInt(c, fe, "PHASE_COUNT", 0);
            core::requireValue(phases >= 1 && phases <= 16, fe, "PHASE_COUNT", "must be 1..16");
            for (int i = 1; i <= phases; ++i) {
                const std::string k = "PHASE" + std::to_string(i) + "_FACTORS";
                const std::string t = "PHASE" + std::to_string(i) + "_THRESHOLD";
                core::requireValue(c.keyExists(fe, k) && c.keyExists(fe, t), fe,
                                   c.keyExists(fe, k) ? t : k,
                                   "missing (PHASE_COUNT is " + std::to_string(phases) + ")");
                const auto f = core::parseNumberList(c.read_string(fe, k, ""), "[" + fe + "] " + k);
                core::requireValue(!f.empty(), fe, k, "expected factor indices");
                double sum = 0;
                for (const double x : f) {
                    core::requireValue(
                        x >= 0 && x < static_cast<double>(n_factors) && x == std::floor(x), fe, k,
                        "factor indices must be integers 0.." + std::to_string(n_factors - 1));
                    sum += fe_weights[static_cast<std::size_t>(x)];
                }
                // (MRPT asserts it at every step: the run ended at its first, with a stack trace)
                core::requireValue(sum > 0, fe, k,
                                   "the factorWeights of these factors sum to 0; a phase needs a "
                                   "weight above 0");
                const double th = core::readDouble(c, fe, t, 0.0);
                core::requireValue(th >= 0 && th <= 1, fe, t, "must be in [0, 1]");
            }
        }
        // VFF: an attractive force of 0 or below leaves the robot standing; a slow-down
        // distance below 0 makes its speed negative (0 is no slow-down: MRPT's min(1, d/0)).
        const std::string vff = "CHolonomicVFF";
        if (c.keyExists(vff, "TARGET_ATTRACTIVE_FORCE"))
            core::requireValue(core::readDouble(c, vff, "TARGET_ATTRACTIVE_FORCE", 0.0) > 0, vff,
                               "TARGET_ATTRACTIVE_FORCE", "must be > 0");
        if (c.keyExists(vff, "TARGET_SLOW_APPROACHING_DISTANCE"))
            core::requireValue(
                core::readDouble(c, vff, "TARGET_SLOW_APPROACHING_DISTANCE", 0.0) >= 0, vff,
                "TARGET_SLOW_APPROACHING_DISTANCE", "must be >= 0");
    });
    // Ours: its own strict reader names the file.
    if (c.sectionExists("CHolonomicVFHPlus")) {
        VfhPlusOptions v;
        v.loadFromConfigFile(c, "CHolonomicVFHPlus", source);
    }

    // The PTGs: how many, of which class, and each class's own keys with its prefix.
    const std::string s = "CReactiveNavigationSystem";
    if (!c.sectionExists(s)) return;
    Keys known = save(CReactiveNavigationSystem::TReactiveNavigatorParams());
    for (const auto& [k, kind] : {std::pair{"PTG_COUNT", Kind::Integer},
                                  {"RobotModel_shape2D_xs", Kind::Numbers},
                                  {"RobotModel_shape2D_ys", Kind::Numbers},
                                  {"RobotModel_circular_shape_radius", Kind::Number}})
        known[core::lowercase(k)] = {k, kind};
    const int n = core::namingSource(source, [&] { return core::readInt(c, s, "PTG_COUNT", 0); });
    if (n < 1 || n > 32)
        throw std::invalid_argument(source + " [" + s + "] PTG_COUNT: must be 1..32, got " +
                                    std::to_string(n));
    for (int i = 0; i < n; ++i) {
        const std::string prefix = "PTG" + std::to_string(i) + "_";
        const std::string type = c.read_string(s, prefix + "Type", "");
        if (type.empty())
            throw std::invalid_argument(source + " [" + s + "] " + prefix +
                                        "Type: missing (PTG_COUNT is " + std::to_string(n) + ")");
        // Its keys first (a junk value would make MRPT take "fast" as 0), then MRPT makes it.
        const auto ptg_known = savedKeys(
            [&](auto& m, const std::string&) {
                mrpt::rtti::registerAllPendingClasses();
                const auto ptg = std::dynamic_pointer_cast<CParameterizedTrajectoryGenerator>(
                    mrpt::rtti::classFactory(type));
                if (!ptg)
                    throw std::invalid_argument(source + " [" + s + "] " + prefix +
                                                "Type: unknown PTG class '" + type + "'");
                ptg->saveToConfigFile(m, "s");
            },
            prefix);
        known.insert(ptg_known.begin(), ptg_known.end());
        known[core::lowercase(prefix + "Type")] = {prefix + "Type", Kind::Text};
    }
    // A PTG's own robot shape (the Navigator replaces it with RobotModel_shape2D_*).
    checkSection(c, s, known, source,
                 {{std::regex("PTG[0-9]+_shape_[xy][0-9]+", std::regex::icase), Kind::Number}});
    // Values MRPT asserts on only when the navigator starts (num_paths 0, resolution 0, ...).
    for (int i = 0; i < n; ++i) {
        const std::string prefix = "PTG" + std::to_string(i) + "_";
        core::namingSource(source, [&] {
            // (the alpha PTG's constants at 0: MRPT printed "Simulation aborted: unexpected
            // exception!" and ran without the PTG, naming no key)
            for (const char* k : {"num_paths", "resolution", "refDistance", "v_max_mps",
                                  "w_max_dps", "cte_a0v_deg", "cte_a0w_deg"})
                if (c.keyExists(s, prefix + k))
                    core::requireValue(core::readDouble(c, s, prefix + k, 0.0) > 0, s, prefix + k,
                                       "must be > 0");
            // A C PTG's K is its direction, by its sign: +1 forward, -1 backward. At 0 it
            // steered forward and mapped targets backward. A negative priority turned its
            // scores negative.
            if (c.read_string(s, prefix + "Type", "") == "CPTG_DiffDrive_C" &&
                c.keyExists(s, prefix + "K"))
                core::requireValue(core::readDouble(c, s, prefix + "K", 1.0) != 0, s, prefix + "K",
                                   "must not be 0 (its sign is the direction: 1 forward, -1 "
                                   "backward)");
            if (c.keyExists(s, prefix + "score_priority"))
                core::requireValue(core::readDouble(c, s, prefix + "score_priority", 1.0) >= 0, s,
                                   prefix + "score_priority", "must be >= 0");
            // MRPT's clearance analysis (evaluate_clearance) takes clearance_decimated_paths
            // (15) of the paths: fewer stopped it on an assertion that ends mid-sentence.
            if (c.keyExists(s, prefix + "num_paths") &&
                core::readBool(c, "CAbstractPTGBasedReactive", "evaluate_clearance", false)) {
                const double decimated =
                    core::readDouble(c, s, prefix + "clearance_decimated_paths", 15.0);
                core::requireValue(core::readDouble(c, s, prefix + "num_paths", 0.0) >= decimated,
                                   s, prefix + "num_paths",
                                   "must be at least " + prefix + "clearance_decimated_paths (" +
                                       std::to_string(static_cast<int>(decimated)) + ")");
            }
            // Bounds on what MRPT builds at the start, silently: 10000 paths ran for minutes
            // (1000: 7 s), a collision grid of 0.0001 m cells or a 1000 m reference distance
            // ran out of memory ("std::bad_alloc", no key named).
            if (c.keyExists(s, prefix + "num_paths"))
                core::requireValue(core::readDouble(c, s, prefix + "num_paths", 0.0) <= 1000, s,
                                   prefix + "num_paths", "must be at most 1000");
            // (the differential-drive PTGs keep a collision grid; a holonomic one has none)
            if (c.read_string(s, prefix + "Type", "").rfind("CPTG_DiffDrive", 0) != 0) return;
            const double res = core::readDouble(c, s, prefix + "resolution", 0.05);
            const double ref = core::readDouble(c, s, prefix + "refDistance", 2.5);
            // MRPT 2.5's scoring asks each path for its point 1 m along it: a shorter
            // reference distance failed at the first step ("Assert condition failed:
            // pt_in_range", 0.9 m; 0.05 m: "step < m_trajectory[k].size()").
            if (c.keyExists(s, prefix + "refDistance"))
                core::requireValue(ref >= 1.0, s, prefix + "refDistance",
                                   "must be at least 1 m (MRPT 2.5 scores each path at its "
                                   "point 1 m along it)");
            const double side = 2 * ref / res;
            std::ostringstream m;
            m << "with " << prefix << "refDistance " << ref << " m and " << prefix
              << "resolution " << res << " m, the collision grid has " << side << " x " << side
              << " cells (at most 3000 x 3000)";
            // (blamed on the key the file gives, resolution when it gives both)
            const std::string key =
                c.keyExists(s, prefix + "resolution") || !c.keyExists(s, prefix + "refDistance")
                    ? prefix + "resolution"
                    : prefix + "refDistance";
            core::requireValue(side <= 3000, s, key, m.str());
        });
        try {
            (void)CParameterizedTrajectoryGenerator::CreatePTG(
                c.read_string(s, prefix + "Type", ""), c, s, prefix);
        } catch (const std::exception& e) {
            throw std::invalid_argument(
                source + " [" + s + "] " + prefix +
                "*: MRPT refuses this PTG: " + core::innermostMessage(e.what()));
        }
    }
}

}  // namespace devslam::nav
