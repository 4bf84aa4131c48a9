#include <devslam/dynamic/DynamicObjectFilter.h>
#include <devslam/dynamic/ShiTomasi.h>

#include <devslam/core/Config.h>

#include <mrpt/config/CConfigFileBase.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include <algorithm>
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
                                     "max_missed_detections",
                                     "hide_unseen_frames",
                                     "forget_unseen_frames",
                                     "keep_border_tracks",
                                     "mask_margin",
                                     "background_factor",
                                     "flow_scale",
                                     "mask_unknown",
                                     "mask_unknown_first_frame",
                                     "mask_border_snap",
                                     "fg_depth_band",
                                     "mask_silhouette",
                                     "silhouette_depth_band",
                                     "slow_frames",
                                     "slow_threshold",
                                     "depth_frames",
                                     "depth_rate_threshold",
                                     "depth_noise_z2",
                                     "new_track_score"};

cv::Rect2f shrink(const cv::Rect2f& b, double f) {
    const auto dx = static_cast<float>(f * b.width), dy = static_cast<float>(f * b.height);
    return {b.x + dx, b.y + dy, b.width - 2 * dx, b.height - 2 * dy};
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

/// The person's depth in a box: median valid depth of its torso region (30-70 % of the
/// width, 15-55 % of the height), where a detected person box is nearly always on the
/// person even when the rest of the box shows background or a desk in front of the legs.
std::optional<float> personDepth(const cv::Mat& depth, const cv::Rect2f& box, double max_depth) {
    const cv::Rect torso =
        cv::Rect(cv::Rect2f(box.x + 0.3f * box.width, box.y + 0.15f * box.height,
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
    return *mid;
}

/// Half-width [m] of the depth band around a person's depth z that belongs to them.
float depthBand(double band, float z) { return static_cast<float>(band) + 0.1f * z; }

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
    mask_silhouette = core::readBool(c, s, "mask_silhouette", mask_silhouette);
    silhouette_depth_band = core::readDouble(c, s, "silhouette_depth_band", silhouette_depth_band);
    slow_frames = core::readInt(c, s, "slow_frames", slow_frames);
    slow_threshold = core::readDouble(c, s, "slow_threshold", slow_threshold);
    depth_frames = core::readInt(c, s, "depth_frames", depth_frames);
    depth_rate_threshold = core::readDouble(c, s, "depth_rate_threshold", depth_rate_threshold);
    depth_noise_z2 = core::readDouble(c, s, "depth_noise_z2", depth_noise_z2);
    new_track_score = core::readDouble(c, s, "new_track_score", new_track_score);
    iou_match = core::readDouble(c, s, "iou_match", iou_match);
    release_frames = core::readInt(c, s, "release_frames", release_frames);
    max_missed_detections = core::readInt(c, s, "max_missed_detections", max_missed_detections);
    hide_unseen_frames = core::readInt(c, s, "hide_unseen_frames", hide_unseen_frames);
    forget_unseen_frames = core::readInt(c, s, "forget_unseen_frames", forget_unseen_frames);
    keep_border_tracks = core::readBool(c, s, "keep_border_tracks", keep_border_tracks);
    mask_margin = core::readInt(c, s, "mask_margin", mask_margin);
    mask_unknown = core::readBool(c, s, "mask_unknown", mask_unknown);
    mask_unknown_first_frame =
        core::readBool(c, s, "mask_unknown_first_frame", mask_unknown_first_frame);
    mask_border_snap = core::readInt(c, s, "mask_border_snap", mask_border_snap);
    core::requireValue(mask_border_snap >= 0, s, "mask_border_snap", "must be >= 0");
    core::requireValue(detect_every >= 1, s, "detect_every", "must be >= 1");
    core::requireValue(flow_scale > 0.1 && flow_scale <= 1.0, s, "flow_scale",
                       "must be in (0.1, 1]");
    core::requireValue(max_corners > 0, s, "max_corners", "must be > 0");
    core::requireValue(max_corners_per_box >= 0, s, "max_corners_per_box", "must be >= 0");
    core::requireValue(corner_quality > 0 && corner_quality < 1, s, "corner_quality",
                       "must be in (0, 1)");
    core::requireValue(lk_window >= 5 && lk_window % 2 == 1, s, "lk_window",
                       "must be odd and >= 5");
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
    core::requireValue(silhouette_depth_band >= 0, s, "silhouette_depth_band",
                       "must be >= 0 (0 = fg_depth_band's)");
    core::requireValue(slow_frames >= 0, s, "slow_frames", "must be >= 0 (0 = off)");
    core::requireValue(slow_threshold > 0, s, "slow_threshold", "must be > 0");
    core::requireValue(depth_frames >= 0, s, "depth_frames", "must be >= 0 (0 = off)");
    core::requireValue(depth_rate_threshold > 0, s, "depth_rate_threshold", "must be > 0");
    core::requireValue(depth_noise_z2 >= 0, s, "depth_noise_z2", "must be >= 0");
    core::requireValue(new_track_score >= 0 && new_track_score <= 1, s, "new_track_score",
                       "must be in [0, 1]");
    core::requireValue(iou_match > 0 && iou_match <= 1, s, "iou_match", "must be in (0, 1]");
    core::requireValue(release_frames >= 1, s, "release_frames", "must be >= 1");
    core::requireValue(max_missed_detections >= 0, s, "max_missed_detections", "must be >= 0");
    core::requireValue(hide_unseen_frames >= 0, s, "hide_unseen_frames", "must be >= 0");
    core::requireValue(forget_unseen_frames >= hide_unseen_frames, s, "forget_unseen_frames",
                       "must be >= hide_unseen_frames");
    core::requireValue(mask_margin >= 0, s, "mask_margin", "must be >= 0");
}

void DynamicObjectFilter::Options::saveToConfig(mrpt::config::CConfigFileBase& c,
                                                const std::string& s) const {
    c.write(s, "mode", toString(mode));
    c.write(s, "detect_every", detect_every);
    c.write(s, "flow_scale", flow_scale);
    c.write(s, "max_corners", max_corners);
    c.write(s, "max_corners_per_box", max_corners_per_box);
    c.write(s, "corner_quality", corner_quality);
    c.write(s, "corner_min_distance", corner_min_distance);
    c.write(s, "lk_window", lk_window);
    c.write(s, "lk_levels", lk_levels);
    c.write(s, "fb_max_error", fb_max_error);
    c.write(s, "refine_ego_motion", refine_ego_motion);
    c.write(s, "min_background_points", min_background_points);
    c.write(s, "ransac_reprojection", ransac_reprojection);
    c.write(s, "max_depth", max_depth);
    c.write(s, "threshold1", threshold1);
    c.write(s, "background_factor", background_factor);
    c.write(s, "threshold2_count", threshold2_count);
    c.write(s, "threshold2_fraction", threshold2_fraction);
    c.write(s, "min_points", min_points);
    c.write(s, "box_shrink", box_shrink);
    c.write(s, "fg_depth_band", fg_depth_band);
    c.write(s, "mask_silhouette", mask_silhouette);
    c.write(s, "silhouette_depth_band", silhouette_depth_band);
    c.write(s, "slow_frames", slow_frames);
    c.write(s, "slow_threshold", slow_threshold);
    c.write(s, "depth_frames", depth_frames);
    c.write(s, "depth_rate_threshold", depth_rate_threshold);
    c.write(s, "depth_noise_z2", depth_noise_z2);
    c.write(s, "new_track_score", new_track_score);
    c.write(s, "iou_match", iou_match);
    c.write(s, "release_frames", release_frames);
    c.write(s, "max_missed_detections", max_missed_detections);
    c.write(s, "hide_unseen_frames", hide_unseen_frames);
    c.write(s, "forget_unseen_frames", forget_unseen_frames);
    c.write(s, "keep_border_tracks", keep_border_tracks);
    c.write(s, "mask_margin", mask_margin);
    c.write(s, "mask_unknown", mask_unknown);
    c.write(s, "mask_unknown_first_frame", mask_unknown_first_frame);
    c.write(s, "mask_border_snap", mask_border_snap);
}

struct DynamicObjectFilter::Impl {
    struct Track {
        TrackedBox tb;
        int quiet = 0;   ///< consecutive frames without moving evidence
        int missed = 0;  ///< detector runs without a matching detection
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
    std::vector<Track> tracks;
    int next_id = 0;
    long frame_count = 0;
};

DynamicObjectFilter::DynamicObjectFilter(const Options& opts,
                                         std::unique_ptr<detect::PersonDetector> detector)
    : opts_(opts), detector_(std::move(detector)), impl_(std::make_unique<Impl>()) {
    if (!detector_ && opts_.mode != MaskMode::None)
        throw std::invalid_argument("dynamic filter: mode '" + toString(opts_.mode) +
                                    "' needs a detector");
}

DynamicObjectFilter::~DynamicObjectFilter() = default;

void DynamicObjectFilter::reset() {
    impl_ = std::make_unique<Impl>();
}

FilterOutput DynamicObjectFilter::step(const core::Frame& frame,
                                       const std::optional<Eigen::Isometry3d>& T_prev_cur_prior) {
    if (frame.bgr.type() != CV_8UC3 || frame.depth.type() != CV_32FC1 ||
        frame.bgr.size() != frame.depth.size() || frame.bgr.empty())
        throw std::invalid_argument("dynamic filter: frame " + std::to_string(frame.index) +
                                    " needs CV_8UC3 colour and CV_32FC1 depth of equal size");
    FilterOutput out;
    out.mask = cv::Mat::zeros(frame.bgr.size(), CV_8UC1);
    if (opts_.mode == MaskMode::None) return out;

    Impl& im = *impl_;
    const auto t_filter0 = Clock::now();
    double detect_ms = 0;
    const cv::Size size = frame.bgr.size();
    // Corners and flow run on a downscaled grey image (flow_scale) for speed; all
    // coordinates below are full-resolution pixels. The images a step builds go into
    // buffers kept in Impl (this step's become the next step's previous ones by swapping):
    // images this large get fresh pages from the kernel, and page faults, when allocated anew.
    const double sc = opts_.flow_scale;
    cv::Mat& work = im.work;
    if (sc != 1.0) {
        cv::cvtColor(frame.bgr, im.gray, cv::COLOR_BGR2GRAY);
        cv::resize(im.gray, work, cv::Size(), sc, sc, cv::INTER_AREA);
    } else {
        cv::cvtColor(frame.bgr, work, cv::COLOR_BGR2GRAY);
    }
    const cv::Size win(opts_.lk_window, opts_.lk_window);
    // With the Scharr derivatives stored in the pyramid, calcOpticalFlowPyrLK does not
    // recompute them for each of the two calls that start from this frame (this step's
    // backward check and the next step's forward flow); the flow is bit-identical.
    std::vector<cv::Mat>& pyr = im.pyr;
    cv::buildOpticalFlowPyramid(work, pyr, win, opts_.lk_levels, true);
    const cv::Rect2f image(0.f, 0.f, static_cast<float>(size.width),
                           static_cast<float>(size.height));
    const bool have_prev = !im.prev_work.empty() && im.prev_work.size() == work.size() &&
                           im.prev_depth.size() == size;

    // 1. Flow of Shi-Tomasi corners of the previous frame (global + inside each box).
    std::vector<cv::Point2f> p0, p1;
    if (have_prev) {
        // One eigenvalue map for the image and every box (see ShiTomasi.h).
        im.corner_map.update(im.prev_work);
        const ShiTomasiMap& corners = im.corner_map;
        p0 = selectShiTomasi(corners, cv::Rect(0, 0, work.cols, work.rows), opts_.max_corners,
                             opts_.corner_quality, opts_.corner_min_distance);
        if (opts_.max_corners_per_box > 0) {
            for (const auto& t : im.tracks) {
                const cv::Rect2f b = shrink(t.tb.box, opts_.box_shrink);
                const cv::Rect roi =
                    cv::Rect(cv::Rect2f(static_cast<float>(b.x * sc), static_cast<float>(b.y * sc),
                                        static_cast<float>(b.width * sc),
                                        static_cast<float>(b.height * sc))) &
                    cv::Rect(0, 0, work.cols, work.rows);
                if (roi.width < 8 || roi.height < 8) continue;
                cv::Mat fg;  // the person's depth band in the ROI (empty: whole ROI)
                if (opts_.fg_depth_band > 0 && t.depth) {  // t.depth: the previous step's
                    const float zp = *t.depth, h = depthBand(opts_.fg_depth_band, zp);
                    const cv::Rect full =
                        cv::Rect(cv::Rect2f(static_cast<float>(roi.x / sc),
                                            static_cast<float>(roi.y / sc),
                                            static_cast<float>(roi.width / sc),
                                            static_cast<float>(roi.height / sc))) &
                        cv::Rect(0, 0, im.prev_depth.cols, im.prev_depth.rows);
                    cv::Mat band;
                    cv::inRange(im.prev_depth(full), zp - h, zp + h, band);
                    cv::resize(band, fg, roi.size(), 0, 0, cv::INTER_NEAREST);
                }
                const auto pts = selectShiTomasi(corners, roi, opts_.max_corners_per_box,
                                                 opts_.corner_quality,
                                                 opts_.corner_min_distance * 0.5, fg);
                p0.insert(p0.end(), pts.begin(), pts.end());
            }
        }
        if (!p0.empty()) {
            std::vector<uchar> st, st_back;
            std::vector<float> err;
            const cv::TermCriteria term(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 10, 0.03);
            cv::calcOpticalFlowPyrLK(im.prev_pyr, pyr, p0, p1, st, err, win, opts_.lk_levels, term);
            std::vector<cv::Point2f> back = p0;
            cv::calcOpticalFlowPyrLK(pyr, im.prev_pyr, p1, back, st_back, err, win, opts_.lk_levels,
                                     term, cv::OPTFLOW_USE_INITIAL_FLOW);
            std::size_t n = 0;
            const auto inv = static_cast<float>(1.0 / sc);
            for (std::size_t i = 0; i < p0.size(); ++i) {
                const float fb = static_cast<float>(cv::norm(back[i] - p0[i])) * inv;
                const cv::Point2f a = p0[i] * inv, b = p1[i] * inv;
                if (!st[i] || !st_back[i] || fb > opts_.fb_max_error || !image.contains(b))
                    continue;
                p0[n] = a;
                p1[n] = b;
                ++n;
            }
            p0.resize(n);
            p1.resize(n);
        }
    }

    // 2. Carry the boxes with the median flow of their points (prediction for association,
    //    and the boxes themselves on frames without detection).
    for (auto& t : im.tracks) {
        std::vector<float> dx, dy;
        for (std::size_t i = 0; i < p0.size(); ++i)
            if (t.tb.box.contains(p0[i])) {
                dx.push_back(p1[i].x - p0[i].x);
                dy.push_back(p1[i].y - p0[i].y);
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

    // 3. Detection every k-th frame, greedy IoU association, new tracks.
    if (im.frame_count % opts_.detect_every == 0) {
        const auto t_det0 = Clock::now();
        const auto dets = detector_->detect(frame.bgr);
        detect_ms = msSince(t_det0);
        out.detector_ran = true;
        std::vector<bool> used_det(dets.size(), false), used_trk(im.tracks.size(), false);
        // Detections scoring under new_track_score only continue tracks (and are
        // matched after the confident ones): a person the detector grows unsure of (cut
        // by the image border, half hidden) stays tracked without weak boxes starting
        // tracks of their own.
        const auto confident = [&](std::size_t d) {
            return dets[d].score >= opts_.new_track_score;
        };
        struct Pair {
            bool confident;
            float iou;
            std::size_t d, t;
        };
        std::vector<Pair> pairs;
        for (std::size_t d = 0; d < dets.size(); ++d)
            for (std::size_t t = 0; t < im.tracks.size(); ++t) {
                const float v = detect::iou(dets[d].box, im.tracks[t].tb.box);
                if (v >= opts_.iou_match) pairs.push_back({confident(d), v, d, t});
            }
        std::sort(pairs.begin(), pairs.end(), [](const Pair& a, const Pair& b) {
            return std::tie(a.confident, a.iou, b.d, b.t) > std::tie(b.confident, b.iou, a.d, a.t);
        });
        for (const auto& p : pairs) {
            if (used_det[p.d] || used_trk[p.t]) continue;
            used_det[p.d] = used_trk[p.t] = true;
            auto& t = im.tracks[p.t];
            t.tb.box = dets[p.d].box;
            t.tb.score = dets[p.d].score;
            t.tb.detected_this_frame = true;
            t.missed = 0;
        }
        for (std::size_t t = 0; t < im.tracks.size(); ++t)
            if (!used_trk[t]) ++im.tracks[t].missed;
        // A track whose last step showed motion is kept without detections, carried by
        // its points' flow: the detector loses walkers cut by the image border, half
        // hidden or filling the view, and the corners seeded in their box would otherwise
        // join the background of the next ego-motion fit. Dropped once quiet and unmatched.
        im.tracks.erase(std::remove_if(im.tracks.begin(), im.tracks.end(),
                                       [&](const Impl::Track& t) {
                                           const bool moving_now =
                                               t.tb.state == BoxState::Moving && t.quiet == 0;
                                           return t.missed > opts_.max_missed_detections &&
                                                  !moving_now;
                                       }),
                        im.tracks.end());
        for (std::size_t d = 0; d < dets.size(); ++d) {
            if (used_det[d] || !confident(d)) continue;
            Impl::Track t;
            t.tb.id = im.next_id++;
            t.tb.box = dets[d].box;
            t.tb.score = dets[d].score;
            t.tb.detected_this_frame = true;
            im.tracks.push_back(t);
        }
    }
    im.tracks.erase(std::remove_if(im.tracks.begin(), im.tracks.end(),
                                   [](const Impl::Track& t) { return t.tb.box.area() < 16.f; }),
                    im.tracks.end());
    // The boxes are final for this step: the person's depth in each, once.
    const bool need_depth =
        opts_.fg_depth_band > 0 || opts_.mask_silhouette || opts_.depth_frames > 0;
    for (auto& t : im.tracks)
        t.depth = need_depth ? personDepth(frame.depth, t.tb.box, opts_.max_depth) : std::nullopt;

    std::vector<std::optional<Eigen::Vector3d>> X;  // 3D of each point in the previous frame
    std::vector<cv::Point2f> res_vec;  // residual flow vector of each point (observed - predicted)
    // depth residual of each point [m]: measured depth at its new position - the depth
    // ego-motion predicts, less the background's median (NaN: no stable depth)
    std::vector<float> res_z;
    // 4. Ego-motion: 3D of each point from the previous depth; relative pose refined with
    //    PnP-RANSAC on points outside every person box.
    if (have_prev && !p0.empty()) {
        const core::CameraIntrinsics& Kp = im.prev_K;
        const core::CameraIntrinsics& Kc = frame.K;
        // Background = outside every box grown by mask_margin plus 20% of its size (the
        // detector's box may lag a walking person's limbs).
        auto inAnyBox = [&](const cv::Point2f& a, const cv::Point2f& b) {
            for (const auto& t : im.tracks) {
                const float mx = opts_.mask_margin + 0.2f * t.tb.box.width;
                const float my = opts_.mask_margin + 0.2f * t.tb.box.height;
                const cv::Rect2f grown(t.tb.box.x - mx, t.tb.box.y - my, t.tb.box.width + 2 * mx,
                                       t.tb.box.height + 2 * my);
                if (grown.contains(a) || grown.contains(b)) return true;
            }
            return false;
        };
        X.assign(p0.size(), std::nullopt);
        std::vector<cv::Point3f> bg_obj;
        std::vector<cv::Point2f> bg_img;
        for (std::size_t i = 0; i < p0.size(); ++i) {
            const auto z = stableDepth(im.prev_depth, p0[i], opts_.max_depth);
            if (!z) continue;
            X[i] = core::backproject(p0[i].x, p0[i].y, *z, Kp);
            if (!inAnyBox(p0[i], p1[i])) {
                bg_obj.emplace_back(static_cast<float>(X[i]->x()), static_cast<float>(X[i]->y()),
                                    static_cast<float>(X[i]->z()));
                bg_img.push_back(p1[i]);
            }
        }
        Eigen::Isometry3d T_prev_cur = T_prev_cur_prior.value_or(Eigen::Isometry3d::Identity());
        if (opts_.refine_ego_motion &&
            static_cast<int>(bg_obj.size()) >= opts_.min_background_points) {
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
            const bool ok =
                cv::solvePnPRansac(bg_obj, bg_img, K_cv, cv::noArray(), rvec, tvec, true, 100,
                                   static_cast<float>(opts_.ransac_reprojection), 0.99, inliers,
                                   cv::SOLVEPNP_ITERATIVE);
            if (ok && static_cast<int>(inliers.size()) >= opts_.min_background_points &&
                inliers.size() * 2 >= bg_obj.size() / 2) {
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
        }
        // 5. Residual flow = observed - predicted from ego-motion and depth. The threshold
        //    adapts to frames where even the background fits badly (rgb/depth time offset,
        //    motion blur): a point is dynamic above max(threshold1, background_factor *
        //    90th percentile of the background residuals).
        const Eigen::Isometry3d T_cur_prev = T_prev_cur.inverse();
        out.flow.reserve(p0.size());
        res_vec.assign(p0.size(), cv::Point2f(0.f, 0.f));
        const bool want_z = opts_.depth_frames > 0;
        res_z.assign(p0.size(), std::numeric_limits<float>::quiet_NaN());
        std::vector<float> bg_res, bg_z;
        for (std::size_t i = 0; i < p0.size(); ++i) {
            FilterOutput::FlowPoint fp{p0[i], p1[i], -1.f, false, false};
            if (X[i]) {
                const Eigen::Vector3d Xc = T_cur_prev * *X[i];
                if (const auto uv = core::project(Xc, Kc)) {
                    res_vec[i] = {p1[i].x - static_cast<float>(uv->x()),
                                  p1[i].y - static_cast<float>(uv->y())};
                    fp.residual = static_cast<float>(std::hypot(res_vec[i].x, res_vec[i].y));
                    if (want_z)
                        if (const auto z = stableDepth(frame.depth, p1[i], opts_.max_depth))
                            res_z[i] = *z - static_cast<float>(Xc.z());
                }
            }
            if (fp.residual >= 0.f && !inAnyBox(p0[i], p1[i])) {
                bg_res.push_back(fp.residual);
                if (!std::isnan(res_z[i])) bg_z.push_back(res_z[i]);
            }
            out.flow.push_back(fp);
        }
        // An ego-motion error along the optical axis shifts every depth residual alike.
        if (bg_z.size() >= static_cast<std::size_t>(opts_.min_background_points)) {
            const auto k = bg_z.begin() + static_cast<std::ptrdiff_t>(bg_z.size() / 2);
            std::nth_element(bg_z.begin(), k, bg_z.end());
            for (auto& z : res_z) z -= *k;
        }
        double thr = opts_.threshold1;
        if (bg_res.size() >= static_cast<std::size_t>(opts_.min_background_points)) {
            const auto k = bg_res.begin() + static_cast<std::ptrdiff_t>(bg_res.size() * 9 / 10);
            std::nth_element(bg_res.begin(), k, bg_res.end());
            thr = std::max(thr, opts_.background_factor * static_cast<double>(*k));
        }
        out.threshold = thr;
        for (auto& fp : out.flow) fp.dynamic = fp.residual > thr;
    }

    // 6. Per-box evidence (Algorithm 1 with residual flow) and hysteresis.
    for (auto& t : im.tracks) {
        const cv::Rect2f inner = shrink(t.tb.box, opts_.box_shrink);
        // Local threshold: the residuals of the static surroundings (a ring from 20% to 70%
        // of the box size around it, outside every box) say how well ego-motion fits there
        // (depth errors of near objects, rgb/depth time offset, rolling shutter).
        double local_thr = out.threshold;
        if (opts_.background_factor > 0) {
            auto grow = [&](float f) {
                return cv::Rect2f(t.tb.box.x - f * t.tb.box.width, t.tb.box.y - f * t.tb.box.height,
                                  t.tb.box.width * (1 + 2 * f), t.tb.box.height * (1 + 2 * f));
            };
            const cv::Rect2f near = grow(0.2f), far = grow(0.7f);
            std::vector<float> ring;
            for (const auto& fp : out.flow) {
                if (fp.residual < 0.f || !far.contains(fp.cur) || near.contains(fp.cur)) continue;
                bool in_other = false;
                for (const auto& o : im.tracks) in_other |= o.tb.box.contains(fp.cur);
                if (!in_other) ring.push_back(fp.residual);
            }
            if (ring.size() >= 8) {
                const auto k = ring.begin() + static_cast<std::ptrdiff_t>(ring.size() * 3 / 4);
                std::nth_element(ring.begin(), k, ring.end());
                local_thr = std::max(local_thr, opts_.background_factor * static_cast<double>(*k));
            }
        }
        const bool use_band = opts_.fg_depth_band > 0 && t.depth.has_value();
        const float zp = t.depth.value_or(0.f);
        int n = 0, n_dyn = 0;
        std::vector<float> rx, ry;  // residual vectors of the box's points (slow walkers)
        std::vector<float> rz;      // their depth residuals (walkers towards the camera)
        for (std::size_t i = 0; i < out.flow.size(); ++i) {
            auto& fp = out.flow[i];
            if (fp.residual < 0.f || !inner.contains(fp.cur)) continue;
            // (a point with a residual has a depth: X[i] is set)
            if (use_band && std::abs(static_cast<float>(X[i]->z()) - zp) >
                                depthBand(opts_.fg_depth_band, zp))
                continue;  // background or foreground clutter seen inside the box
            fp.in_box = true;
            fp.dynamic = fp.residual > local_thr;
            ++n;
            if (fp.dynamic) ++n_dyn;
            if (opts_.slow_frames > 0) {
                rx.push_back(res_vec[i].x);
                ry.push_back(res_vec[i].y);
            }
            if (!res_z.empty() && !std::isnan(res_z[i])) rz.push_back(res_z[i]);
        }
        t.tb.n_points = n;
        t.tb.n_dynamic_points = n_dyn;
        if (n < opts_.min_points) {  // no evidence: keep the state
            // and no detection either: unseen, unless the box reaches the image's left or
            // right border, where walkers leave and come back, and where one cut by the
            // border is often both undetected and without points (the bottom border cuts
            // every near person's box, so it does not count)
            const auto m = static_cast<float>(opts_.mask_margin);
            const bool at_border =
                t.tb.box.x <= m || t.tb.box.br().x >= static_cast<float>(size.width) - m;
            if (t.missed > 0 && !(opts_.keep_border_tracks && at_border))
                ++t.unseen;
            else
                t.unseen = 0;
            continue;
        }
        t.unseen = 0;
        bool moving = n_dyn >= opts_.threshold2_count &&
                      n_dyn >= opts_.threshold2_fraction * static_cast<double>(n);
        if (opts_.slow_frames > 0) {
            // Slow walkers: the mean of the box's per-step median residual vectors. A
            // walker who stops keeps it above the threshold for up to slow_frames - 1
            // steps, which delay the release by as many.
            const auto mid = rx.size() / 2;
            std::nth_element(rx.begin(), rx.begin() + static_cast<std::ptrdiff_t>(mid), rx.end());
            std::nth_element(ry.begin(), ry.begin() + static_cast<std::ptrdiff_t>(mid), ry.end());
            t.slow_history.emplace_back(rx[mid], ry[mid]);
            if (t.slow_history.size() > static_cast<std::size_t>(opts_.slow_frames))
                t.slow_history.pop_front();
            if (t.slow_history.size() == static_cast<std::size_t>(opts_.slow_frames)) {
                cv::Point2f sum(0.f, 0.f);
                for (const auto& r : t.slow_history) sum += r;
                const double mean = cv::norm(sum) / opts_.slow_frames;
                moving |= mean > std::max(opts_.slow_threshold, 0.5 * local_thr);
            }
        }
        if (opts_.depth_frames > 0) {
            // A step whose box has too few points with depth adds no sample (the window
            // then spans more steps).
            if (rz.size() >= static_cast<std::size_t>(opts_.min_points)) {
                const auto mid = rz.begin() + static_cast<std::ptrdiff_t>(rz.size() / 2);
                std::nth_element(rz.begin(), mid, rz.end());
                t.depth_history.push_back(*mid);
                if (t.depth_history.size() > static_cast<std::size_t>(opts_.depth_frames))
                    t.depth_history.pop_front();
            }
            if (t.depth_history.size() == static_cast<std::size_t>(opts_.depth_frames) && t.depth) {
                double sum = 0;
                for (const float z : t.depth_history) sum += z;
                const double z = *t.depth;
                moving |= std::abs(sum) > std::max(opts_.depth_rate_threshold * opts_.depth_frames,
                                                   opts_.depth_noise_z2 * z * z);
            }
        }
        if (moving) {
            t.tb.state = BoxState::Moving;  // caught at once
            t.quiet = 0;
        } else if (t.tb.state == BoxState::Moving) {
            if (++t.quiet >= opts_.release_frames) t.tb.state = BoxState::Static;
        } else {
            t.tb.state = BoxState::Static;
        }
    }

    // A track nothing has shown for forget_unseen_frames steps is gone for good; before
    // that, from hide_unseen_frames on, it is kept out of the boxes and the mask but
    // remembered, so that a walker who comes back (through the border they left by, from
    // behind someone) is matched and masked at once instead of collecting evidence anew.
    if (opts_.hide_unseen_frames > 0)
        im.tracks.erase(std::remove_if(im.tracks.begin(), im.tracks.end(),
                                       [&](const Impl::Track& t) {
                                           return t.unseen > opts_.forget_unseen_frames;
                                       }),
                        im.tracks.end());

    // 7. Mask: whole boxes, dilated by the margin. On a frame with no previous one every
    //    box is Unknown, walkers and sitters alike: masking them all there would be
    //    all_persons for that frame (mask_unknown_first_frame).
    const bool mask_unknown = opts_.mask_unknown && (have_prev || opts_.mask_unknown_first_frame);
    for (const auto& t : im.tracks) {
        if (t.hidden(opts_)) continue;
        out.boxes.push_back(t.tb);
        const bool masked = opts_.mode == MaskMode::AllPersons || t.tb.state == BoxState::Moving ||
                            (mask_unknown && t.tb.state == BoxState::Unknown);
        if (!masked) continue;
        const auto m = static_cast<float>(opts_.mask_margin);
        const auto snap = static_cast<float>(opts_.mask_border_snap);
        const auto W = static_cast<float>(size.width), H = static_cast<float>(size.height);
        float x0 = t.tb.box.x - m, y0 = t.tb.box.y - m;
        float x1 = t.tb.box.br().x + m, y1 = t.tb.box.br().y + m;
        if (x0 < snap) x0 = 0.f;
        if (y0 < snap) y0 = 0.f;
        if (x1 > W - snap) x1 = W;
        if (y1 > H - snap) y1 = H;
        const cv::Rect r =
            cv::Rect(cv::Rect2f(x0, y0, x1 - x0, y1 - y0)) & cv::Rect({}, size);
        if (!opts_.mask_silhouette || !t.depth) {
            out.mask(r).setTo(255);
            continue;
        }
        // Silhouette: the box's pixels in the person's depth band or without depth (the
        // holes along a person's outline), dilated by the margin.
        const float zp = *t.depth;
        const double band = opts_.silhouette_depth_band > 0 ? opts_.silhouette_depth_band
                            : opts_.fg_depth_band > 0       ? opts_.fg_depth_band
                                                            : 0.5;
        const float h = depthBand(band, zp);
        const cv::Rect inner = cv::Rect(t.tb.box) & cv::Rect({}, size);
        if (inner.empty()) continue;
        cv::Mat sil, holes;
        cv::inRange(frame.depth(inner), zp - h, zp + h, sil);
        cv::compare(frame.depth(inner), 0.f, holes, cv::CMP_LE);
        sil |= holes;
        cv::Mat big = cv::Mat::zeros(r.size(), CV_8UC1);
        sil.copyTo(big(inner - r.tl()));
        if (opts_.mask_margin > 0)
            cv::dilate(big, big,
                       cv::getStructuringElement(cv::MORPH_RECT,
                                                 cv::Size(2 * opts_.mask_margin + 1,
                                                          2 * opts_.mask_margin + 1)));
        out.mask(r) |= big;
    }

    std::swap(im.prev_work, im.work);
    std::swap(im.prev_pyr, im.pyr);
    frame.depth.copyTo(im.prev_depth);
    im.prev_K = frame.K;
    ++im.frame_count;
    out.detect_ms = detect_ms;
    out.filter_ms = msSince(t_filter0) - detect_ms;
    return out;
}

std::unique_ptr<DynamicObjectFilter> makeFilterFromConfig(const mrpt::config::CConfigFileBase& cfg,
                                                          std::optional<MaskMode> mode_override) {
    DynamicObjectFilter::Options o;
    o.loadFromConfig(cfg, "dynamic_filter");
    if (mode_override) o.mode = *mode_override;
    std::unique_ptr<detect::PersonDetector> det;
    if (o.mode != MaskMode::None) det = detect::makeDetector(cfg, "detector");
    return std::make_unique<DynamicObjectFilter>(o, std::move(det));
}

}  // namespace devslam::dynamic
