#include "BenchConfig.h"

#include <devslam/core/Config.h>
#include <devslam/core/Parse.h>
#include <devslam/dynamic/DynamicObjectFilter.h>
#include <devslam/eval/MaskScore.h>
#include <devslam/io/RgbdReader.h>

#include <mrpt/config/CConfigFileMemory.h>

#include <algorithm>
#include <filesystem>
#include <limits>
#include <set>
#include <sstream>
#include <stdexcept>

namespace devslam::bench {

namespace fs = std::filesystem;
namespace {
const std::string kRoot = DEVSLAM_SOURCE_DIR;
}  // namespace

std::vector<Input> inputsOf(const Sequence& q, const std::string& out_dir) {
    if (q.scenario.empty()) return {{q.path, std::nullopt}};
    const fs::path synth = fs::path(out_dir) / "synth";
    if (q.seeds.empty()) return {{(synth / q.name).string(), std::nullopt}};
    std::vector<Input> v;
    for (const auto s : q.seeds)
        v.push_back({(synth / (q.name + "_seed" + std::to_string(s))).string(), s});
    return v;
}

namespace {
/// A path from a bench INI: as given when absolute, else from the INI's folder `base` when it
/// is there, else from the repository root.
std::string resolve(const std::string& p, const std::string& base) {
    if (p.empty() || fs::path(p).is_absolute()) return p;
    const fs::path a = fs::path(base) / p;
    if (fs::exists(a)) return a.lexically_normal().string();
    return (fs::path(kRoot) / p).lexically_normal().string();  // repository-relative
}

Bench readBench(const std::string& path) {
    auto cfg = core::loadIni(path);
    Bench b;
    const std::string base = fs::absolute(path).parent_path().string();
    core::requireKnownKeys(
        *cfg, "bench", {"modes", "repeats", "max_frames", "render_jobs", "out_dir", "slam_config"},
        path);
    // Given empty, it ran the default modes without a word.
    if (cfg->keyExists("bench", "modes") &&
        cfg->read_string("bench", "modes", "").find_first_not_of(" \t") == std::string::npos)
        throw std::invalid_argument("[bench] modes: empty (list the devslam-run modes to run)");
    const std::string modes = cfg->read_string("bench", "modes", "");
    if (!modes.empty()) {
        b.modes.clear();
        std::istringstream ss(modes);
        for (std::string m; ss >> m;) {
            if (m != "truth") {
                try {
                    (void)dynamic::parseMaskMode(m);  // throws with the known names
                } catch (const std::invalid_argument& e) {
                    throw std::invalid_argument("[bench] modes: " + std::string(e.what()) +
                                                " or truth");
                }
            }
            // Runs are kept in <out>/runs/SEQ/MODE: a mode twice would run into one folder.
            if (std::find(b.modes.begin(), b.modes.end(), m) != b.modes.end())
                throw std::invalid_argument("[bench] modes: '" + m + "' is listed twice");
            b.modes.push_back(m);
        }
    }
    b.repeats = core::readInt(*cfg, "bench", "repeats", b.repeats);
    const int max_frames = core::readInt(*cfg, "bench", "max_frames", 0);
    core::requireValue(max_frames >= 0, "bench", "max_frames",
                       "must be >= 0 (0 = whole sequences)");
    b.max_frames = std::size_t(max_frames);
    b.render_jobs = core::readInt(*cfg, "bench", "render_jobs", 0);
    core::requireValue(b.render_jobs >= 0 && b.render_jobs <= 64, "bench", "render_jobs",
                       "must be 0..64 (0 = the CPU's threads)");
    b.out_dir = cfg->read_string("bench", "out_dir", b.out_dir);
    b.slam_config = resolve(cfg->read_string("bench", "slam_config", b.slam_config), base);
    core::requireValue(b.repeats >= 1 && b.repeats <= 100, "bench", "repeats", "must be 1..100");
    core::requireKnownSections(*cfg, {"bench", "sequence_*", "targets"}, path);
    std::set<std::string> checked_configs;  // SLAM INIs read and their filter made, below
    // In the file's order: the tables list the sequences as the user wrote them.
    for (const auto& s : core::sectionsInFileOrder(*cfg, path)) {
        if (s.rfind("sequence_", 0) != 0) continue;  // [bench], [targets]
        core::requireKnownKeys(
            *cfg, s, {"name", "path", "scenario", "slam_config", "seeds", "set", "repeats"}, path);
        Sequence q;
        q.name = cfg->read_string(s, "name", s.substr(9));
        q.scenario = cfg->read_string(s, "scenario", "");
        // A scenario file (not a name devslam-synth finds in sim_worlds/synth) is found as
        // `path` is, from the bench INI's folder first: devslam-synth would look in the
        // working directory.
        if (q.scenario.find('/') != std::string::npos || core::endsWithNoCase(q.scenario, ".ini"))
            q.scenario = resolve(q.scenario, base);
        q.path = resolve(cfg->read_string(s, "path", ""), base);
        q.slam_config = resolve(cfg->read_string(s, "slam_config", ""), base);
        if (q.slam_config.empty()) q.slam_config = b.slam_config;
        // Found now, not as every run of the sequence failing after minutes of work.
        if (!fs::is_regular_file(q.slam_config)) {
            const std::string section =
                cfg->keyExists(s, "slam_config") ? s : std::string("bench");
            const std::string given = cfg->read_string(section, "slam_config", "");
            const std::string beside =
                given.empty() ? "" : (fs::path(base) / given).lexically_normal().string();
            throw std::invalid_argument(
                path + " [" + section + "] slam_config: " +
                (fs::is_directory(q.slam_config) ? "'" + q.slam_config + "' is a folder, not a file"
                                                 : "no such file '" + q.slam_config + "'") +
                // (a relative name is looked for beside the INI first: say so)
                (!given.empty() && fs::path(given).is_relative() && beside != q.slam_config
                     ? " (nor '" + beside + "')"
                     : std::string()));
        }
        // ... and read, with the filter INI it names: a syntax error in the last sequence's
        // INI stopped the bench there, hours into it, with no table. The filter and its
        // detector are made from them too: a mistyped [detector] key or a missing weights
        // file failed only the runs that detect, after the renders and the other modes' runs.
        // (Once per SLAM INI: most sequences share one, and each check loads the detector.)
        if (checked_configs.insert(q.slam_config).second) {
            std::string filter_source;
            const auto filter_cfg = core::loadFilterConfig(q.slam_config, &filter_source);
            core::namingSource(filter_source,
                               [&] { (void)dynamic::makeFilterFromConfig(*filter_cfg); });
        }
        if (!q.path.empty() && !fs::exists(q.path))
            throw std::invalid_argument(path + " [" + s + "] path: no such file or folder '" +
                                        q.path + "'");
        // A folder must be a TUM sequence (its lists are read now; a rawlog's frames are
        // counted only when it is run, which reads it whole).
        if (!q.path.empty() && fs::is_directory(q.path)) try {
                (void)io::openRgbd(q.path);
            } catch (const std::exception& e) {
                throw std::invalid_argument(path + " [" + s + "] path: " + e.what());
            }
        q.where = path + " [" + s + "]";
        // The name is a folder and a file name prefix, and a cell of runs.csv.
        if (q.name.empty() ||
            q.name.find_first_not_of(
                "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789"
                "_.-") != std::string::npos ||
            q.name == "." || q.name == "..")
            throw std::invalid_argument(
                path + " [" + s + "] name: '" + q.name + "' (" +
                (q.name == "." || q.name == ".." ? "'.' and '..' are taken by every folder"
                                                 : "letters, digits, '_', '.', '-' only") +
                ": it names folders, files and a CSV column)");
        if (q.scenario.empty() && q.path.empty())
            throw std::invalid_argument(path + " [" + s +
                                        "]: give 'path' (a TUM folder) or 'scenario' (synthetic)");
        if (!q.scenario.empty() && !q.path.empty())  // the path was ignored without a word
            throw std::invalid_argument(path + " [" + s +
                                        "]: give 'path' (a TUM folder) or 'scenario' "
                                        "(synthetic), not both");
        const std::string where = path + " [" + s + "]";
        std::istringstream seeds(cfg->read_string(s, "seeds", ""));
        for (std::string w; seeds >> w;) {
            const auto seed = std::uint64_t(core::parseInteger(
                w, where + " seeds", 0, std::numeric_limits<std::uint32_t>::max()));
            if (std::find(q.seeds.begin(), q.seeds.end(), seed) != q.seeds.end())
                throw std::invalid_argument(where + " seeds: seed " + w + " is listed twice");
            q.seeds.push_back(seed);
        }
        if (!q.seeds.empty() && q.scenario.empty())
            throw std::invalid_argument(where +
                                        " seeds: only a synthetic sequence (scenario) has renders");
        // Whitespace-separated, as [run] filter_overrides; the format is checked here, the
        // sections and keys by devslam-synth --check before any render (devslam-bench).
        q.sets = core::overrideItems(cfg->read_string(s, "set", ""), where + " set");
        if (!q.sets.empty() && q.scenario.empty())
            throw std::invalid_argument(where + " set: only a synthetic sequence (scenario) " +
                                        "has render settings");
        {
            mrpt::config::CConfigFileMemory scratch;
            core::applyOverrides(scratch, q.sets, where + " set item");
        }
        q.repeats = core::readInt(*cfg, s, "repeats", 0);
        core::requireValue(q.repeats >= 0 && q.repeats <= 100, s, "repeats",
                           "must be 1..100 (0 or missing = [bench] repeats)");
        // The name is the runs' and renders' folder: two sequences of one name would write
        // over each other's runs and mix them in one row.
        for (const auto& other : b.sequences)
            if (other.name == q.name)
                throw std::invalid_argument(where + " name: '" + q.name +
                                            "' is already the name of an earlier sequence");
        // Nor may their renders share a folder: 'a_seed1' renders where 'a' with seed 1 does.
        for (const auto& other : b.sequences)
            for (const auto& mine : inputsOf(q, "out"))
                for (const auto& theirs : inputsOf(other, "out"))
                    if (!q.scenario.empty() && !other.scenario.empty() && mine.path == theirs.path)
                        throw std::invalid_argument(
                            where + " name: its render " + fs::path(mine.path).filename().string() +
                            " would share a folder with sequence '" + other.name + "''s");
        b.sequences.push_back(q);
    }
    if (b.sequences.empty()) throw std::invalid_argument(path + ": no [sequence_*] section");
    // Mode truth runs only where there is person truth (renders); with none it would run
    // nothing and leave its column empty.
    if (std::find(b.modes.begin(), b.modes.end(), "truth") != b.modes.end() &&
        std::none_of(b.sequences.begin(), b.sequences.end(), [](const Sequence& q) {
            return !q.scenario.empty() || eval::PersonTruth::available(q.path);
        }))
        throw std::invalid_argument(path +
                                    " [bench] modes: truth needs person truth, which "
                                    "no sequence has (a scenario, or a devslam-synth "
                                    "folder as path)");
    b.targets = loadTargets(*cfg, path, b.names(), b.modes);
    return b;
}

}  // namespace

/// readBench, with the file named in front of the "[section] key: ..." errors of the
/// strict readers.
Bench loadBench(const std::string& path) {
    return core::namingSource(path, [&] { return readBench(path); });
}

bool runsMode(const Sequence& q, const std::string& out_dir, const std::string& mode) {
    return mode != "truth" || eval::PersonTruth::hasWalkers(inputsOf(q, out_dir).front().path);
}

}  // namespace devslam::bench
