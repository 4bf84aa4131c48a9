#pragma once
/// Loop detection: descriptor matching of a new keyframe against older keyframes near
/// its current pose estimate, geometric verification by PnP-RANSAC + refinement on the
/// old keyframe's own keypoints with depth (not its landmarks: the measured relative pose
/// depends on the two images only). Pure function.
///
/// Usage:
///   if (auto loop = devslam::slam::detectLoop(map, kf_id, K, opts)) edges.push_back(...);
#include <devslam/core/Camera.h>
#include <devslam/slam/Map.h>
#include <devslam/slam/PoseSolver.h>

#include <optional>
#include <string>

namespace mrpt::config {
class CConfigFileBase;
}

namespace devslam::slam {

struct LoopOptions {
    bool enabled = true;
    int min_keyframe_gap = 20;   ///< candidates are at least this many keyframes older
    /// after a loop closed at keyframe N, the next loop search is at keyframe N + this
    /// (the keyframes in between are not searched; 0 and 1: no pause)
    int cooldown_keyframes = 5;
    double max_distance = 1.0;   ///< [m] candidate keyframes within this of the current pose
    int max_candidates = 3;      ///< nearest candidates verified
    int max_hamming = 50;        ///< descriptor threshold
    double ratio = 0.8;          ///< ratio test
    int min_inliers = 40;        ///< verified inliers for a loop
    /// A verified loop whose measured relative pose differs from the current estimate's
    /// by more than this is rejected: repeated textures (the same poster on two walls) can
    /// verify a false loop with many inliers, and one false loop wrecks the whole graph.
    double max_correction = 0.25;      ///< [m]
    double max_correction_deg = 10.0;  ///< [deg]
    /// Temporal consistency: a verified loop is closed only once one of the next
    /// `confirm_keyframes` keyframes also verifies a loop that agrees with it (the relative
    /// pose of the two new keyframes the loops imply matches the map's own within
    /// confirm_t / confirm_deg); then both are closed. 0: every verified loop is closed.
    int confirm_keyframes = 0;
    double confirm_t = 0.02;           ///< [m]
    double confirm_deg = 1.0;          ///< [deg]
    double sigma_t = 0.02;             ///< [m] loop-edge translation std (pose-graph information)
    double sigma_r_deg = 1.0;          ///< [deg] loop-edge rotation std
    double scale_factor = 1.3;         ///< ORB pyramid scale for level sigmas (copied from [orb])

    void loadFromConfig(const mrpt::config::CConfigFileBase& cfg,
                        const std::string& section = "loop_closure");
    void saveToConfig(mrpt::config::CConfigFileBase& cfg,
                      const std::string& section = "loop_closure") const;
};

struct LoopConstraint {
    KeyframeId old_kf = kNoId, new_kf = kNoId;
    Eigen::Isometry3d T_old_new;  ///< measured pose of the new keyframe in the old one
    int n_inliers = 0;
};

/// Whether two verified loops agree (see LoopOptions::confirm_keyframes): the pose of b's new
/// keyframe in a's new keyframe, as the two loops and the old keyframes' poses imply it,
/// against the same from the map's new-keyframe poses.
[[nodiscard]] bool loopsAgree(const Map& map, const LoopConstraint& a, const LoopConstraint& b,
                              double max_t, double max_deg);

/// Looks for a loop between `current` and older keyframes (see LoopOptions).
[[nodiscard]] std::optional<LoopConstraint> detectLoop(const Map& map, KeyframeId current,
                                                       const core::CameraIntrinsics& K,
                                                       const LoopOptions& opts,
                                                       const PoseRefineOptions& refine = {});

}  // namespace devslam::slam
