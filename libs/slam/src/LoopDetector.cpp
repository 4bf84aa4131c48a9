#include <devslam/core/Config.h>
#include <devslam/slam/LoopDetector.h>
#include <devslam/slam/Matching.h>

#include <mrpt/config/CConfigFileBase.h>

#include <algorithm>
#include <cmath>

namespace devslam::slam {

void LoopOptions::loadFromConfig(const mrpt::config::CConfigFileBase& c, const std::string& s) {
    core::requireKnownKeys(
        c, s,
        {"enabled", "min_keyframe_gap", "cooldown_keyframes", "max_distance", "max_candidates",
         "max_hamming", "ratio", "min_inliers", "sigma_t", "sigma_r_deg", "max_correction",
         "max_correction_deg", "confirm_keyframes", "confirm_t", "confirm_deg"});
    enabled = core::readBool(c, s, "enabled", enabled);
    min_keyframe_gap = core::readInt(c, s, "min_keyframe_gap", min_keyframe_gap);
    cooldown_keyframes = core::readInt(c, s, "cooldown_keyframes", cooldown_keyframes);
    max_distance = core::readDouble(c, s, "max_distance", max_distance);
    max_candidates = core::readInt(c, s, "max_candidates", max_candidates);
    max_hamming = core::readInt(c, s, "max_hamming", max_hamming);
    ratio = core::readDouble(c, s, "ratio", ratio);
    min_inliers = core::readInt(c, s, "min_inliers", min_inliers);
    max_correction = core::readDouble(c, s, "max_correction", max_correction);
    max_correction_deg = core::readDouble(c, s, "max_correction_deg", max_correction_deg);
    confirm_keyframes = core::readInt(c, s, "confirm_keyframes", confirm_keyframes);
    confirm_t = core::readDouble(c, s, "confirm_t", confirm_t);
    confirm_deg = core::readDouble(c, s, "confirm_deg", confirm_deg);
    sigma_t = core::readDouble(c, s, "sigma_t", sigma_t);
    sigma_r_deg = core::readDouble(c, s, "sigma_r_deg", sigma_r_deg);
    core::requireValue(min_keyframe_gap >= 1, s, "min_keyframe_gap", "must be >= 1");
    core::requireValue(cooldown_keyframes >= 0, s, "cooldown_keyframes", "must be >= 0");
    core::requireValue(max_candidates >= 1 && max_candidates <= 1000, s, "max_candidates",
                       "must be in [1, 1000]");
    core::requireValue(max_hamming > 0 && max_hamming <= 256, s, "max_hamming",
                       "must be in (0, 256]");
    core::requireValue(ratio > 0 && ratio <= 1, s, "ratio", "must be in (0, 1]");
    core::requireValue(max_distance > 0, s, "max_distance", "must be > 0");
    core::requireValue(min_inliers >= 6, s, "min_inliers", "must be >= 6");
    core::requireValue(max_correction > 0, s, "max_correction", "must be > 0 [m]");
    core::requireValue(max_correction_deg > 0, s, "max_correction_deg", "must be > 0");
    core::requireValue(confirm_keyframes >= 0, s, "confirm_keyframes", "must be >= 0");
    core::requireValue(confirm_t > 0, s, "confirm_t", "must be > 0 [m]");
    core::requireValue(confirm_deg > 0, s, "confirm_deg", "must be > 0");
    // The pose graph's information is 1 / sigma^2: 1e-200 made it inf, 1e200 zero.
    core::requireValue(sigma_t >= 1e-6 && sigma_t <= 1e3, s, "sigma_t",
                       "must be in [1e-6, 1e3] [m]");
    core::requireValue(sigma_r_deg >= 1e-6 && sigma_r_deg <= 1e3, s, "sigma_r_deg",
                       "must be in [1e-6, 1e3] [deg]");
}

void LoopOptions::saveToConfig(mrpt::config::CConfigFileBase& c, const std::string& s) const {
    core::writeKey(c, s, "enabled", enabled);
    core::writeKey(c, s, "min_keyframe_gap", min_keyframe_gap);
    core::writeKey(c, s, "cooldown_keyframes", cooldown_keyframes);
    core::writeKey(c, s, "max_distance", max_distance);
    core::writeKey(c, s, "max_candidates", max_candidates);
    core::writeKey(c, s, "max_hamming", max_hamming);
    core::writeKey(c, s, "ratio", ratio);
    core::writeKey(c, s, "min_inliers", min_inliers);
    core::writeKey(c, s, "max_correction", max_correction);
    core::writeKey(c, s, "max_correction_deg", max_correction_deg);
    core::writeKey(c, s, "confirm_keyframes", confirm_keyframes);
    core::writeKey(c, s, "confirm_t", confirm_t);
    core::writeKey(c, s, "confirm_deg", confirm_deg);
    core::writeKey(c, s, "sigma_t", sigma_t);
    core::writeKey(c, s, "sigma_r_deg", sigma_r_deg);
}

bool loopsAgree(const Map& map, const LoopConstraint& a, const LoopConstraint& b, double max_t,
                double max_deg) {
    const auto pose = [&](KeyframeId id) { return map.keyframe(id).T_wc; };
    const Eigen::Isometry3d via_loops =
        (pose(a.old_kf) * a.T_old_new).inverse() * (pose(b.old_kf) * b.T_old_new);
    const Eigen::Isometry3d via_map = pose(a.new_kf).inverse() * pose(b.new_kf);
    const Eigen::Isometry3d d = via_map.inverse() * via_loops;
    return d.translation().norm() <= max_t &&
           Eigen::AngleAxisd(d.linear()).angle() <= max_deg * M_PI / 180.0;
}

std::optional<LoopConstraint> detectLoop(const Map& map, KeyframeId current,
                                         const core::CameraIntrinsics& K, const LoopOptions& opts,
                                         const PoseRefineOptions& refine) {
    if (!opts.enabled) return std::nullopt;
    const Keyframe& cur = map.keyframe(current);
    std::vector<std::pair<double, KeyframeId>> cands;
    for (const auto& [id, kf] : map.keyframes()) {
        if (id > current - opts.min_keyframe_gap) break;  // std::map: ascending ids
        const double d = (kf.T_wc.translation() - cur.T_wc.translation()).norm();
        if (d <= opts.max_distance) cands.emplace_back(d, id);
    }
    std::sort(cands.begin(), cands.end());
    if (static_cast<int>(cands.size()) > opts.max_candidates) cands.resize(opts.max_candidates);
    std::optional<LoopConstraint> best;
    for (const auto& [d, id] : cands) {
        const Keyframe& old = map.keyframe(id);
        // The old keyframe's own keypoints with depth, in its camera frame: the measured
        // relative pose depends on the two keyframes' images only, not on how the map
        // between them was adjusted.
        std::vector<int> rows;
        for (int i = 0; i < static_cast<int>(old.features.size()); ++i)
            if (old.features.depth[i] > 0) rows.push_back(i);
        if (static_cast<int>(rows.size()) < opts.min_inliers) continue;
        cv::Mat train(static_cast<int>(rows.size()), 32, CV_8U);
        for (std::size_t r = 0; r < rows.size(); ++r)
            old.features.descriptors.row(rows[r]).copyTo(train.row(static_cast<int>(r)));
        const auto pairs =
            matchBruteForce(cur.features.descriptors, train, opts.max_hamming, opts.ratio);
        if (static_cast<int>(pairs.size()) < opts.min_inliers) continue;
        std::vector<PoseObservation> obs;
        for (const auto& [q, t] : pairs)
            obs.push_back(
                observationOf(cur.features, q, old.features.points_c[rows[t]], opts.scale_factor));
        if (!inlierBoundReaches(obs, opts.min_inliers, K, refine)) continue;  // none could pass
        PnpRansacOptions pnp;
        pnp.iterations = 300;
        pnp.min_inliers = opts.min_inliers;
        const auto sol = solvePnpRansac(obs, K, pnp);
        if (!sol) continue;
        const auto ref = refinePose(obs, sol->T_wc, K, refine);
        if (ref.n_inliers < opts.min_inliers) continue;
        const Eigen::Isometry3d correction = (old.T_wc.inverse() * cur.T_wc).inverse() * ref.T_wc;
        if (correction.translation().norm() > opts.max_correction ||
            Eigen::AngleAxisd(correction.linear()).angle() > opts.max_correction_deg * M_PI / 180.0)
            continue;
        if (!best || ref.n_inliers > best->n_inliers)
            best = LoopConstraint{id, current, ref.T_wc, ref.n_inliers};
    }
    return best;
}

}  // namespace devslam::slam
