#include <devslam/core/Config.h>
#include <devslam/slam/KeyframeSelector.h>

#include <mrpt/config/CConfigFileBase.h>

namespace devslam::slam {

void KeyframeSelectorOptions::loadFromConfig(const mrpt::config::CConfigFileBase& c,
                                             const std::string& s) {
    core::requireKnownKeys(
        c, s,
        {"min_frames", "max_frames", "min_tracked_ratio", "min_tracked", "close_tracked_below",
         "close_untracked_above", "max_translation", "max_rotation_deg"});
    min_frames = core::readInt(c, s, "min_frames", min_frames);
    max_frames = core::readInt(c, s, "max_frames", max_frames);
    min_tracked_ratio = core::readDouble(c, s, "min_tracked_ratio", min_tracked_ratio);
    min_tracked = core::readInt(c, s, "min_tracked", min_tracked);
    close_tracked_below = core::readInt(c, s, "close_tracked_below", close_tracked_below);
    close_untracked_above = core::readInt(c, s, "close_untracked_above", close_untracked_above);
    max_translation = core::readDouble(c, s, "max_translation", max_translation);
    max_rotation_deg = core::readDouble(c, s, "max_rotation_deg", max_rotation_deg);
    core::requireValue(max_frames >= 1, s, "max_frames", "must be >= 1");
    core::requireValue(min_frames >= 0 && min_frames <= max_frames, s, "min_frames",
                       "must be in [0, max_frames]");
    core::requireValue(min_tracked_ratio > 0 && min_tracked_ratio <= 1, s, "min_tracked_ratio",
                       "must be in (0, 1]");
    core::requireValue(max_translation > 0, s, "max_translation", "must be > 0");
    core::requireValue(max_rotation_deg > 0, s, "max_rotation_deg", "must be > 0");
}

void KeyframeSelectorOptions::saveToConfig(mrpt::config::CConfigFileBase& c,
                                           const std::string& s) const {
    core::writeKey(c, s, "min_frames", min_frames);
    core::writeKey(c, s, "max_frames", max_frames);
    core::writeKey(c, s, "min_tracked_ratio", min_tracked_ratio);
    core::writeKey(c, s, "min_tracked", min_tracked);
    core::writeKey(c, s, "close_tracked_below", close_tracked_below);
    core::writeKey(c, s, "close_untracked_above", close_untracked_above);
    core::writeKey(c, s, "max_translation", max_translation);
    core::writeKey(c, s, "max_rotation_deg", max_rotation_deg);
}

std::string toString(KeyframeReason r) {
    switch (r) {
        case KeyframeReason::None:
            return "none";
        case KeyframeReason::TooFewTracked:
            return "too_few_tracked";
        case KeyframeReason::MaxInterval:
            return "max_interval";
        case KeyframeReason::TrackedDropped:
            return "tracked_dropped";
        case KeyframeReason::NeedCloseStructure:
            return "need_close_structure";
        case KeyframeReason::Motion:
            return "motion";
    }
    return "?";
}

KeyframeDecision decideKeyframe(const KeyframeSelectorInput& in,
                                const KeyframeSelectorOptions& opts) {
    if (in.n_tracked < opts.min_tracked) return {false, KeyframeReason::TooFewTracked};
    if (in.frames_since_last_kf >= opts.max_frames) return {true, KeyframeReason::MaxInterval};
    if (in.translation > opts.max_translation || in.rotation_deg > opts.max_rotation_deg)
        return {true, KeyframeReason::Motion};
    if (in.frames_since_last_kf < opts.min_frames) return {false, KeyframeReason::None};
    if (in.n_tracked < opts.min_tracked_ratio * in.n_tracked_at_last_kf)
        return {true, KeyframeReason::TrackedDropped};
    if (in.n_close_tracked < opts.close_tracked_below &&
        in.n_close_untracked > opts.close_untracked_above)
        return {true, KeyframeReason::NeedCloseStructure};
    return {false, KeyframeReason::None};
}

}  // namespace devslam::slam
