#pragma once
/// Timestamp association exactly as the TUM benchmark's associate.py: every pair with
/// |a - (b + offset)| < max_dt is a candidate; candidates are taken greedily by increasing
/// |difference|, and each stamp is used at most once. Output sorted by `a`.
///
/// Usage:
///   auto pairs = devslam::core::associate(rgb_stamps, depth_stamps, 0.02);
///   for (auto [i, j] : pairs) { ... rgb[i] with depth[j] ... }

#include <cstddef>
#include <utility>
#include <vector>

namespace devslam::core {

/// Index pairs (i into a, j into b). Neither input needs to be sorted.
[[nodiscard]] std::vector<std::pair<std::size_t, std::size_t>> associate(
    const std::vector<double>& a, const std::vector<double>& b, double max_dt = 0.02,
    double offset = 0.0);

}  // namespace devslam::core
