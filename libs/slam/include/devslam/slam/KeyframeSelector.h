#pragma once
/// When does a tracked frame become a keyframe? A pure rule set in the spirit of
/// ORB-SLAM2's RGB-D rules (tracked fraction of the reference keyframe, new close
/// structure, a maximum interval) plus a motion rule.
///
/// Usage:
///   auto d = devslam::slam::decideKeyframe(in, opts);
///   if (d.insert) ... ;   // d.reason says which rule fired
#include <string>

namespace mrpt::config {
class CConfigFileBase;
}

namespace devslam::slam {

struct KeyframeSelectorOptions {
    int min_frames = 0;              ///< frames since the last keyframe before any rule but motion
    int max_frames = 20;             ///< a keyframe at least every max_frames tracked frames
    double min_tracked_ratio = 0.9;  ///< tracked < ratio * reference count (below) -> new one
    int min_tracked = 15;            ///< never insert a keyframe tracked on fewer inliers
    int close_tracked_below = 100;   ///< "needs close structure": tracked close points below this
    int close_untracked_above = 70;  ///< ...and untracked close points (with depth) above this
    double max_translation = 0.10;   ///< [m] from the last keyframe
    double max_rotation_deg = 10.0;  ///< [deg] from the last keyframe

    void loadFromConfig(const mrpt::config::CConfigFileBase& cfg,
                        const std::string& section = "keyframes");
    void saveToConfig(mrpt::config::CConfigFileBase& cfg,
                      const std::string& section = "keyframes") const;
};

struct KeyframeSelectorInput {
    int frames_since_last_kf = 0;  ///< tracked frames since the last keyframe
    int n_tracked = 0;             ///< inlier landmarks in this frame
    int n_tracked_at_last_kf = 0;  ///< inliers of the first frame tracked after the last keyframe
    int n_close_tracked = 0;       ///< tracked keypoints with depth
    int n_close_untracked = 0;     ///< keypoints with depth and no landmark
    double translation = 0.0;      ///< [m] from the last keyframe
    double rotation_deg = 0.0;     ///< [deg] from the last keyframe
};

enum class KeyframeReason {
    None,
    TooFewTracked,
    MaxInterval,
    TrackedDropped,
    NeedCloseStructure,
    Motion
};
[[nodiscard]] std::string toString(KeyframeReason r);

struct KeyframeDecision {
    bool insert = false;
    KeyframeReason reason = KeyframeReason::None;  ///< the rule that fired (or why not)
};

/// Rules, in order: tracked < min_tracked -> no (TooFewTracked); frames >= max_frames ->
/// yes (MaxInterval); motion beyond max_translation/max_rotation -> yes (Motion); with
/// frames >= min_frames: tracked < ratio * tracked_at_last_kf -> yes (TrackedDropped),
/// close tracked < below and close untracked > above -> yes (NeedCloseStructure).
[[nodiscard]] KeyframeDecision decideKeyframe(const KeyframeSelectorInput& in,
                                              const KeyframeSelectorOptions& opts);

}  // namespace devslam::slam
