#pragma once
/// Local bundle adjustment: the poses of the newest keyframes and every landmark they see
/// are refined together (keyframes outside the window that see those landmarks are held
/// fixed), minimising the same reprojection + virtual-right-coordinate residuals as the
/// tracker, with a Huber kernel. Own Levenberg-Marquardt on Eigen with the Schur
/// complement on the 3x3 landmark blocks (a dense reduced camera system of 6 x keyframes:
/// the local window, or every keyframe for the final BA, LocalBaOptions::final_window).
///
/// Usage:
///   auto r = devslam::slam::localBundleAdjust(map, newest_kf, K, opts);
/// Not thread-safe (modifies `map`).
#include <devslam/core/Camera.h>
#include <devslam/slam/Map.h>

#include <string>

namespace mrpt::config {
class CConfigFileBase;
}

namespace devslam::slam {

struct LocalBaOptions {
    bool enabled = true;
    int window = 5;      ///< keyframes optimised (newest ones), 2..30
    int iterations = 8;  ///< LM iterations (per round)
    /// rounds after the first, each without the observations the previous round left
    /// outside chi2 (ORB-SLAM2 local BA: 1)
    int outlier_rounds = 1;
    double bf = 40.0;            ///< [px*m] virtual baseline * fx (as the tracker)
    double chi2_mono = 5.991;    ///< outlier test for 2-dof residuals (Huber width too)
    double chi2_stereo = 7.815;  ///< for 3-dof residuals
    double scale_factor = 1.3;   ///< ORB pyramid scale (level sigmas), copied from [orb]
    /// [m] when > 0, an optimisation that moves a keyframe farther than this is not
    /// applied (the map stays as it was, no observation removed either). The
    /// keyframes were tracked frame to frame, and a local BA refines them by millimetres to
    /// a few centimetres; a shift of decimetres comes from a window barely tied to the
    /// keyframes held fixed (few shared observations when the mask covers most of the
    /// image: the window's own points then fit it better elsewhere; docs/slam.md, session
    /// 20), and it drags the keyframes, and every frame tracked from them, away at once.
    double max_keyframe_shift = 0.0;
    /// keyframes adjusted by the last BA, at the end of the run (Slam::finalize): 0 = the
    /// last `window`, as after every keyframe; N = the newest N (all of them when the map
    /// has fewer; keyframe 0 stays the gauge): ORB-SLAM2's global BA, on a dense reduced
    /// system of 6N unknowns (0.06-1.4 s for the 16-168 keyframes of the bench's runs), 0..1000
    int final_window = 0;

    void loadFromConfig(const mrpt::config::CConfigFileBase& cfg,
                        const std::string& section = "local_ba");
    void saveToConfig(mrpt::config::CConfigFileBase& cfg,
                      const std::string& section = "local_ba") const;
};

struct LocalBaResult {
    int n_keyframes = 0;        ///< optimised
    int n_fixed_keyframes = 0;  ///< seen, held fixed
    int n_landmarks = 0;
    int n_observations = 0;
    int iterations = 0;
    double initial_cost = 0.0;  ///< robust cost (sum of Huber-weighted chi2)
    double final_cost = 0.0;
    int n_outliers_removed = 0;  ///< observations removed after the optimisation
    double max_shift = 0.0;      ///< [m] largest keyframe translation the optimisation found
    bool rejected = false;       ///< not applied: max_shift > max_keyframe_shift
};

/// Optimises the window ending at `newest`. Keyframe 0 (the gauge) is never moved.
[[nodiscard]] LocalBaResult localBundleAdjust(Map& map, KeyframeId newest,
                                              const core::CameraIntrinsics& K,
                                              const LocalBaOptions& opts);

}  // namespace devslam::slam
