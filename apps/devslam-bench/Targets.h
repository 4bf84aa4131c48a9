#pragma once
// devslam-bench's [targets]: goals such as "walking_xyz dynamic ate <= 0.015", checked on the
// bench's own medians and written with them, so that whether a target is met is measured by
// the same command as the tables, never typed by hand.
//
//   [targets]
//   walking_xyz_ate = walking_xyz dynamic ate <= 0.015
//   sitting_vs_mask = sitting_xyz dynamic ate/all_persons < 1
//   walkers         = * dynamic walkers_masked >= 0.9      // every sequence that has it
#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace mrpt::config {
class CConfigFileBase;
}

namespace devslam::bench {

struct Target {
    std::string key;       ///< INI key (its name in messages)
    std::string sequence;  ///< a [sequence_*] name, or "*" = every sequence with the figure
    std::string mode;
    std::string figure;    ///< ate | fps | walkers_masked | static_masked | ate/<mode>
    std::string op;        ///< <= < >= >
    double value = 0;
    [[nodiscard]] std::string text() const;  ///< "walking_xyz dynamic ate <= 0.015"
    [[nodiscard]] bool holds(double measured) const;
};

/// Reads [targets] (each key one target, "SEQUENCE MODE FIGURE OP VALUE"); throws
/// std::invalid_argument naming `path`, the section and the key for a malformed target, an
/// unknown sequence, mode or figure.
[[nodiscard]] std::vector<Target> loadTargets(const mrpt::config::CConfigFileBase& cfg,
                                              const std::string& path,
                                              const std::vector<std::string>& sequences,
                                              const std::vector<std::string>& modes);

/// The bench's median of a figure for (sequence, mode), over all its runs, or over the runs
/// on one render when `seed` is given; NaN where it has none (a mode that did not run, no
/// walkers in the sequence, ...).
using FigureOf = std::function<double(const std::string& sequence, const std::string& mode,
                                      const std::string& figure,
                                      std::optional<std::uint64_t> seed)>;

struct TargetCheck {
    double measured = std::numeric_limits<double>::quiet_NaN();  ///< NaN: no figure
    std::string sequence;  ///< where it was measured (for "*": the worst sequence)
    bool met = false;
};

/// A sequence and its renders (seeds; none: one input, a real sequence or a single render).
struct SequenceInputs {
    std::string name;
    std::vector<std::uint64_t> seeds;
};

/// Evaluates a target on the medians over all runs; for "*" the sequence whose figure is
/// furthest from the target (largest for <=, <; smallest for >=, >) decides.
[[nodiscard]] TargetCheck check(const Target& t, const std::vector<SequenceInputs>& sequences,
                                const FigureOf& figure);

/// How many inputs meet a target on their own figure (each render's median over its
/// repeats; a ratio compares the two modes on the same render): says whether the median
/// meets or misses the target on most renders, or only by the spread between them.
struct InputTally {
    int met = 0;
    int of = 0;  ///< inputs with the figure
};
[[nodiscard]] InputTally tallyInputs(const Target& t, const std::vector<SequenceInputs>& inputs,
                                     const FigureOf& figure);

/// For a ratio target (ate/<mode>) on one sequence: the geometric mean of its per-render
/// ratios and that mean's 95 % confidence interval (Student's t on the ratios' logarithms; the
/// two modes run on the same renders, so the ratios are paired samples). An interval that
/// holds 1 says the renders do not tell the two modes apart, however the median falls.
/// count: renders with both figures; NaN where the target is no ratio or none has them, NaN
/// bounds below two renders.
struct PairedRatio {
    std::size_t count = 0;
    double geomean = std::numeric_limits<double>::quiet_NaN();
    double lo = std::numeric_limits<double>::quiet_NaN();
    double hi = std::numeric_limits<double>::quiet_NaN();
};
[[nodiscard]] PairedRatio pairedRatio(const Target& t, const std::string& sequence,
                                      const std::vector<SequenceInputs>& inputs,
                                      const FigureOf& figure);

/// What a ratio target's per-render interval says of its bound: both ends meet it (Met), both
/// miss it (Missed), or the bound lies inside (Open: the renders cannot tell whether the target
/// holds, however the medians fall); None without an interval (no ratio, under two renders).
enum class RenderVerdict { None, Met, Missed, Open };
[[nodiscard]] RenderVerdict renderVerdict(const Target& t, const PairedRatio& p);

/// The sentence under the targets table: "5 of 7 targets met on the medians.", then the keys
/// whose interval is Open, and those whose interval lies wholly against the medians' verdict.
[[nodiscard]] std::string targetsSummary(int met, std::size_t count,
                                         const std::vector<std::string>& open,
                                         const std::vector<std::string>& against);

}  // namespace devslam::bench
