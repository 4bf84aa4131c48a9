#pragma once
// devslam-bench's reading of one devslam-run run.json: the figures of Tables 1-3 and of the
// mask against the renderer's truth, each found by its whole path ("ate.median", never the
// first "median" after "ate"), and why a file is not kept when it is not a whole run.json.
//
//   const RunFigures f = readRun(dir + "/run.json");
//   if (!f.ok) std::cerr << (f.unreadable.empty() ? "the run failed" : f.unreadable);
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>

namespace devslam::bench {

/// One JSON scalar as written: a number's text, or a string's contents without its quotes
/// (escapes kept as they are), or true/false/null.
struct JsonScalar {
    bool string = false;
    std::string text;
};

/// Every scalar of `js` outside arrays, by its dotted path ("rpe_1s.trans.rmse"; "" for a
/// top-level scalar); values inside arrays are checked, not kept. nullopt when `js` is not one
/// whole JSON value (empty, cut short, garbage, or followed by anything but white space).
[[nodiscard]] std::optional<std::map<std::string, JsonScalar>> jsonScalars(const std::string& js);

/// One run's figures. NaN for a figure the run has not (no ground truth, no person truth,
/// too short for the RPE over 1 s).
struct RunFigures {
    double ate_rmse = 0, ate_mean = 0, ate_median = 0;
    double rpe_t_rmse = 0, rpe_t_mean = 0, rpe_t_median = 0;
    double rpe_r_rmse = 0, rpe_r_mean = 0, rpe_r_median = 0;
    double fps_median = 0, fps_mean = 0, lost = 0;
    // The run's masks against the renderer's person truth (NaN for real data)
    double moving_recall = NAN, moving_area_recall = NAN, mask_precision = NAN, static_masked = NAN,
           moving_instances = NAN, static_instances = NAN;
    // The map at the end of the run (NaN in a run.json from before they were written)
    double keyframes = NAN, landmarks = NAN, map_mb = NAN;
    std::optional<std::uint64_t> seed;  ///< the render it ran on (synthetic, seeded)
    std::filesystem::path dir;          ///< its output folder
    bool ok = false;         ///< a whole run over the whole input: no read error, not interrupted
    std::string unreadable;  ///< a run.json that is there but not a whole run.json: why
};

/// The figures of the run.json at `json_path`. A missing file gives ok = false with
/// `unreadable` empty (the run wrote nothing); a file that is not one whole JSON object, or
/// lacks a key devslam-run always writes, gives ok = false and says why in `unreadable`.
[[nodiscard]] RunFigures readRun(const std::string& json_path);

}  // namespace devslam::bench
