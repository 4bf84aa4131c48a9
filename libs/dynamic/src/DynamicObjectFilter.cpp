#include <devslam/dynamic/DynamicObjectFilter.h>
#include <devslam/dynamic/ShiTomasi.h>

#include <devslam/core/Config.h>
#include <devslam/core/Stats.h>

#include <mrpt/config/CConfigFileBase.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <deque>
#include <limits>
#include <stdexcept>
#include <tuple>

namespace devslam::dynamic {

namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

const std::vector<std::string> kKeys{"mode",
                                     "detect_every",
                                     "max_corners",
                                     "max_corners_per_box",
                                     "background_corners",
                                     "corner_quality",
                                     "corner_min_distance",
                                     "lk_window",
                                     "lk_levels",
                                     "fb_max_error",
                                     "refine_ego_motion",
                                     "min_background_points",
                                     "ransac_reprojection",
                                     "max_depth",
                                     "threshold1",
                                     "threshold2_count",
                                     "threshold2_fraction",
                                     "min_points",
                                     "box_shrink",
                                     "iou_match",
                                     "release_frames",
                                     "confirm_border_frames",
                                     "max_missed_detections",
                                     "hide_unseen_frames",
                                     "forget_unseen_frames",
                                     "keep_border_tracks",
                                     "mask_margin",
                                     "background_factor",
                                     "flow_scale",
                                     "mask_unknown",
                                     "mask_unknown_first_frame",
                                     "first_frame_as_static",
                                     "mask_border_snap",
                                     "fg_depth_band",
                                     "narrow_vote_band",
                                     "narrow_vote_slope",
                                     "mask_silhouette",
                                     "silhouette_depth_band",
                                     "silhouette_grow",
                                     "silhouette_depth_slope",
                                     "slow_frames",
                                     "slow_threshold",
                                     "slow_speed",
                                     "depth_frames",
                                     "depth_rate_threshold",
                                     "depth_noise_z2",
                                     "new_track_score",
                                     "static_person_weight",
                                     "static_person_gate",
                                     "static_person_outline",
                                     "static_person_outline_after"};

cv::Rect2f shrink(const cv::Rect2f& b, double f) {
    const auto dx = static_cast<float>(f * b.width), dy = static_cast<float>(f * b.height);
    return {b.x + dx, b.y + dy, b.width - 2 * dx, b.height - 2 * dy};
}

/// A person box grown by mask_margin plus 20 % of its size on each side (the detector's box
/// may lag a walker's limbs): points in it are not background for the ego-motion fit.
cv::Rect2f nearBox(const cv::Rect2f& b, const DynamicObjectFilter::Options& o) {
    const float mx = static_cast<float>(o.mask_margin) + 0.2f * b.width;
    const float my = static_cast<float>(o.mask_margin) + 0.2f * b.height;
    return {b.x - mx, b.y - my, b.width + 2 * mx, b.height + 2 * my};
}

/// Depth at (u, v) if it is valid and not on a depth discontinuity (3x3 spread below 5%):
/// corners on the silhouette of a person often sample the background's depth.
std::optional<float> stableDepth(const cv::Mat& depth, const cv::Point2f& p, double max_depth) {
    const int u = cvRound(p.x), v = cvRound(p.y);
    if (u < 1 || v < 1 || u >= depth.cols - 1 || v >= depth.rows - 1) return std::nullopt;
    float lo = 1e9f, hi = 0.f;
    for (int dv = -1; dv <= 1; ++dv) {
        const float* row = depth.ptr<float>(v + dv);
        for (int du = -1; du <= 1; ++du) {
            const float z = row[u + du];
            if (!(z > 0.f)) return std::nullopt;
            lo = std::min(lo, z);
            hi = std::max(hi, z);
        }
    }
    const float z = depth.at<float>(v, u);
    if (z > max_depth || hi - lo > 0.05f * z) return std::nullopt;
    return z;
}

/// Half-width [m] of the depth band around a person's depth z that belongs to them.
float depthBand(double band, float z) {
    return static_cast<float>(band) + 0.1f * z;
}

/// The person's depth in a box: median valid depth of its torso region (30-70 % of the
/// width, 15-55 % of the height), where a detected person box is nearly always on the
/// person even when the rest of the box shows background or a desk in front of the legs.
/// Not so for a person the image's border cuts, entering at a corner: the detector's box
/// reaches past them and the torso region shows mostly the background behind. So where
/// the nearest quarter of the samples lies more than a depth band (band > 0) in front of
/// the median, the person is that nearer surface: the median of the samples up to a band
/// behind it. (A walker entering at walking_rpy's bottom-left corner got the wall's depth
/// for six frames, and the flow test looked at the wall.)
std::optional<float> personDepth(const cv::Mat& depth, const cv::Rect2f& box, double max_depth,
                                 double band) {
    const cv::Rect torso = cv::Rect(cv::Rect2f(box.x + 0.3f * box.width, box.y + 0.15f * box.height,
                                               0.4f * box.width, 0.4f * box.height)) &
                           cv::Rect(0, 0, depth.cols, depth.rows);
    if (torso.width < 2 || torso.height < 2) return std::nullopt;
    std::vector<float> z;
    z.reserve(static_cast<std::size_t>(torso.area() / 4 + 1));
    for (int v = torso.y; v < torso.br().y; v += 2) {
        const float* row = depth.ptr<float>(v);
        for (int u = torso.x; u < torso.br().x; u += 2)
            if (row[u] > 0.f && row[u] <= max_depth) z.push_back(row[u]);
    }
    if (z.size() < 8) return std::nullopt;
    const auto mid = z.begin() + static_cast<std::ptrdiff_t>(z.size() / 2);
    std::nth_element(z.begin(), mid, z.end());
    const float median = *mid;
    if (band <= 0) return median;
    const auto quarter = z.begin() + static_cast<std::ptrdiff_t>(z.size() / 4);
    std::nth_element(z.begin(), quarter, mid);  // (z[0, mid) are the samples <= median)
    const float near = *quarter;
    if (median - near <= depthBand(band, near)) return median;
    const float far = near + depthBand(band, near);
    const auto end = std::partition(z.begin(), z.end(), [&](float v) { return v <= far; });
    const auto m = z.begin() + (end - z.begin()) / 2;
    std::nth_element(z.begin(), m, end);
    return *m;
}

/// static_person_gate's INI names and the exponents (Options::static_person_gate) they stand
/// for: read, written and checked from this one table.
constexpr std::array<std::pair<const char*, double>, 3> kGates{
    {{"wider", 1.0}, {"same", 0.0}, {"narrower", -1.0}}};

/// The name of gate exponent `p`, nullptr for one the table does not hold.
const char* gateName(double p) {
    for (const auto& [name, e] : kGates)
        if (e == p) return name;
    return nullptr;
}

}  // namespace

MaskMode parseMaskMode(const std::string& name) {
    if (name == "none") return MaskMode::None;
    if (name == "all_persons") return MaskMode::AllPersons;
    if (name == "dynamic") return MaskMode::Dynamic;
    throw std::invalid_argument("unknown mask mode '" + name +
                                "' (known: none, all_persons, dynamic)");
}

std::string toString(MaskMode mode) {
    switch (mode) {
        case MaskMode::None:
            return "none";
        case MaskMode::AllPersons:
            return "all_persons";
        case MaskMode::Dynamic:
            return "dynamic";
    }
    return "?";
}

std::string toString(BoxState state) {
    switch (state) {
        case BoxState::Unknown:
            return "unknown";
        case BoxState::Static:
            return "static";
        case BoxState::Moving:
            return "moving";
    }
    return "?";
}

void DynamicObjectFilter::Options::loadFromConfig(const mrpt::config::CConfigFileBase& c,
                                                  const std::string& s) {
    core::requireKnownKeys(c, s, kKeys);
    if (c.keyExists(s, "mode")) {
        try {
            mode = parseMaskMode(c.read_string(s, "mode", ""));
        } catch (const std::invalid_argument& e) {
            throw std::invalid_argument("[" + s + "] mode: " + e.what());
        }
    }
    detect_every = core::readInt(c, s, "detect_every", detect_every);
    flow_scale = core::readDouble(c, s, "flow_scale", flow_scale);
    max_corners = core::readInt(c, s, "max_corners", max_corners);
    max_corners_per_box = core::readInt(c, s, "max_corners_per_box", max_corners_per_box);
    background_corners = core::readInt(c, s, "background_corners", background_corners);
    corner_quality = core::readDouble(c, s, "corner_quality", corner_quality);
    corner_min_distance = core::readDouble(c, s, "corner_min_distance", corner_min_distance);
    lk_window = core::readInt(c, s, "lk_window", lk_window);
    lk_levels = core::readInt(c, s, "lk_levels", lk_levels);
    fb_max_error = core::readDouble(c, s, "fb_max_error", fb_max_error);
    refine_ego_motion = core::readBool(c, s, "refine_ego_motion", refine_ego_motion);
    min_background_points = core::readInt(c, s, "min_background_points", min_background_points);
    ransac_reprojection = core::readDouble(c, s, "ransac_reprojection", ransac_reprojection);
    max_depth = core::readDouble(c, s, "max_depth", max_depth);
    threshold1 = core::readDouble(c, s, "threshold1", threshold1);
    background_factor = core::readDouble(c, s, "background_factor", background_factor);
    threshold2_count = core::readInt(c, s, "threshold2_count", threshold2_count);
    threshold2_fraction = core::readDouble(c, s, "threshold2_fraction", threshold2_fraction);
    min_points = core::readInt(c, s, "min_points", min_points);
    box_shrink = core::readDouble(c, s, "box_shrink", box_shrink);
    fg_depth_band = core::readDouble(c, s, "fg_depth_band", fg_depth_band);
    narrow_vote_band = core::readDouble(c, s, "narrow_vote_band", narrow_vote_band);
    narrow_vote_slope = core::readDouble(c, s, "narrow_vote_slope", narrow_vote_slope);
    mask_silhouette = core::readBool(c, s, "mask_silhouette", mask_silhouette);
    silhouette_depth_band = core::readDouble(c, s, "silhouette_depth_band", silhouette_depth_band);
    silhouette_grow = core::readDouble(c, s, "silhouette_grow", silhouette_grow);
    silhouette_depth_slope =
        core::readDouble(c, s, "silhouette_depth_slope", silhouette_depth_slope);
    static_person_weight = core::readDouble(c, s, "static_person_weight", static_person_weight);
    if (c.keyExists(s, "static_person_gate")) {
        const std::string g = c.read_string(s, "static_person_gate", "");
        const auto it = std::find_if(kGates.begin(), kGates.end(),
                                     [&](const auto& gate) { return g == gate.first; });
        core::requireValue(it != kGates.end(), s, "static_person_gate",
                           "must be wider, same or narrower (got '" + g + "')");
        static_person_gate = it->second;
    }
    static_person_outline = core::readInt(c, s, "static_person_outline", static_person_outline);
    static_person_outline_after =
        core::readInt(c, s, "static_person_outline_after", static_person_outline_after);
    slow_frames = core::readInt(c, s, "slow_frames", slow_frames);
    slow_threshold = core::readDouble(c, s, "slow_threshold", slow_threshold);
    slow_speed = core::readDouble(c, s, "slow_speed", slow_speed);
    depth_frames = core::readInt(c, s, "depth_frames", depth_frames);
    depth_rate_threshold = core::readDouble(c, s, "depth_rate_threshold", depth_rate_threshold);
    depth_noise_z2 = core::readDouble(c, s, "depth_noise_z2", depth_noise_z2);
    new_track_score = core::readDouble(c, s, "new_track_score", new_track_score);
    iou_match = core::readDouble(c, s, "iou_match", iou_match);
    release_frames = core::readInt(c, s, "release_frames", release_frames);
    confirm_border_frames = core::readInt(c, s, "confirm_border_frames", confirm_border_frames);
    max_missed_detections = core::readInt(c, s, "max_missed_detections", max_missed_detections);
    hide_unseen_frames = core::readInt(c, s, "hide_unseen_frames", hide_unseen_frames);
    forget_unseen_frames = core::readInt(c, s, "forget_unseen_frames", forget_unseen_frames);
    keep_border_tracks = core::readBool(c, s, "keep_border_tracks", keep_border_tracks);
    mask_margin = core::readInt(c, s, "mask_margin", mask_margin);
    mask_unknown = core::readBool(c, s, "mask_unknown", mask_unknown);
    mask_unknown_first_frame =
        core::readBool(c, s, "mask_unknown_first_frame", mask_unknown_first_frame);
    first_frame_as_static = core::readBool(c, s, "first_frame_as_static", first_frame_as_static);
    mask_border_snap = core::readInt(c, s, "mask_border_snap", mask_border_snap);
    validate(s);
}

void DynamicObjectFilter::Options::validate(const std::string& s) const {
    // (1e9 snapped every box to every border: the whole frame masked, nothing tracked)
    core::requireValue(mask_border_snap >= 0 && mask_border_snap <= 100, s, "mask_border_snap",
                       "must be in [0, 100] [px]");
    core::requireValue(detect_every >= 1, s, "detect_every", "must be >= 1");
    core::requireValue(flow_scale > 0.1 && flow_scale <= 1.0, s, "flow_scale",
                       "must be in (0.1, 1]");
    core::requireValue(max_corners > 0, s, "max_corners", "must be > 0");
    core::requireValue(max_corners_per_box >= 0, s, "max_corners_per_box", "must be >= 0");
    core::requireValue(background_corners >= 0, s, "background_corners", "must be >= 0");
    core::requireValue(corner_quality > 0 && corner_quality < 1, s, "corner_quality",
                       "must be in (0, 1)");
    // A huge spacing overflowed the corner grid's cell count (a crash at 3e9); a huge window
    // grows the pyramids' borders by its size.
    core::requireValue(corner_min_distance >= 0 && corner_min_distance <= 1000, s,
                       "corner_min_distance", "must be in [0, 1000] px");
    core::requireValue(lk_window >= 5 && lk_window <= 255 && lk_window % 2 == 1, s, "lk_window",
                       "must be odd and in [5, 255]");
    core::requireValue(lk_levels >= 0 && lk_levels <= 6, s, "lk_levels", "must be in [0, 6]");
    core::requireValue(fb_max_error > 0, s, "fb_max_error", "must be > 0");
    core::requireValue(min_background_points >= 6, s, "min_background_points", "must be >= 6");
    core::requireValue(ransac_reprojection > 0, s, "ransac_reprojection", "must be > 0");
    core::requireValue(max_depth > 0, s, "max_depth", "must be > 0");
    core::requireValue(threshold1 > 0, s, "threshold1", "must be > 0");
    core::requireValue(background_factor >= 0, s, "background_factor", "must be >= 0");
    core::requireValue(threshold2_count >= 1, s, "threshold2_count", "must be >= 1");
    core::requireValue(threshold2_fraction >= 0 && threshold2_fraction <= 1, s,
                       "threshold2_fraction", "must be in [0, 1]");
    core::requireValue(min_points >= 1, s, "min_points", "must be >= 1");
    core::requireValue(box_shrink >= 0 && box_shrink < 0.5, s, "box_shrink", "must be in [0, 0.5)");
    core::requireValue(fg_depth_band >= 0, s, "fg_depth_band", "must be >= 0 (0 = off)");
    core::requireValue(narrow_vote_band >= 0, s, "narrow_vote_band", "must be >= 0 (0 = off)");
    core::requireValue(narrow_vote_slope >= 0 && narrow_vote_slope <= 1, s, "narrow_vote_slope",
                       "must be in [0, 1] (m per m of depth)");
    core::requireValue(silhouette_depth_band >= 0, s, "silhouette_depth_band",
                       "must be >= 0 (0 = fg_depth_band's)");
    core::requireValue(silhouette_grow >= 0 && silhouette_grow <= 1, s, "silhouette_grow",
                       "must be in [0, 1] (0 = the box only)");
    core::requireValue(silhouette_depth_slope >= 0 && silhouette_depth_slope <= 1, s,
                       "silhouette_depth_slope", "must be in [0, 1] (m per m of depth)");
    core::requireValue(static_person_weight > 0 && static_person_weight <= 1, s,
                       "static_person_weight", "must be in (0, 1] (1 = like any keypoint)");
    core::requireValue(gateName(static_person_gate) != nullptr, s, "static_person_gate",
                       "must be 1, 0 or -1 (wider, same, narrower)");
    // (the band's region grows by w on each side: 500 px spans the image)
    core::requireValue(static_person_outline >= 0 && static_person_outline <= 500, s,
                       "static_person_outline", "must be in [0, 500] [px] (0 = off)");
    core::requireValue(static_person_outline_after >= 0, s, "static_person_outline_after",
                       "must be >= 0 [steps] (0 = from the first step judged Static)");
    core::requireValue(slow_frames >= 0, s, "slow_frames", "must be >= 0 (0 = off)");
    core::requireValue(slow_threshold > 0, s, "slow_threshold", "must be > 0");
    core::requireValue(slow_speed >= 0, s, "slow_speed", "must be >= 0 (0 = off)");
    core::requireValue(depth_frames >= 0, s, "depth_frames", "must be >= 0 (0 = off)");
    core::requireValue(depth_rate_threshold > 0, s, "depth_rate_threshold", "must be > 0");
    core::requireValue(depth_noise_z2 >= 0, s, "depth_noise_z2", "must be >= 0");
    core::requireValue(new_track_score >= 0 && new_track_score <= 1, s, "new_track_score",
                       "must be in [0, 1]");
    core::requireValue(iou_match > 0 && iou_match <= 1, s, "iou_match", "must be in (0, 1]");
    core::requireValue(release_frames >= 1, s, "release_frames", "must be >= 1");
    core::requireValue(confirm_border_frames >= 1, s, "confirm_border_frames", "must be >= 1");
    core::requireValue(max_missed_detections >= 0, s, "max_missed_detections", "must be >= 0");
    core::requireValue(hide_unseen_frames >= 0, s, "hide_unseen_frames", "must be >= 0");
    core::requireValue(forget_unseen_frames >= hide_unseen_frames, s, "forget_unseen_frames",
                       "must be >= hide_unseen_frames");
    // (a dilation kernel of (2 m + 1)^2 bytes per masked box and frame: 100000 asked 40 GB)
    core::requireValue(mask_margin >= 0 && mask_margin <= 500, s, "mask_margin",
                       "must be in [0, 500] [px]");
}

void DynamicObjectFilter::Options::saveToConfig(mrpt::config::CConfigFileBase& c,
                                                const std::string& s) const {
    core::writeKey(c, s, "mode", toString(mode));
    core::writeKey(c, s, "detect_every", detect_every);
    core::writeKey(c, s, "flow_scale", flow_scale);
    core::writeKey(c, s, "max_corners", max_corners);
    core::writeKey(c, s, "max_corners_per_box", max_corners_per_box);
    core::writeKey(c, s, "background_corners", background_corners);
    core::writeKey(c, s, "corner_quality", corner_quality);
    core::writeKey(c, s, "corner_min_distance", corner_min_distance);
    core::writeKey(c, s, "lk_window", lk_window);
    core::writeKey(c, s, "lk_levels", lk_levels);
    core::writeKey(c, s, "fb_max_error", fb_max_error);
    core::writeKey(c, s, "refine_ego_motion", refine_ego_motion);
    core::writeKey(c, s, "min_background_points", min_background_points);
    core::writeKey(c, s, "ransac_reprojection", ransac_reprojection);
    core::writeKey(c, s, "max_depth", max_depth);
    core::writeKey(c, s, "threshold1", threshold1);
    core::writeKey(c, s, "background_factor", background_factor);
    core::writeKey(c, s, "threshold2_count", threshold2_count);
    core::writeKey(c, s, "threshold2_fraction", threshold2_fraction);
    core::writeKey(c, s, "min_points", min_points);
    core::writeKey(c, s, "box_shrink", box_shrink);
    core::writeKey(c, s, "fg_depth_band", fg_depth_band);
    core::writeKey(c, s, "narrow_vote_band", narrow_vote_band);
    core::writeKey(c, s, "narrow_vote_slope", narrow_vote_slope);
    core::writeKey(c, s, "mask_silhouette", mask_silhouette);
    core::writeKey(c, s, "silhouette_depth_band", silhouette_depth_band);
    core::writeKey(c, s, "silhouette_grow", silhouette_grow);
    core::writeKey(c, s, "silhouette_depth_slope", silhouette_depth_slope);
    core::writeKey(c, s, "static_person_weight", static_person_weight);
    // An exponent outside the table (options set in code, not validated) is written as a
    // number, which loading refuses naming the key.
    const char* gate = gateName(static_person_gate);
    if (gate)
        core::writeKey(c, s, "static_person_gate", std::string(gate));
    else
        core::writeKey(c, s, "static_person_gate", static_person_gate);
    core::writeKey(c, s, "static_person_outline", static_person_outline);
    core::writeKey(c, s, "static_person_outline_after", static_person_outline_after);
    core::writeKey(c, s, "slow_frames", slow_frames);
    core::writeKey(c, s, "slow_threshold", slow_threshold);
    core::writeKey(c, s, "slow_speed", slow_speed);
    core::writeKey(c, s, "depth_frames", depth_frames);
    core::writeKey(c, s, "depth_rate_threshold", depth_rate_threshold);
    core::writeKey(c, s, "depth_noise_z2", depth_noise_z2);
    core::writeKey(c, s, "new_track_score", new_track_score);
    core::writeKey(c, s, "iou_match", iou_match);
    core::writeKey(c, s, "release_frames", release_frames);
    core::writeKey(c, s, "confirm_border_frames", confirm_border_frames);
    core::writeKey(c, s, "max_missed_detections", max_missed_detections);
    core::writeKey(c, s, "hide_unseen_frames", hide_unseen_frames);
    core::writeKey(c, s, "forget_unseen_frames", forget_unseen_frames);
    core::writeKey(c, s, "keep_border_tracks", keep_border_tracks);
    core::writeKey(c, s, "mask_margin", mask_margin);
    core::writeKey(c, s, "mask_unknown", mask_unknown);
    core::writeKey(c, s, "mask_unknown_first_frame", mask_unknown_first_frame);
    core::writeKey(c, s, "first_frame_as_static", first_frame_as_static);
    core::writeKey(c, s, "mask_border_snap", mask_border_snap);
}

namespace {

using Options = DynamicObjectFilter::Options;

/// Shi-Tomasi corners of the previous frame (p0) and where LK finds them in the current one
/// (p1), in full-resolution pixels; only points that pass the forward-backward check and
/// land in the image.
struct PointFlow {
    std::vector<cv::Point2f> p0, p1;  ///< in the previous / current image [px]
    /// p0, p1 undistorted (core::undistortPixels with the previous / current intrinsics):
    /// for the geometry (back-projection, PnP, predicted flow); the images, boxes and depth
    /// are the camera's own, so p0 and p1 serve the rest. Copies of p0, p1 for a camera
    /// without distortion (the renders).
    std::vector<cv::Point2f> u0, u1;
};

/// What ego-motion compensation says about each point of a PointFlow.
struct Residuals {
    /// 3D of the point in the previous camera frame (nullopt: no stable depth there)
    std::vector<std::optional<Eigen::Vector3d>> X;
    /// for a point with X: near no person box (nearAnyBox), so it is background for the
    /// ego-motion fit and the image-wide threshold
    std::vector<bool> background;
    /// residual flow vector [px]: observed - predicted from ego-motion and depth
    std::vector<cv::Point2f> vec;
    /// depth residual [m]: measured depth at the point's new position - the depth
    /// ego-motion predicts, less the background's median (NaN: no stable depth)
    std::vector<float> z;
};

}  // namespace

/// The filter's state between steps, and the stages of step(), numbered in the order
/// step() calls them (the data flow diagram of docs/dynamic.md, top to bottom).
struct DynamicObjectFilter::Impl {
    struct Track {
        TrackedBox tb;
        int quiet = 0;         ///< consecutive frames without moving evidence
        int static_steps = 0;  ///< consecutive steps, this one included, in state Static
        int missed = 0;        ///< detector runs without a matching detection
        /// consecutive steps unmatched at the last detector run and with fewer than
        /// min_points points in the box: nothing shows the person is still there
        int unseen = 0;
        [[nodiscard]] bool hidden(const Options& o) const {
            return o.hide_unseen_frames > 0 && unseen >= o.hide_unseen_frames;
        }
        /// the person's depth (personDepth) in this step's box and depth image, when the
        /// band or the silhouette mask needs it; the next step's corners use it as the
        /// previous frame's
        std::optional<float> depth;
        /// the median residual flow vector of the box's points in its last steps with
        /// evidence (at most slow_frames, newest last)
        std::deque<cv::Point2f> slow_history;
        /// the median depth residual [m] of the box's points in the same steps
        std::deque<float> depth_history;
    };
    cv::Mat prev_work, prev_depth;
    std::vector<cv::Mat> prev_pyr;
    /// this step's images (swapped into prev_* at its end), the full-size grey image, and
    /// the eigenvalue map of prev_work: buffers reused from step to step
    cv::Mat work, gray;
    std::vector<cv::Mat> pyr;
    ShiTomasiMap corner_map;
    core::CameraIntrinsics prev_K;
    double prev_timestamp = 0.0;
    std::vector<Track> tracks;
    int next_id = 0;
    long frame_count = 0;

    /// 0. This frame's grey image at flow_scale and its LK pyramid. Returns whether there
    ///    is a previous frame of the same size to take the flow from.
    bool prepareImages(const core::Frame& frame, const Options& o);
    /// 1. Flow of the previous frame's Shi-Tomasi corners: over the whole image, and more
    ///    inside each box, on the person's depth band when known.
    PointFlow trackCorners(const Options& o, const cv::Rect2f& image,
                           FilterOutput::StageTimes& times);
    /// 2. Carries each box with the median flow of its points (the prediction for the
    ///    association, and the box itself on frames without detection).
    void carryBoxes(const PointFlow& f, const cv::Rect2f& image);
    /// 3. Greedy IoU association of this frame's detections with the tracks; drops tracks
    ///    the detector lost (unless moving), starts tracks for confident new detections.
    void associate(const std::vector<detect::Detection>& dets, const Options& o);
    /// Drops degenerate boxes and measures the person's depth in each remaining one.
    void measureBoxes(const cv::Mat& depth, const Options& o);
    /// Whether a point (at a in the previous frame or b in this one) is near a box: within
    /// mask_margin plus 20 % of the box's size (the detector's box may lag a walker's limbs).
    [[nodiscard]] bool nearAnyBox(const cv::Point2f& a, const cv::Point2f& b,
                                  const Options& o) const;
    /// 4. Ego-motion: the 3D of each point from the previous depth (into r.X, and whether
    ///    it is background into r.background), and the relative pose p_prev = T * p_cur,
    ///    the prior refined by PnP-RANSAC on the background points (also written to
    ///    out.T_prev_cur_refined).
    Eigen::Isometry3d egoMotion(const PointFlow& f, const core::CameraIntrinsics& Kc,
                                const std::optional<Eigen::Isometry3d>& prior, const Options& o,
                                Residuals& r, FilterOutput& out) const;
    /// 5. Residual flow of each point (into r.vec, r.z and out.flow) and the image-wide
    ///    threshold (out.threshold).
    void residualFlow(const core::Frame& frame, const PointFlow& f,
                      const Eigen::Isometry3d& T_prev_cur, const Options& o, Residuals& r,
                      FilterOutput& out) const;
    /// The threshold a box's points are judged by: out.threshold, raised where the box's
    /// static surroundings fit ego-motion badly.
    [[nodiscard]] double localThreshold(const cv::Rect2f& box, const FilterOutput& out,
                                        const Options& o) const;
    /// 6. Per-box evidence (Algorithm 1 with residual flow) and the state's hysteresis.
    ///    dt: [s] since the previous frame (<= 0: unknown).
    void classifyBoxes(const Residuals& r, const core::Frame& frame, double dt, const Options& o,
                       FilterOutput& out);
    /// Forgets tracks unseen for more than forget_unseen_frames steps.
    void forgetUnseen(const Options& o);
    /// 7. The boxes to report and the mask (out.boxes, out.mask).
    void drawMask(const core::Frame& frame, bool have_prev, const Options& o,
                  FilterOutput& out) const;
    /// This step's images become the previous ones.
    void endStep(const core::Frame& frame);
};

DynamicObjectFilter::DynamicObjectFilter(const Options& opts,
                                         std::unique_ptr<detect::PersonDetector> detector)
    : opts_(opts), detector_(std::move(detector)), impl_(std::make_unique<Impl>()) {
    if (!detector_ && opts_.mode != MaskMode::None)
        throw std::invalid_argument("dynamic filter: mode '" + toString(opts_.mode) +
                                    "' needs a detector");
    opts_.validate();  // options set in code get the INI's checks (detect_every 0 divides by 0)
}

DynamicObjectFilter::~DynamicObjectFilter() = default;

void DynamicObjectFilter::reset() {
    // Track ids go on from where they were: a box after the reset is another track, and
    // its id must not be an old one's (a consumer keying on ids would join the two).
    const int next_id = impl_->next_id;
    impl_ = std::make_unique<Impl>();
    impl_->next_id = next_id;
}

int DynamicObjectFilter::Options::minFrameSide() const {
    // The flow runs on the image scaled by flow_scale, with an lk_window-sized window.
    if (mode == MaskMode::None) return 0;
    return static_cast<int>(std::ceil(lk_window / std::min(flow_scale, 1.0)));
}

FilterOutput DynamicObjectFilter::step(const core::Frame& frame,
                                       const std::optional<Eigen::Isometry3d>& T_prev_cur_prior) {
    if (frame.bgr.type() != CV_8UC3 || frame.depth.type() != CV_32FC1 ||
        frame.bgr.size() != frame.depth.size() || frame.bgr.empty())
        throw std::invalid_argument("dynamic filter: frame " + std::to_string(frame.index) +
                                    " needs CV_8UC3 colour and CV_32FC1 depth of equal size");
    // An image smaller than the flow's window (a 1x1 frame gave cv::resize an empty size) is
    // refused.
    const int min_side = opts_.minFrameSide();
    if (frame.bgr.cols < min_side || frame.bgr.rows < min_side)
        throw std::invalid_argument("dynamic filter: frame " + std::to_string(frame.index) +
                                    " is " + std::to_string(frame.bgr.cols) + "x" +
                                    std::to_string(frame.bgr.rows) +
                                    " px; the flow needs at least " + std::to_string(min_side) +
                                    "x" + std::to_string(min_side) + " (lk_window / flow_scale)");
    FilterOutput out;
    out.mask = cv::Mat::zeros(frame.bgr.size(), CV_8UC1);
    if (opts_.mode == MaskMode::None) return out;

    // A frame of another size has no previous frame to flow from, and the tracks' boxes
    // are in the old size's pixels: it starts afresh, as a first frame.
    if (!impl_->prev_depth.empty() && impl_->prev_depth.size() != frame.bgr.size()) reset();
    Impl& im = *impl_;
    const auto t_filter0 = Clock::now();
    double detect_ms = 0;
    const cv::Size size = frame.bgr.size();
    const cv::Rect2f image(0.f, 0.f, static_cast<float>(size.width),
                           static_cast<float>(size.height));

    FilterOutput::StageTimes& times = out.stage_ms;
    auto t_stage = Clock::now();
    const auto lap = [&t_stage](double& ms) {  // the time since the last lap, into ms
        const auto now = Clock::now();
        ms += std::chrono::duration<double, std::milli>(now - t_stage).count();
        t_stage = now;
    };

    const bool have_prev = im.prepareImages(frame, opts_);
    lap(times.images);
    PointFlow flow;
    if (have_prev) {
        flow = im.trackCorners(opts_, image, times);
        flow.u0 = core::undistortPixels(flow.p0, im.prev_K);
        flow.u1 = core::undistortPixels(flow.p1, frame.K);
    }
    t_stage = Clock::now();
    im.carryBoxes(flow, image);
    if (im.frame_count % opts_.detect_every == 0) {
        lap(times.boxes);
        const auto dets = detector_->detect(frame.bgr);
        lap(detect_ms);
        out.detector_ran = true;
        im.associate(dets, opts_);
    }
    im.measureBoxes(frame.depth, opts_);  // the boxes are final for this step
    lap(times.boxes);
    Residuals res;
    if (have_prev && !flow.p0.empty()) {
        const Eigen::Isometry3d T_prev_cur =
            im.egoMotion(flow, frame.K, T_prev_cur_prior, opts_, res, out);
        lap(times.ego_motion);
        im.residualFlow(frame, flow, T_prev_cur, opts_, res, out);
        lap(times.residuals);
    }
    im.classifyBoxes(res, frame, have_prev ? frame.timestamp - im.prev_timestamp : 0.0, opts_, out);
    im.forgetUnseen(opts_);
    for (auto& t : im.tracks)
        t.static_steps = t.tb.state == BoxState::Static ? t.static_steps + 1 : 0;
    lap(times.evidence);
    im.drawMask(frame, have_prev, opts_, out);
    lap(times.mask);
    im.endStep(frame);
    lap(times.images);

    out.detect_ms = detect_ms;
    out.filter_ms = msSince(t_filter0) - detect_ms;
    return out;
}

bool DynamicObjectFilter::Impl::prepareImages(const core::Frame& frame, const Options& o) {
    // Corners and flow run on a downscaled grey image (flow_scale) for speed; all
    // coordinates outside trackCorners are full-resolution pixels. The images a step
    // builds go into buffers kept here (this step's become the next step's previous ones
    // by swapping): images this large get fresh pages from the kernel, and page faults,
    // when allocated anew.
    const double sc = o.flow_scale;
    if (sc != 1.0) {
        cv::cvtColor(frame.bgr, gray, cv::COLOR_BGR2GRAY);
        cv::resize(gray, work, cv::Size(), sc, sc, cv::INTER_AREA);
    } else {
        cv::cvtColor(frame.bgr, work, cv::COLOR_BGR2GRAY);
    }
    // With the Scharr derivatives stored in the pyramid, calcOpticalFlowPyrLK does not
    // recompute them for each of the two calls that start from this frame (this step's
    // backward check and the next step's forward flow); the flow is bit-identical.
    cv::buildOpticalFlowPyramid(work, pyr, cv::Size(o.lk_window, o.lk_window), o.lk_levels, true);
    return !prev_work.empty() && prev_work.size() == work.size() &&
           prev_depth.size() == frame.bgr.size();
}

PointFlow DynamicObjectFilter::Impl::trackCorners(const Options& o, const cv::Rect2f& image,
                                                  FilterOutput::StageTimes& times) {
    const auto t0 = Clock::now();
    const double sc = o.flow_scale;
    PointFlow f;
    std::vector<cv::Point2f>& p0 = f.p0;
    std::vector<cv::Point2f>& p1 = f.p1;
    // One eigenvalue map for the image and every box (see ShiTomasi.h).
    corner_map.update(prev_work);
    const cv::Rect whole(0, 0, work.cols, work.rows);
    p0 = selectShiTomasi(corner_map, whole, o.max_corners, o.corner_quality, o.corner_min_distance);
    const auto scaled = [&](const cv::Rect2f& b) {
        return cv::Rect(cv::Rect2f(static_cast<float>(b.x * sc), static_cast<float>(b.y * sc),
                                   static_cast<float>(b.width * sc),
                                   static_cast<float>(b.height * sc))) &
               whole;
    };
    if (o.background_corners > 0 && !tracks.empty()) {
        // People filling the view leave few of the image's strongest corners away from their
        // boxes, where egoMotion takes its background: with fewer than min_background_points
        // there it keeps the prior, whose error (a constant-velocity guess while the camera
        // swings) then shows as residual flow everywhere and hides the walkers' own. On
        // walking_rpy that left a walker crossing near the camera unmasked for ten frames.
        cv::Mat away(work.size(), CV_8U, cv::Scalar(255));
        for (const auto& t : tracks) away(scaled(nearBox(t.tb.box, o))).setTo(0);
        const auto have = std::count_if(p0.begin(), p0.end(), [&](const cv::Point2f& p) {
            return away.at<uchar>(cv::Point(p)) != 0;
        });
        if (have < o.background_corners) {
            const auto pts =
                selectShiTomasi(corner_map, whole, o.background_corners - static_cast<int>(have),
                                o.corner_quality, o.corner_min_distance * 0.5, away, p0);
            p0.insert(p0.end(), pts.begin(), pts.end());
        }
    }
    if (o.max_corners_per_box > 0) {
        for (const auto& t : tracks) {
            const cv::Rect roi = scaled(shrink(t.tb.box, o.box_shrink));
            if (roi.width < 8 || roi.height < 8) continue;
            cv::Mat fg;  // the person's depth band in the ROI (empty: whole ROI)
            if (o.fg_depth_band > 0 && t.depth) {  // t.depth: the previous step's
                const float zp = *t.depth, h = depthBand(o.fg_depth_band, zp);
                const cv::Rect full =
                    cv::Rect(cv::Rect2f(
                        static_cast<float>(roi.x / sc), static_cast<float>(roi.y / sc),
                        static_cast<float>(roi.width / sc), static_cast<float>(roi.height / sc))) &
                    cv::Rect(0, 0, prev_depth.cols, prev_depth.rows);
                cv::Mat band;
                cv::inRange(prev_depth(full), zp - h, zp + h, band);
                cv::resize(band, fg, roi.size(), 0, 0, cv::INTER_NEAREST);
            }
            // A box's strongest corners are often the image's too (one eigenvalue map), and
            // overlapping boxes share theirs: the box gets corners of its own, apart from those
            // chosen before, or one pixel's flow would count twice towards its evidence
            // (min_points, threshold2_count), as it did until session 32.
            const auto pts = selectShiTomasi(corner_map, roi, o.max_corners_per_box,
                                             o.corner_quality, o.corner_min_distance * 0.5, fg, p0);
            p0.insert(p0.end(), pts.begin(), pts.end());
        }
    }
    const auto t1 = Clock::now();
    times.corners = std::chrono::duration<double, std::milli>(t1 - t0).count();
    if (p0.empty()) return f;
    const cv::Size win(o.lk_window, o.lk_window);
    std::vector<uchar> st, st_back;
    std::vector<float> err;
    const cv::TermCriteria term = lkTermination();
    cv::calcOpticalFlowPyrLK(prev_pyr, pyr, p0, p1, st, err, win, o.lk_levels, term);
    std::vector<cv::Point2f> back = p0;
    cv::calcOpticalFlowPyrLK(pyr, prev_pyr, p1, back, st_back, err, win, o.lk_levels, term,
                             cv::OPTFLOW_USE_INITIAL_FLOW);
    std::size_t n = 0;
    const auto inv = static_cast<float>(1.0 / sc);
    // Pixel centres: the scaled image's pixel i averages (INTER_AREA) the full image's
    // pixels i/sc .. (i+1)/sc - 1, whose centre is (i + 0.5)/sc - 0.5 (p/sc put every point
    // half a pixel up and left at flow_scale 0.5).
    const auto full = [&](const cv::Point2f& p) {
        return (p + cv::Point2f(0.5f, 0.5f)) * inv - cv::Point2f(0.5f, 0.5f);
    };
    for (std::size_t i = 0; i < p0.size(); ++i) {
        const float fb = static_cast<float>(cv::norm(back[i] - p0[i])) * inv;
        const cv::Point2f a = full(p0[i]), b = full(p1[i]);
        if (!st[i] || !st_back[i] || fb > o.fb_max_error || !image.contains(b)) continue;
        p0[n] = a;
        p1[n] = b;
        ++n;
    }
    p0.resize(n);
    p1.resize(n);
    times.flow = msSince(t1);
    return f;
}

void DynamicObjectFilter::Impl::carryBoxes(const PointFlow& f, const cv::Rect2f& image) {
    for (auto& t : tracks) {
        std::vector<float> dx, dy;
        for (std::size_t i = 0; i < f.p0.size(); ++i)
            if (t.tb.box.contains(f.p0[i])) {
                dx.push_back(f.p1[i].x - f.p0[i].x);
                dy.push_back(f.p1[i].y - f.p0[i].y);
            }
        if (dx.size() >= 3) {
            std::nth_element(dx.begin(), dx.begin() + dx.size() / 2, dx.end());
            std::nth_element(dy.begin(), dy.begin() + dy.size() / 2, dy.end());
            t.tb.box.x += dx[dx.size() / 2];
            t.tb.box.y += dy[dy.size() / 2];
        }
        t.tb.box &= image;
        t.tb.detected_this_frame = false;
    }
}

void DynamicObjectFilter::Impl::associate(const std::vector<detect::Detection>& dets,
                                          const Options& o) {
    std::vector<bool> used_det(dets.size(), false), used_trk(tracks.size(), false);
    // Detections scoring under new_track_score only continue tracks (and are matched after
    // the confident ones): a person the detector grows unsure of (cut by the image border,
    // half hidden) stays tracked without weak boxes starting tracks of their own.
    const auto confident = [&](std::size_t d) { return dets[d].score >= o.new_track_score; };
    struct Pair {
        bool confident;
        float iou;
        std::size_t d, t;
    };
    std::vector<Pair> pairs;
    for (std::size_t d = 0; d < dets.size(); ++d)
        for (std::size_t t = 0; t < tracks.size(); ++t) {
            const float v = detect::iou(dets[d].box, tracks[t].tb.box);
            if (v >= o.iou_match) pairs.push_back({confident(d), v, d, t});
        }
    std::sort(pairs.begin(), pairs.end(), [](const Pair& a, const Pair& b) {
        return std::tie(a.confident, a.iou, b.d, b.t) > std::tie(b.confident, b.iou, a.d, a.t);
    });
    for (const auto& p : pairs) {
        if (used_det[p.d] || used_trk[p.t]) continue;
        used_det[p.d] = used_trk[p.t] = true;
        auto& t = tracks[p.t];
        t.tb.box = dets[p.d].box;
        t.tb.score = dets[p.d].score;
        t.tb.detected_this_frame = true;
        t.missed = 0;
    }
    for (std::size_t t = 0; t < tracks.size(); ++t)
        if (!used_trk[t]) ++tracks[t].missed;
    // A track whose last step showed motion is kept without detections, carried by its
    // points' flow: the detector loses walkers cut by the image border, half hidden or
    // filling the view, and the corners seeded in their box would otherwise join the
    // background of the next ego-motion fit. Dropped once quiet and unmatched.
    tracks.erase(std::remove_if(tracks.begin(), tracks.end(),
                                [&](const Track& t) {
                                    const bool moving_now =
                                        t.tb.state == BoxState::Moving && t.quiet == 0;
                                    return t.missed > o.max_missed_detections && !moving_now;
                                }),
                 tracks.end());
    for (std::size_t d = 0; d < dets.size(); ++d) {
        if (used_det[d] || !confident(d)) continue;
        Track t;
        t.tb.id = next_id++;
        t.tb.box = dets[d].box;
        t.tb.score = dets[d].score;
        t.tb.detected_this_frame = true;
        tracks.push_back(t);
    }
}

void DynamicObjectFilter::Impl::measureBoxes(const cv::Mat& depth, const Options& o) {
    tracks.erase(std::remove_if(tracks.begin(), tracks.end(),
                                [](const Track& t) { return t.tb.box.area() < 16.f; }),
                 tracks.end());
    const bool need_depth = o.fg_depth_band > 0 || o.narrow_vote_band > 0 || o.mask_silhouette ||
                            o.depth_frames > 0 || (o.slow_frames > 0 && o.slow_speed > 0) ||
                            o.static_person_outline > 0;
    for (auto& t : tracks) {
        const auto z =
            need_depth ? personDepth(depth, t.tb.box, o.max_depth, o.fg_depth_band) : std::nullopt;
        // A jump past the band (the person's depth found on another surface: a walker who
        // came to fill enough of their box at the border, or the wall behind one who left
        // it) leaves the box's evidence histories about a surface it no longer looks at:
        // the depth test's sum mixed the wall's residuals, of larger noise, with the
        // bound of the nearer person's depth, and a still person went Moving.
        if (z && t.depth && o.fg_depth_band > 0 &&
            std::abs(*z - *t.depth) > depthBand(o.fg_depth_band, std::min(*z, *t.depth))) {
            t.depth_history.clear();
            t.slow_history.clear();
        }
        t.depth = z;
    }
}

bool DynamicObjectFilter::Impl::nearAnyBox(const cv::Point2f& a, const cv::Point2f& b,
                                           const Options& o) const {
    for (const auto& t : tracks) {
        const cv::Rect2f grown = nearBox(t.tb.box, o);
        if (grown.contains(a) || grown.contains(b)) return true;
    }
    return false;
}

Eigen::Isometry3d DynamicObjectFilter::Impl::egoMotion(
    const PointFlow& f, const core::CameraIntrinsics& Kc,
    const std::optional<Eigen::Isometry3d>& prior, const Options& o, Residuals& r,
    FilterOutput& out) const {
    const std::vector<cv::Point2f>& p0 = f.p0;
    const std::vector<cv::Point2f>& p1 = f.p1;
    r.X.assign(p0.size(), std::nullopt);
    r.background.assign(p0.size(), false);
    std::vector<cv::Point3f> bg_obj;
    std::vector<cv::Point2f> bg_img;
    for (std::size_t i = 0; i < p0.size(); ++i) {
        const auto z = stableDepth(prev_depth, p0[i], o.max_depth);
        if (!z) continue;
        r.X[i] = core::backproject(f.u0[i].x, f.u0[i].y, *z, prev_K);
        r.background[i] = !nearAnyBox(p0[i], p1[i], o);
        if (r.background[i]) {
            bg_obj.emplace_back(static_cast<float>(r.X[i]->x()), static_cast<float>(r.X[i]->y()),
                                static_cast<float>(r.X[i]->z()));
            bg_img.push_back(f.u1[i]);  // the PnP's pinhole K: undistorted pixels
        }
    }
    Eigen::Isometry3d T_prev_cur = prior.value_or(Eigen::Isometry3d::Identity());
    if (!o.refine_ego_motion || static_cast<int>(bg_obj.size()) < o.min_background_points)
        return T_prev_cur;
    // solvePnP gives T_cur_prev (x_cur = R x_prev + t).
    const Eigen::Isometry3d T_cp = T_prev_cur.inverse();
    cv::Mat R_cv, rvec, tvec;
    cv::eigen2cv(Eigen::Matrix3d(T_cp.linear()), R_cv);
    cv::Rodrigues(R_cv, rvec);
    cv::eigen2cv(Eigen::Vector3d(T_cp.translation()), tvec);
    cv::Mat K_cv;
    cv::eigen2cv(Kc.matrix(), K_cv);
    std::vector<int> inliers;
    // (OpenCV's RANSAC uses its own fixed-seed RNG: runs are repeatable.)
    const bool ok = cv::solvePnPRansac(bg_obj, bg_img, K_cv, cv::noArray(), rvec, tvec, true, 100,
                                       static_cast<float>(o.ransac_reprojection), 0.99, inliers,
                                       cv::SOLVEPNP_ITERATIVE);
    // At least a quarter of the background points: walkers the detector missed, and the
    // clutter around the boxes, can be many of them.
    if (ok && static_cast<int>(inliers.size()) >= o.min_background_points &&
        inliers.size() * 4 >= bg_obj.size()) {
        cv::Mat R_new;
        cv::Rodrigues(rvec, R_new);
        Eigen::Matrix3d R;
        Eigen::Vector3d t;
        cv::cv2eigen(R_new, R);
        cv::cv2eigen(tvec, t);
        Eigen::Isometry3d T_cp_new = Eigen::Isometry3d::Identity();
        T_cp_new.linear() = R;
        T_cp_new.translation() = t;
        T_prev_cur = T_cp_new.inverse();
        out.T_prev_cur_refined = T_prev_cur;
    }
    return T_prev_cur;
}

void DynamicObjectFilter::Impl::residualFlow(const core::Frame& frame, const PointFlow& f,
                                             const Eigen::Isometry3d& T_prev_cur, const Options& o,
                                             Residuals& r, FilterOutput& out) const {
    // The threshold adapts to frames where even the background fits badly (rgb/depth time
    // offset, motion blur): a point is dynamic above max(threshold1, background_factor *
    // 90th percentile of the background residuals).
    const std::vector<cv::Point2f>& p0 = f.p0;
    const std::vector<cv::Point2f>& p1 = f.p1;
    const core::CameraIntrinsics& Kc = frame.K;
    const Eigen::Isometry3d T_cur_prev = T_prev_cur.inverse();
    out.flow.reserve(p0.size());
    r.vec.assign(p0.size(), cv::Point2f(0.f, 0.f));
    const bool want_z = o.depth_frames > 0;
    r.z.assign(p0.size(), std::numeric_limits<float>::quiet_NaN());
    std::vector<float> bg_res, bg_z;
    for (std::size_t i = 0; i < p0.size(); ++i) {
        FilterOutput::FlowPoint fp{p0[i], p1[i], -1.f, false, false};
        if (r.X[i]) {
            const Eigen::Vector3d Xc = T_cur_prev * *r.X[i];
            if (const auto uv = core::project(Xc, Kc)) {
                r.vec[i] = {f.u1[i].x - static_cast<float>(uv->x()),
                            f.u1[i].y - static_cast<float>(uv->y())};
                fp.residual = static_cast<float>(std::hypot(r.vec[i].x, r.vec[i].y));
                if (want_z)
                    if (const auto z = stableDepth(frame.depth, p1[i], o.max_depth))
                        r.z[i] = *z - static_cast<float>(Xc.z());
            }
        }
        if (fp.residual >= 0.f && r.background[i]) {  // (a residual needs X)
            bg_res.push_back(fp.residual);
            if (!std::isnan(r.z[i])) bg_z.push_back(r.z[i]);
        }
        out.flow.push_back(fp);
    }
    // An ego-motion error along the optical axis shifts every depth residual alike.
    if (bg_z.size() >= static_cast<std::size_t>(o.min_background_points)) {
        const auto k = bg_z.begin() + static_cast<std::ptrdiff_t>(bg_z.size() / 2);
        std::nth_element(bg_z.begin(), k, bg_z.end());
        for (auto& z : r.z) z -= *k;
    }
    double thr = o.threshold1;
    if (bg_res.size() >= static_cast<std::size_t>(o.min_background_points)) {
        const auto k = bg_res.begin() + static_cast<std::ptrdiff_t>(bg_res.size() * 9 / 10);
        std::nth_element(bg_res.begin(), k, bg_res.end());
        thr = std::max(thr, o.background_factor * static_cast<double>(*k));
    }
    out.threshold = thr;
    for (auto& fp : out.flow) fp.dynamic = fp.residual > thr;
}

double DynamicObjectFilter::Impl::localThreshold(const cv::Rect2f& box, const FilterOutput& out,
                                                 const Options& o) const {
    // The residuals of the static surroundings (a ring from 20% to 70% of the box size
    // around it, outside every box) say how well ego-motion fits there (depth errors of
    // near objects, rgb/depth time offset, rolling shutter).
    double local_thr = out.threshold;
    if (o.background_factor <= 0) return local_thr;
    auto grow = [&](float f) {
        return cv::Rect2f(box.x - f * box.width, box.y - f * box.height, box.width * (1 + 2 * f),
                          box.height * (1 + 2 * f));
    };
    const cv::Rect2f near = grow(0.2f), far = grow(0.7f);
    std::vector<float> ring;
    for (const auto& fp : out.flow) {
        if (fp.residual < 0.f || !far.contains(fp.cur) || near.contains(fp.cur)) continue;
        bool in_other = false;
        for (const auto& t : tracks) in_other |= t.tb.box.contains(fp.cur);
        if (!in_other) ring.push_back(fp.residual);
    }
    if (ring.size() >= 8) {
        const auto k = ring.begin() + static_cast<std::ptrdiff_t>(ring.size() * 3 / 4);
        std::nth_element(ring.begin(), k, ring.end());
        local_thr = std::max(local_thr, o.background_factor * static_cast<double>(*k));
    }
    return local_thr;
}

void DynamicObjectFilter::Impl::classifyBoxes(const Residuals& r, const core::Frame& frame,
                                              double dt, const Options& o, FilterOutput& out) {
    const cv::Size size = frame.bgr.size();
    for (auto& t : tracks) {
        const cv::Rect2f inner = shrink(t.tb.box, o.box_shrink);
        const double local_thr = localThreshold(t.tb.box, out, o);
        const bool use_band = o.fg_depth_band > 0 && t.depth.has_value();
        const float zp = t.depth.value_or(0.f);
        // The narrow vote's points: those nearest the person's depth (see Options).
        const bool use_narrow = o.narrow_vote_band > 0 && t.depth.has_value();
        const auto narrow =
            static_cast<float>(o.narrow_vote_band + o.narrow_vote_slope * static_cast<double>(zp));
        int n = 0, n_dyn = 0, n_narrow = 0, n_narrow_dyn = 0;
        std::vector<float> rx, ry;  // residual vectors of the box's points (slow walkers)
        std::vector<float> rz;      // their depth residuals (walkers towards the camera)
        for (std::size_t i = 0; i < out.flow.size(); ++i) {
            auto& fp = out.flow[i];
            if (fp.residual < 0.f || !inner.contains(fp.cur)) continue;
            // (a point with a residual has a depth: r.X[i] is set)
            const float dz = t.depth ? std::abs(static_cast<float>(r.X[i]->z()) - zp) : 0.f;
            if (use_band && dz > depthBand(o.fg_depth_band, zp))
                continue;  // background or foreground clutter seen inside the box
            fp.in_box = true;
            fp.dynamic = fp.residual > local_thr;
            ++n;
            if (fp.dynamic) ++n_dyn;
            if (use_narrow && dz <= narrow) {
                ++n_narrow;
                if (fp.dynamic) ++n_narrow_dyn;
            }
            if (o.slow_frames > 0) {
                rx.push_back(r.vec[i].x);
                ry.push_back(r.vec[i].y);
            }
            if (!r.z.empty() && !std::isnan(r.z[i])) rz.push_back(r.z[i]);
        }
        t.tb.n_points = n;
        t.tb.n_dynamic_points = n_dyn;
        // The image's left or right border, where walkers enter, leave and come back, and
        // where one cut by the border is often undetected, without points, or without motion
        // on their first steps (the bottom border cuts every near person's box, so it does
        // not count).
        const auto m = static_cast<float>(o.mask_margin);
        const bool at_border =
            t.tb.box.x <= m || t.tb.box.br().x >= static_cast<float>(size.width) - m;
        if (n < o.min_points) {  // no evidence: keep the state
            // and no detection either: unseen, unless the box is at the border
            if (t.missed > 0 && !(o.keep_border_tracks && at_border))
                ++t.unseen;
            else
                t.unseen = 0;
            continue;
        }
        t.unseen = 0;
        const auto vote = [&o](int points, int dynamic) {
            return dynamic >= o.threshold2_count &&
                   dynamic >= o.threshold2_fraction * static_cast<double>(points);
        };
        bool moving = vote(n, n_dyn);
        // The narrow vote: a walker passing a still desk or shelf at nearly their depth has
        // the clutter's points in the wide band too, and they outvote the walker's.
        if (use_narrow && n_narrow >= o.min_points) moving |= vote(n_narrow, n_narrow_dyn);
        if (o.slow_frames > 0) {
            // Slow walkers: the mean of the box's per-step median residual vectors. A
            // walker who stops keeps it above the threshold for up to slow_frames - 1
            // steps, which delay the release by as many.
            const auto mid = rx.size() / 2;
            std::nth_element(rx.begin(), rx.begin() + static_cast<std::ptrdiff_t>(mid), rx.end());
            std::nth_element(ry.begin(), ry.begin() + static_cast<std::ptrdiff_t>(mid), ry.end());
            t.slow_history.emplace_back(rx[mid], ry[mid]);
            if (t.slow_history.size() > static_cast<std::size_t>(o.slow_frames))
                t.slow_history.pop_front();
            if (t.slow_history.size() == static_cast<std::size_t>(o.slow_frames)) {
                cv::Point2f sum(0.f, 0.f);
                for (const auto& v : t.slow_history) sum += v;
                const double mean = cv::norm(sum) / o.slow_frames;
                // The speed in pixels per frame at the person's depth; not known without a
                // depth, or for timestamps that do not advance or jump by a second or more.
                double slow_px = o.slow_threshold;
                if (o.slow_speed > 0 && t.depth && dt > 0 && dt < 1)
                    slow_px = std::max(slow_px, o.slow_speed * dt * frame.K.fx / *t.depth);
                moving |= mean > std::max(slow_px, 0.5 * local_thr);
            }
        }
        if (o.depth_frames > 0) {
            // A step whose box has too few points with depth adds no sample (the window
            // then spans more steps).
            // The interquartile mean, not the median, of the box's depth residuals: depth
            // comes in disparity steps (2 cm at 2.6 m), larger than a walker's change a frame
            // there, and where the band holds static points too (most likely the floor at the
            // feet), the median sat at 0 in most frames. A walker of walking_towards was Static for
            // 100 frames; masked 86.8 -> 91.6 % of their frames (docs/dynamic.md, session 14).
            if (rz.size() >= static_cast<std::size_t>(o.min_points)) {
                t.depth_history.push_back(static_cast<float>(
                    core::interquartileMean(std::vector<double>(rz.begin(), rz.end()))));
                if (t.depth_history.size() > static_cast<std::size_t>(o.depth_frames))
                    t.depth_history.pop_front();
            }
            if (t.depth_history.size() == static_cast<std::size_t>(o.depth_frames) && t.depth) {
                double sum = 0;
                for (const float z : t.depth_history) sum += z;
                const double z = *t.depth;
                moving |= std::abs(sum) > std::max(o.depth_rate_threshold * o.depth_frames,
                                                   o.depth_noise_z2 * z * z);
            }
        }
        if (moving) {
            t.tb.state = BoxState::Moving;  // caught at once
            t.quiet = 0;
        } else if (t.tb.state == BoxState::Moving) {
            if (++t.quiet >= o.release_frames) t.tb.state = BoxState::Static;
        } else if (t.tb.state == BoxState::Unknown) {
            if (++t.quiet >= (at_border ? o.confirm_border_frames : 1))
                t.tb.state = BoxState::Static;
        }
    }
}

void DynamicObjectFilter::Impl::forgetUnseen(const Options& o) {
    // A track nothing has shown for forget_unseen_frames steps is gone for good; before
    // that, from hide_unseen_frames on, it is kept out of the boxes and the mask but
    // remembered, so that a walker who comes back (through the border they left by, from
    // behind someone) is matched and masked at once instead of collecting evidence anew.
    if (o.hide_unseen_frames > 0)
        tracks.erase(
            std::remove_if(tracks.begin(), tracks.end(),
                           [&](const Track& t) { return t.unseen > o.forget_unseen_frames; }),
            tracks.end());
}

namespace {

/// Clears the set pixels of `sil` not 8-connected to one inside `inner` (a rectangle in
/// sil's coordinates). Pixels inside `inner` are all kept: their components reach it.
void keepConnectedTo(cv::Mat& sil, const cv::Rect& inner) {
    cv::Mat labels;
    const int n = cv::connectedComponents(sil, labels, 8, CV_32S);
    if (n <= 1) return;
    std::vector<unsigned char> keep(static_cast<std::size_t>(n), 0);
    const cv::Mat in = labels(inner);
    for (int y = 0; y < in.rows; ++y) {
        const int* row = in.ptr<int>(y);
        for (int x = 0; x < in.cols; ++x) keep[static_cast<std::size_t>(row[x])] = 1;
    }
    keep[0] = 0;
    for (int y = 0; y < sil.rows; ++y) {
        const int* l = labels.ptr<int>(y);
        unsigned char* m = sil.ptr<unsigned char>(y);
        for (int x = 0; x < sil.cols; ++x)
            if (m[x] && !keep[static_cast<std::size_t>(l[x])]) m[x] = 0;
    }
}

/// Half-width [m] of the depth band of a person at depth zp that their silhouette holds.
float silhouetteBand(const DynamicObjectFilter::Options& o, float zp) {
    const double band = o.silhouette_depth_band > 0 ? o.silhouette_depth_band
                        : o.fg_depth_band > 0       ? o.fg_depth_band
                                                    : 0.5;
    return static_cast<float>(band + o.silhouette_depth_slope * zp);
}

/// The person's silhouette as mask_silhouette draws it: the pixels of `outer` in the
/// person's depth band (person depth zp) or without depth (the holes along a person's
/// outline); outside `inner` (the box, inside outer) only those connected to the silhouette
/// inside it (a head above the box, not a desk at the person's depth beside it). In outer's
/// coordinates.
cv::Mat silhouetteIn(const cv::Mat& depth, const cv::Rect& outer, const cv::Rect& inner, float zp,
                     const DynamicObjectFilter::Options& o) {
    const float h = silhouetteBand(o, zp);
    cv::Mat sil, holes;
    cv::inRange(depth(outer), zp - h, zp + h, sil);
    cv::compare(depth(outer), 0.f, holes, cv::CMP_LE);
    sil |= holes;
    if (outer != inner) keepConnectedTo(sil, inner - outer.tl());
    return sil;
}

/// `r` grown by gx px left and right and gy px up and down, clipped to an image of `size`.
cv::Rect grownClipped(const cv::Rect& r, int gx, int gy, const cv::Size& size) {
    return cv::Rect(r.x - gx, r.y - gy, r.width + 2 * gx, r.height + 2 * gy) & cv::Rect({}, size);
}

/// The box grown by silhouette_grow (the region the silhouette is sought in), clipped.
cv::Rect grownBox(const cv::Rect& inner, const cv::Rect2f& box, const cv::Size& size,
                  const DynamicObjectFilter::Options& o) {
    return grownClipped(inner, static_cast<int>(std::lround(o.silhouette_grow * box.width)),
                        static_cast<int>(std::lround(o.silhouette_grow * box.height)), size);
}

/// Sets in `mask` the pixels within `w` px of a Static person's outline where it is a depth
/// edge (static_person_outline), on both sides: where the person covers the wall behind them
/// (or a desk covers them). The outline is the silhouette's boundary (its pixels with a
/// 4-neighbour outside it); a boundary pixel is a depth edge when the valid depths within
/// kEdgeReach px of it span more than the person's depth band. The reach spans the band of
/// missing depth a depth camera leaves along a discontinuity (the silhouette holds those
/// holes, so its boundary is on their far side); holes do not count as depths, so the
/// scattered missing pixels of the person and the wall make no edges. A cut of the
/// silhouette by the grown box (a box that stops at the knees) and a box on a flat wall (a
/// false detection) have no outline, and the image's border none either: the first version
/// of this band, the silhouette's dilation less its erosion, outlined the first two
/// (docs/dynamic.md, "A band along the still person's outline").
void drawOutline(const core::Frame& frame, const cv::Rect& inner, const cv::Rect2f& box, float zp,
                 const DynamicObjectFilter::Options& o, cv::Mat& mask) {
    constexpr int kEdgeReach = 5;  // [px]
    const int w = o.static_person_outline;
    const cv::Size size = mask.size();
    const cv::Rect outer = grownBox(inner, box, size, o);
    const cv::Rect region = grownClipped(outer, w, w, size);
    // The span of the valid depths around each pixel, from the image beyond the grown box
    // too (a head at the box's top, with the wall above it). Holes: 0, never the largest;
    // set to +max, never the smallest.
    const cv::Rect wide = grownClipped(outer, kEdgeReach, kEdgeReach, size);
    const cv::Mat depth = frame.depth(wide);
    const cv::Mat reach =
        cv::getStructuringElement(cv::MORPH_RECT, cv::Size(2 * kEdgeReach + 1, 2 * kEdgeReach + 1));
    cv::Mat dmax, dmin, no_hole = depth.clone(), jump;
    no_hole.setTo(std::numeric_limits<float>::max(), depth <= 0.f);
    cv::dilate(depth, dmax, reach, {-1, -1}, 1, cv::BORDER_REPLICATE);
    cv::erode(no_hole, dmin, reach, {-1, -1}, 1, cv::BORDER_REPLICATE);
    cv::compare(dmax - dmin, silhouetteBand(o, zp), jump, cv::CMP_GT);
    // The silhouette's boundary, the grown box's cut included (the depth span decides there:
    // a head cut by it is an edge, legs or a flat wall are not)
    const cv::Mat sil = silhouetteIn(frame.depth, outer, inner, zp, o);
    cv::Mat eroded;
    cv::erode(sil, eroded, cv::getStructuringElement(cv::MORPH_CROSS, cv::Size(3, 3)), {-1, -1}, 1,
              cv::BORDER_CONSTANT, cv::Scalar(0));
    const cv::Mat edge = sil & ~eroded & jump(outer - wide.tl());
    // The band: every pixel within w px of an edge pixel (the zeros of `far`). A distance
    // transform, not a dilation by a disc: linear in the region's pixels, whatever w.
    cv::Mat far(region.size(), CV_8UC1, cv::Scalar(255)), dist, band;
    far(outer - region.tl()).setTo(0, edge);
    cv::distanceTransform(far, dist, cv::DIST_L2, cv::DIST_MASK_PRECISE);
    cv::compare(dist, static_cast<double>(w), band, cv::CMP_LE);
    mask(region) |= band;
}

}  // namespace

void DynamicObjectFilter::Impl::drawMask(const core::Frame& frame, bool have_prev, const Options& o,
                                         FilterOutput& out) const {
    // Whole boxes, dilated by the margin. On a frame with no previous one every box is
    // Unknown, walkers and sitters alike: masking them all there would be all_persons for
    // that frame (mask_unknown_first_frame).
    const cv::Size size = frame.bgr.size();
    const bool mask_unknown = o.mask_unknown && (have_prev || o.mask_unknown_first_frame);
    // The people judged Static, for the SLAM's static_person_weight (mode Dynamic only:
    // all_persons masks them).
    const bool weigh_static = o.mode == MaskMode::Dynamic && o.static_person_weight < 1.0;
    const bool outline_static = o.mode == MaskMode::Dynamic && o.static_person_outline > 0;
    if (weigh_static) out.static_people = cv::Mat::zeros(size, CV_8UC1);
    for (const auto& t : tracks) {
        if (t.hidden(o)) continue;
        out.boxes.push_back(t.tb);
        const bool masked = o.mode == MaskMode::AllPersons || t.tb.state == BoxState::Moving ||
                            (mask_unknown && t.tb.state == BoxState::Unknown);
        if (!masked) {
            // first_frame_as_static: the people of a frame with no previous one (all
            // Unknown, unmasked there) are treated as people judged Static
            const bool first_unknown =
                o.first_frame_as_static && !have_prev && t.tb.state == BoxState::Unknown;
            if (t.tb.state != BoxState::Static && !first_unknown) continue;
            // The whole box, not the silhouette (with or without the margin): on sitting_xyz
            // the silhouette's weights were worse (docs/dynamic.md, "Weighing seated people
            // down"); a gesturing hand leaves the person's depth band, not the box.
            const cv::Rect inner = cv::Rect(t.tb.box) & cv::Rect({}, size);
            if (weigh_static) out.static_people(inner).setTo(255);
            // (a person Static for static_person_outline_after steps: walkers the filter
            // holds Static for a while are left alone, docs/dynamic.md)
            if (outline_static && t.depth && !inner.empty() &&
                (first_unknown || t.static_steps >= o.static_person_outline_after))
                drawOutline(frame, inner, t.tb.box, *t.depth, o, out.mask);
            continue;
        }
        const auto m = static_cast<float>(o.mask_margin);
        const auto snap = static_cast<float>(o.mask_border_snap);
        const auto W = static_cast<float>(size.width), H = static_cast<float>(size.height);
        float x0 = t.tb.box.x - m, y0 = t.tb.box.y - m;
        float x1 = t.tb.box.br().x + m, y1 = t.tb.box.br().y + m;
        // (snap 0 still snaps a side whose margin crosses the border: the silhouette below
        // may then follow the person's pixels to it, as the clipped whole box reaches it)
        const bool snap_l = x0 < snap;
        const bool snap_t = y0 < snap;
        const bool snap_r = x1 > W - snap;
        const bool snap_b = y1 > H - snap;
        if (snap_l) x0 = 0.f;
        if (snap_t) y0 = 0.f;
        if (snap_r) x1 = W;
        if (snap_b) y1 = H;
        const cv::Rect r = cv::Rect(cv::Rect2f(x0, y0, x1 - x0, y1 - y0)) & cv::Rect({}, size);
        if (!o.mask_silhouette || !t.depth) {
            out.mask(r).setTo(255);
            continue;
        }
        // Silhouette: the box's pixels in the person's depth band or without depth (the
        // holes along a person's outline), dilated by the margin.
        const cv::Rect inner = cv::Rect(t.tb.box) & cv::Rect({}, size);
        if (inner.empty()) continue;
        // The band is sought in the box grown by silhouette_grow; outside the box only the
        // parts connected to the silhouette inside it are kept.
        cv::Rect outer = grownBox(inner, t.tb.box, size, o);
        // mask_border_snap: on a side snapped to the border the silhouette may reach it, as
        // the whole box does (still only through the person's pixels, like silhouette_grow).
        if (snap_l) outer = cv::Rect(0, outer.y, outer.br().x, outer.height);
        if (snap_t) outer = cv::Rect(outer.x, 0, outer.width, outer.br().y);
        if (snap_r) outer.width = size.width - outer.x;
        if (snap_b) outer.height = size.height - outer.y;
        const cv::Mat sil = silhouetteIn(frame.depth, outer, inner, *t.depth, o);
        // Room for the margin on every side of the silhouette: where silhouette_grow x box
        // height passed mask_margin the margin was cut at the grown box's edge (the top of
        // a head lost up to mask_margin px of it, session 32).
        const cv::Rect region = grownClipped(outer, o.mask_margin, o.mask_margin, size) | r;
        cv::Mat big = cv::Mat::zeros(region.size(), CV_8UC1);
        sil.copyTo(big(outer - region.tl()));
        if (o.mask_margin > 0)
            cv::dilate(big, big,
                       cv::getStructuringElement(
                           cv::MORPH_RECT, cv::Size(2 * o.mask_margin + 1, 2 * o.mask_margin + 1)));
        out.mask(region) |= big;
    }
}

void DynamicObjectFilter::Impl::endStep(const core::Frame& frame) {
    std::swap(prev_work, work);
    std::swap(prev_pyr, pyr);
    frame.depth.copyTo(prev_depth);
    prev_K = frame.K;
    prev_timestamp = frame.timestamp;
    ++frame_count;
}

std::unique_ptr<DynamicObjectFilter> makeFilterFromConfig(const mrpt::config::CConfigFileBase& cfg,
                                                          std::optional<MaskMode> mode_override) {
    DynamicObjectFilter::Options o;
    o.loadFromConfig(cfg, "dynamic_filter");
    if (mode_override) o.mode = *mode_override;
    // Made in mode None too, and dropped there: a mistyped [detector] key, an unknown
    // detector or a missing weights file was accepted until the mode changed (about 60 ms).
    auto det = detect::makeDetector(cfg, "detector");
    if (o.mode == MaskMode::None) det.reset();
    return std::make_unique<DynamicObjectFilter>(o, std::move(det));
}

}  // namespace devslam::dynamic
