#pragma once
/// Presentation of ATE/RPE results: an aligned text table, JSON, and a PNG plot (top view
/// with the estimate coloured by its error, and x/y/z over time).
///
/// Usage:
///   std::cout << devslam::eval::formatTable(&ate, &rpe);
///   devslam::eval::writeJson("eval.json", &ate, &rpe);
///   devslam::eval::plotAte("ate.png", ate, "fr1_xyz_first37");

#include <devslam/eval/Metrics.h>

#include <string>

namespace devslam::eval {

/// Table in the TUM tools' vocabulary; either pointer may be null.
[[nodiscard]] std::string formatTable(const AteResult* ate, const RpeResult* rpe,
                                      const RpeOptions* rpe_opts = nullptr);
/// One JSON object {"ate": {...}, "rpe": {...}}; either pointer may be null.
[[nodiscard]] std::string toJson(const AteResult* ate, const RpeResult* rpe,
                                 const RpeOptions* rpe_opts = nullptr);
/// Writes toJson() to a file; throws std::runtime_error if it cannot.
void writeJson(const std::string& path, const AteResult* ate, const RpeResult* rpe,
               const RpeOptions* rpe_opts = nullptr);
/// 1200x932 PNG: `title` and the ATE RMSE across the top, then the top view (x-y) of ground
/// truth and the aligned estimate coloured by ATE error (blue low, red high) and x, y, z
/// over time. Throws if the file cannot be written.
void plotAte(const std::string& path, const AteResult& ate, const std::string& title);

}  // namespace devslam::eval
