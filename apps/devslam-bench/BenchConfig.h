#pragma once
// devslam-bench's INI (config_ini/bench.ini): [bench], the [sequence_*] it runs on and their
// renders, and [targets]. Read strictly: every error names the file, section and key, found
// before any render or run.
#include "Targets.h"

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace devslam::bench {

struct Sequence {
    std::string name;      ///< table row label
    std::string where;     ///< "<bench INI> [sequence_x]", for messages
    std::string path;      ///< real data: TUM folder or rawlog
    std::string scenario;  ///< synthetic: scenario name/file (rendered when missing)
    std::string slam_config;
    /// Synthetic: renders of the scenario (`devslam-synth --seed`); empty = the scenario's
    /// own seed, one render.
    std::vector<std::uint64_t> seeds;
    /// Synthetic: `devslam-synth --set` items (SECTION.KEY=VALUE) over the scenario file, e.g.
    /// the same scene with still people; empty = the scenario as shipped.
    std::vector<std::string> sets;
    int repeats = 0;  ///< runs per render and mode; 0 = [bench] repeats
};

/// One input the SLAM runs on: a render of a synthetic sequence, or the real data.
struct Input {
    std::string path;
    std::optional<std::uint64_t> seed;  ///< the render's seed when it was given
};

/// Where the renders of a sequence go: <out>/synth/<name> (scenario's seed) or
/// <out>/synth/<name>_seed<S>.
[[nodiscard]] std::vector<Input> inputsOf(const Sequence& q, const std::string& out_dir);

struct Bench {
    std::vector<std::string> modes{"none", "all_persons", "dynamic"};
    int repeats = 5;
    std::size_t max_frames = 0;
    int render_jobs = 0;  ///< renders made at once; 0 = the CPU's threads
    std::string out_dir = "out/bench";
    std::string slam_config = std::string(DEVSLAM_SOURCE_DIR) + "/config_ini/slam_synthetic.ini";
    std::vector<Sequence> sequences;
    std::vector<Target> targets;  ///< [targets], checked on the medians
    [[nodiscard]] std::vector<std::string> names() const {
        std::vector<std::string> v;
        for (const auto& q : sequences) v.push_back(q.name);
        return v;
    }
};

/// Reads a bench INI; throws std::invalid_argument naming the file, section and key for
/// anything the bench could not run (unknown keys, a missing path or SLAM INI, seeds listed
/// twice, sequence names that would share folders, bad targets).
[[nodiscard]] Bench loadBench(const std::string& path);

/// devslam-run's diagnostic mode `truth` (the renderer's walkers as the mask) needs the
/// person truth that devslam-synth writes, and someone walking in it: sequences without
/// truth skip that mode, and so do renders without walkers, where its mask is empty in
/// every frame and its run would repeat mode `none`'s to the digit. Call it once the first
/// render exists.
[[nodiscard]] bool runsMode(const Sequence& q, const std::string& out_dir, const std::string& mode);

}  // namespace devslam::bench
