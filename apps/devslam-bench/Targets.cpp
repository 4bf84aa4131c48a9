#include "Targets.h"

#include <devslam/core/Config.h>
#include <devslam/core/Parse.h>
#include <devslam/core/Stats.h>

#include <mrpt/config/CConfigFileBase.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace devslam::bench {

std::string Target::text() const {
    std::ostringstream s;
    s << sequence << " " << mode << " " << figure << " " << op << " " << value;
    return s.str();
}

bool Target::holds(double m) const {
    if (std::isnan(m)) return false;
    if (op == "<=") return m <= value;
    if (op == "<") return m < value;
    if (op == ">=") return m >= value;
    return m > value;
}

std::vector<Target> loadTargets(const mrpt::config::CConfigFileBase& cfg, const std::string& path,
                                const std::vector<std::string>& sequences,
                                const std::vector<std::string>& modes) {
    // In the file's order: the table lists the targets as the user wrote them.
    const auto keys = core::keysInFileOrder(cfg, path, "targets");
    std::vector<Target> out;
    const auto known = [](const std::vector<std::string>& v, const std::string& x) {
        return std::find(v.begin(), v.end(), x) != v.end();
    };
    const auto list = [](const std::vector<std::string>& v) {
        std::string s;
        for (const auto& x : v) s += (s.empty() ? "" : ", ") + x;
        return s;
    };
    for (const auto& key : keys) {
        const std::string where = path + " [targets] " + key;
        // The key is a cell of targets.csv and of the Markdown table (no quoting there).
        if (key.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789"
                                  "_.-") != std::string::npos)
            throw std::invalid_argument(where + ": a target's name is letters, digits, '_', '.', "
                                                "'-' only (it is a cell of targets.csv)");
        const std::string line = cfg.read_string("targets", key, "");
        std::istringstream in(line);
        Target t;
        t.key = key;
        std::string value, extra;
        if (!(in >> t.sequence >> t.mode >> t.figure >> t.op >> value) || (in >> extra))
            throw std::invalid_argument(where + ": expected 'SEQUENCE MODE FIGURE OP VALUE', got '" +
                                        line + "'");
        if (t.sequence != "*" && !known(sequences, t.sequence))
            throw std::invalid_argument(where + ": unknown sequence '" + t.sequence +
                                        "' (known: *, " + list(sequences) + ")");
        if (!known(modes, t.mode))
            throw std::invalid_argument(where + ": mode '" + t.mode +
                                        "' is not run (modes: " + list(modes) + ")");
        const auto slash = t.figure.find('/');
        const std::string base = t.figure.substr(0, slash);
        if (slash != std::string::npos) {
            const std::string ref = t.figure.substr(slash + 1);
            if (base != "ate" || !known(modes, ref))
                throw std::invalid_argument(where + ": ratio '" + t.figure +
                                            "': only ate/<mode> with a mode that is run (modes: " +
                                            list(modes) + ")");
        } else if (!known({"ate", "fps", "walkers_masked", "static_masked"}, base)) {
            throw std::invalid_argument(
                where + ": unknown figure '" + t.figure +
                "' (known: ate, ate/<mode>, fps, walkers_masked, static_masked)");
        }
        if (!known({"<=", "<", ">=", ">"}, t.op))
            throw std::invalid_argument(where + ": unknown comparison '" + t.op +
                                        "' (known: <=, <, >=, >)");
        t.value = core::parseNumber(value, where);
        out.push_back(t);
    }
    return out;
}

TargetCheck check(const Target& t, const std::vector<SequenceInputs>& sequences,
                  const FigureOf& figure) {
    TargetCheck c;
    const bool upper = t.op[0] == '<';  // the target bounds the figure from above
    for (const auto& q : sequences) {
        if (t.sequence != "*" && q.name != t.sequence) continue;
        const double v = figure(q.name, t.mode, t.figure, std::nullopt);
        if (std::isnan(v)) continue;
        if (std::isnan(c.measured) || (upper ? v > c.measured : v < c.measured)) {
            c.measured = v;
            c.sequence = q.name;
        }
    }
    c.met = t.holds(c.measured);
    return c;
}

InputTally tallyInputs(const Target& t, const std::vector<SequenceInputs>& inputs,
                       const FigureOf& figure) {
    InputTally n;
    const auto count = [&](const std::string& seq, std::optional<std::uint64_t> seed) {
        const double v = figure(seq, t.mode, t.figure, seed);
        if (std::isnan(v)) return;
        ++n.of;
        n.met += t.holds(v);
    };
    for (const auto& in : inputs) {
        if (t.sequence != "*" && in.name != t.sequence) continue;
        if (in.seeds.empty()) count(in.name, std::nullopt);
        for (const auto seed : in.seeds) count(in.name, seed);
    }
    return n;
}

PairedRatio pairedRatio(const Target& t, const std::string& sequence,
                        const std::vector<SequenceInputs>& inputs, const FigureOf& figure) {
    PairedRatio r;
    if (t.figure.find('/') == std::string::npos) return r;
    std::vector<double> logs;
    for (const auto& in : inputs) {
        if (in.name != sequence) continue;
        for (const auto seed : in.seeds) {
            const double v = figure(in.name, t.mode, t.figure, seed);
            if (std::isfinite(v) && v > 0) logs.push_back(std::log(v));
        }
    }
    const auto m = core::meanInterval95(logs);
    r.count = m.count;
    r.geomean = std::exp(m.mean);
    r.lo = std::exp(m.lo);
    r.hi = std::exp(m.hi);
    return r;
}

RenderVerdict renderVerdict(const Target& t, const PairedRatio& p) {
    if (p.count < 2 || !std::isfinite(p.lo) || !std::isfinite(p.hi)) return RenderVerdict::None;
    const bool lo = t.holds(p.lo), hi = t.holds(p.hi);
    if (lo && hi) return RenderVerdict::Met;
    if (!lo && !hi) return RenderVerdict::Missed;
    return RenderVerdict::Open;
}

std::string targetsSummary(int met, std::size_t count, const std::vector<std::string>& open,
                           const std::vector<std::string>& against) {
    const auto names = [](const std::vector<std::string>& keys) {
        std::string s;
        for (std::size_t i = 0; i < keys.size(); ++i)
            s += (i ? (i + 1 == keys.size() ? " and " : ", ") : "") + keys[i];
        return s;
    };
    std::string s =
        std::to_string(met) + " of " + std::to_string(count) + " targets met on the medians.";
    if (!open.empty())
        s += " The per-render interval holds the bound of " + names(open) +
             ": the renders do not settle " + (open.size() > 1 ? "these." : "this one.");
    if (!against.empty())
        s += " The per-render interval lies wholly on the other side of the bound for " +
             names(against) + ".";
    return s;
}

}  // namespace devslam::bench
