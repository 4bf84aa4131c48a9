#include <devslam/core/Config.h>
#include <devslam/slam/Tracker.h>

#include <mrpt/config/CConfigFileBase.h>

#include <opencv2/calib3d.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

namespace devslam::slam {

std::string toString(TrackingState s) {
    switch (s) {
        case TrackingState::NotInitialized:
            return "not_initialized";
        case TrackingState::Ok:
            return "ok";
        case TrackingState::Relocalized:
            return "relocalized";
        case TrackingState::Lost:
            return "lost";
    }
    return "?";
}

void TrackerOptions::loadFromConfig(const mrpt::config::CConfigFileBase& c, const std::string& s) {
    core::requireKnownKeys(c, s,
                           {"search_radius",
                            "fine_radius",
                            "wide_radius_factor",
                            "max_hamming",
                            "match_ratio",
                            "max_depth",
                            "pnp_iterations",
                            "pnp_reprojection_px",
                            "pnp_confidence",
                            "bf",
                            "refine_rounds",
                            "refine_iterations",
                            "min_matches",
                            "min_inliers",
                            "local_keyframes",
                            "max_motion_dt",
                            "near_keyframes",
                            "near_max_angle_deg",
                            "localize_keyframes",
                            "reloc_keyframes",
                            "reloc_min_inliers",
                            "reloc_max_hamming",
                            "reloc_ratio",
                            "reloc_max_jump",
                            "reloc_max_speed",
                            "reloc_max_jump_deg",
                            "reloc_max_rate_deg",
                            "place_recognition",
                            "localize_max_see_through"});
    projection.radius = core::readDouble(c, s, "search_radius", projection.radius);
    fine_radius = core::readDouble(c, s, "fine_radius", fine_radius);
    wide_radius_factor = core::readDouble(c, s, "wide_radius_factor", wide_radius_factor);
    projection.max_hamming = core::readInt(c, s, "max_hamming", projection.max_hamming);
    projection.ratio = core::readDouble(c, s, "match_ratio", projection.ratio);
    projection.max_depth = core::readDouble(c, s, "max_depth", projection.max_depth);
    pnp.iterations = core::readInt(c, s, "pnp_iterations", pnp.iterations);
    pnp.reprojection_px = core::readDouble(c, s, "pnp_reprojection_px", pnp.reprojection_px);
    pnp.confidence = core::readDouble(c, s, "pnp_confidence", pnp.confidence);
    refine.bf = core::readDouble(c, s, "bf", refine.bf);
    refine.rounds = core::readInt(c, s, "refine_rounds", refine.rounds);
    refine.iterations = core::readInt(c, s, "refine_iterations", refine.iterations);
    min_matches = core::readInt(c, s, "min_matches", min_matches);
    min_inliers = core::readInt(c, s, "min_inliers", min_inliers);
    local_keyframes = core::readInt(c, s, "local_keyframes", local_keyframes);
    near_keyframes = core::readInt(c, s, "near_keyframes", near_keyframes);
    near_max_angle_deg = core::readDouble(c, s, "near_max_angle_deg", near_max_angle_deg);
    localize_keyframes = core::readInt(c, s, "localize_keyframes", localize_keyframes);
    max_motion_dt = core::readDouble(c, s, "max_motion_dt", max_motion_dt);
    reloc_keyframes = core::readInt(c, s, "reloc_keyframes", reloc_keyframes);
    place_recognition = core::readBool(c, s, "place_recognition", place_recognition);
    localize_max_see_through =
        core::readDouble(c, s, "localize_max_see_through", localize_max_see_through);
    reloc_min_inliers = core::readInt(c, s, "reloc_min_inliers", reloc_min_inliers);
    reloc_max_hamming = core::readInt(c, s, "reloc_max_hamming", reloc_max_hamming);
    reloc_ratio = core::readDouble(c, s, "reloc_ratio", reloc_ratio);
    reloc_max_jump = core::readDouble(c, s, "reloc_max_jump", reloc_max_jump);
    reloc_max_speed = core::readDouble(c, s, "reloc_max_speed", reloc_max_speed);
    reloc_max_jump_deg = core::readDouble(c, s, "reloc_max_jump_deg", reloc_max_jump_deg);
    reloc_max_rate_deg = core::readDouble(c, s, "reloc_max_rate_deg", reloc_max_rate_deg);
    // Bounded: the matcher's grid cells are ints, and 1e11 px cast to none (undefined; on
    // x86 no cell at all, and every frame lost).
    core::requireValue(projection.radius > 0 && projection.radius <= 2000, s, "search_radius",
                       "must be in (0, 2000] [px]");
    core::requireValue(fine_radius > 0 && fine_radius <= 2000, s, "fine_radius",
                       "must be in (0, 2000] [px]");
    core::requireValue(wide_radius_factor >= 1 && projection.radius * wide_radius_factor <= 2000, s,
                       "wide_radius_factor",
                       "must be >= 1, and search_radius x wide_radius_factor at most 2000 [px]");
    core::requireValue(projection.max_hamming > 0 && projection.max_hamming <= 256, s,
                       "max_hamming", "must be in (0, 256]");
    core::requireValue(projection.ratio > 0 && projection.ratio <= 1, s, "match_ratio",
                       "must be in (0, 1]");
    core::requireValue(projection.max_depth > 0, s, "max_depth", "must be > 0 [m]");
    core::requireValue(pnp.iterations > 0 && pnp.iterations <= 100000, s, "pnp_iterations",
                       "must be in [1, 100000]");
    core::requireValue(pnp.reprojection_px > 0, s, "pnp_reprojection_px", "must be > 0");
    core::requireValue(pnp.confidence > 0 && pnp.confidence < 1, s, "pnp_confidence",
                       "must be in (0, 1)");
    core::requireValue(refine.bf > 0, s, "bf", "must be > 0");
    // Per frame: a billion rounds ran forever, deaf to Ctrl-C between frames.
    core::requireValue(refine.rounds >= 1 && refine.rounds <= 10, s, "refine_rounds",
                       "must be in [1, 10]");
    core::requireValue(refine.iterations >= 1 && refine.iterations <= 1000, s, "refine_iterations",
                       "must be in [1, 1000]");
    core::requireValue(min_matches >= 6, s, "min_matches", "must be >= 6");
    core::requireValue(min_inliers >= 6, s, "min_inliers", "must be >= 6");
    core::requireValue(local_keyframes >= 1 && local_keyframes <= 1000, s, "local_keyframes",
                       "must be in [1, 1000]");
    core::requireValue(near_keyframes >= 0 && near_keyframes <= 1000, s, "near_keyframes",
                       "must be in [0, 1000]");
    core::requireValue(near_max_angle_deg > 0 && near_max_angle_deg <= 180, s, "near_max_angle_deg",
                       "must be in (0, 180] [deg]");
    core::requireValue(localize_keyframes >= 1 && localize_keyframes <= 1000, s,
                       "localize_keyframes", "must be in [1, 1000]");
    core::requireValue(max_motion_dt >= 0, s, "max_motion_dt",
                       "must be >= 0 [s] (0: no motion model)");
    core::requireValue(reloc_keyframes >= 1 && reloc_keyframes <= 1000, s, "reloc_keyframes",
                       "must be in [1, 1000]");
    core::requireValue(reloc_min_inliers >= 6, s, "reloc_min_inliers", "must be >= 6");
    core::requireValue(reloc_max_hamming > 0 && reloc_max_hamming <= 256, s, "reloc_max_hamming",
                       "must be in (0, 256]");
    core::requireValue(reloc_ratio > 0 && reloc_ratio <= 1, s, "reloc_ratio", "must be in (0, 1]");
    core::requireValue(localize_max_see_through >= 0 && localize_max_see_through <= 1, s,
                       "localize_max_see_through", "must be in [0, 1] (1: no test)");
    core::requireValue(reloc_max_jump >= 0, s, "reloc_max_jump", "must be >= 0 [m]");
    core::requireValue(reloc_max_speed >= 0, s, "reloc_max_speed", "must be >= 0 [m/s]");
    core::requireValue(reloc_max_jump_deg >= 0, s, "reloc_max_jump_deg", "must be >= 0");
    core::requireValue(reloc_max_rate_deg >= 0, s, "reloc_max_rate_deg", "must be >= 0");
}

void TrackerOptions::saveToConfig(mrpt::config::CConfigFileBase& c, const std::string& s) const {
    core::writeKey(c, s, "search_radius", projection.radius);
    core::writeKey(c, s, "fine_radius", fine_radius);
    core::writeKey(c, s, "wide_radius_factor", wide_radius_factor);
    core::writeKey(c, s, "max_hamming", projection.max_hamming);
    core::writeKey(c, s, "match_ratio", projection.ratio);
    core::writeKey(c, s, "max_depth", projection.max_depth);
    core::writeKey(c, s, "pnp_iterations", pnp.iterations);
    core::writeKey(c, s, "pnp_reprojection_px", pnp.reprojection_px);
    core::writeKey(c, s, "pnp_confidence", pnp.confidence);
    core::writeKey(c, s, "bf", refine.bf);
    core::writeKey(c, s, "refine_rounds", refine.rounds);
    core::writeKey(c, s, "refine_iterations", refine.iterations);
    core::writeKey(c, s, "min_matches", min_matches);
    core::writeKey(c, s, "min_inliers", min_inliers);
    core::writeKey(c, s, "local_keyframes", local_keyframes);
    core::writeKey(c, s, "near_keyframes", near_keyframes);
    core::writeKey(c, s, "localize_keyframes", localize_keyframes);
    core::writeKey(c, s, "near_max_angle_deg", near_max_angle_deg);
    core::writeKey(c, s, "max_motion_dt", max_motion_dt);
    core::writeKey(c, s, "reloc_keyframes", reloc_keyframes);
    core::writeKey(c, s, "place_recognition", place_recognition);
    core::writeKey(c, s, "localize_max_see_through", localize_max_see_through);
    core::writeKey(c, s, "reloc_min_inliers", reloc_min_inliers);
    core::writeKey(c, s, "reloc_max_hamming", reloc_max_hamming);
    core::writeKey(c, s, "reloc_ratio", reloc_ratio);
    core::writeKey(c, s, "reloc_max_jump", reloc_max_jump);
    core::writeKey(c, s, "reloc_max_speed", reloc_max_speed);
    core::writeKey(c, s, "reloc_max_jump_deg", reloc_max_jump_deg);
    core::writeKey(c, s, "reloc_max_rate_deg", reloc_max_rate_deg);
}

void Tracker::startLocalizing(const Map& map) {
    place_.reset();
    if (opts_.place_recognition)
        place_ = std::make_shared<const PlaceIndex>(map, PlaceIndexOptions{});
    state_ = TrackingState::Lost;
    localizing_ = true;
    loaded_map_ = true;
    localized_ = false;
    unanchored_ = false;
    has_velocity_ = false;
    last_T_wc_ = Eigen::Isometry3d::Identity();
    last_t_ = 0.0;
}

void Tracker::initialize(const Eigen::Isometry3d& T_wc, double timestamp) {
    state_ = TrackingState::Ok;
    last_T_wc_ = T_wc;
    last_t_ = timestamp;
    has_velocity_ = false;
    velocity_ = Eigen::Isometry3d::Identity();
}

std::optional<Eigen::Isometry3d> Tracker::predictPrevCur(double timestamp) const {
    return predictMotion(timestamp - last_t_);
}

std::optional<Eigen::Isometry3d> Tracker::predictMotion(double dt) const {
    if (state_ == TrackingState::NotInitialized || state_ == TrackingState::Lost)
        return std::nullopt;
    if (!has_velocity_ || dt <= 0 || dt > opts_.max_motion_dt || velocity_dt_ <= 0)
        return Eigen::Isometry3d::Identity();
    // Scale the last inter-frame motion to this frame's interval.
    const double s = dt / velocity_dt_;
    const Eigen::AngleAxisd aa(velocity_.linear());
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = Eigen::AngleAxisd(aa.angle() * s, aa.axis()).toRotationMatrix();
    T.translation() = velocity_.translation() * s;
    return T;
}

void Tracker::applyCorrection(const Eigen::Isometry3d& T_new_old) {
    last_T_wc_ = T_new_old * last_T_wc_;
}

namespace {
std::vector<PoseObservation> observationsOf(const Map& map, const FrameFeatures& f,
                                            const std::vector<Match>& matches,
                                            double scale_factor) {
    std::vector<PoseObservation> obs;
    obs.reserve(matches.size());
    for (const auto& m : matches)
        obs.push_back(observationOf(f, m.kp, map.landmark(m.landmark)->p_w, scale_factor));
    return obs;
}
}  // namespace

std::optional<PoseRefineResult> Tracker::trackWithMap(const FrameFeatures& f, const Map& map,
                                                      const core::CameraIntrinsics& K,
                                                      const Eigen::Isometry3d& pred,
                                                      const std::vector<LandmarkId>& local,
                                                      TrackResult& res,
                                                      std::vector<LandmarkId>& in_view) const {
    const KeypointGrid grid(f.keypoints, cv::Size(K.width, K.height));
    auto matches = matchByProjection(map, local, f, grid, pred, K, opts_.projection);
    if (static_cast<int>(matches.size()) < opts_.min_matches) {
        auto wide = opts_.projection;
        wide.radius *= opts_.wide_radius_factor;
        matches = matchByProjection(map, local, f, grid, pred, K, wide);
    }
    if (static_cast<int>(matches.size()) < opts_.min_matches) {
        res.reason = "too few projection matches (" + std::to_string(matches.size()) + ")";
        return std::nullopt;
    }
    auto obs = observationsOf(map, f, matches, opts_.scale_factor);
    const auto pnp = solvePnpRansac(obs, K, opts_.pnp, pred);
    Eigen::Isometry3d T0 = pred;
    if (pnp) T0 = pnp->T_wc;
    auto refined = refinePose(obs, T0, K, opts_.refine);
    if (refined.n_inliers < opts_.min_inliers) {
        res.reason = "too few inliers after refinement (" + std::to_string(refined.n_inliers) + ")";
        return std::nullopt;
    }
    // Second pass: every local landmark again around the refined pose, tighter window.
    auto fine = opts_.projection;
    fine.radius = opts_.fine_radius;
    in_view.clear();
    matches =
        matchByProjection(map, local, f, grid, refined.T_wc, K, fine, &res.n_in_view, &in_view);
    obs = observationsOf(map, f, matches, opts_.scale_factor);
    auto refined2 = refinePose(obs, refined.T_wc, K, opts_.refine);
    if (refined2.n_inliers < opts_.min_inliers) {
        res.reason =
            "too few inliers in the fine pass (" + std::to_string(refined2.n_inliers) + ")";
        return std::nullopt;
    }
    res.n_matches = static_cast<int>(matches.size());
    res.landmark_of_kp.assign(f.size(), kNoId);
    for (std::size_t i = 0; i < matches.size(); ++i)
        if (refined2.inlier[i]) res.landmark_of_kp[matches[i].kp] = matches[i].landmark;
    return refined2;
}

bool Tracker::relocPlausible(const Eigen::Isometry3d& T_wc, double timestamp) const {
    // No pose to be near before the first one in a loaded map.
    if (opts_.reloc_max_speed <= 0 || (localizing_ && (!localized_ || unanchored_))) return true;
    const double lost_s = std::max(0.0, timestamp - last_t_);
    const Eigen::Isometry3d d = last_T_wc_.inverse() * T_wc;
    const double deg = Eigen::AngleAxisd(d.linear()).angle() * 180.0 / M_PI;
    return d.translation().norm() <= opts_.reloc_max_jump + opts_.reloc_max_speed * lost_s &&
           deg <= opts_.reloc_max_jump_deg + opts_.reloc_max_rate_deg * lost_s;
}

namespace {
/// Appends to `kfs` up to `n` keyframes with ids below `before` (all when kNoId) nearest
/// `T_wc` by camera centre (ties by id) among those whose optical axis has a cosine of at
/// least `min_cos` with its own.
void addNearest(const Map& map, const Eigen::Isometry3d& T_wc, std::size_t n, double min_cos,
                KeyframeId before, std::vector<KeyframeId>& kfs) {
    if (n == 0) return;
    const Eigen::Vector3d axis = T_wc.linear().col(2);
    std::vector<std::pair<double, KeyframeId>> near;
    for (const auto& [id, kf] : map.keyframes()) {
        if (before != kNoId && id >= before) break;  // kept in id order
        if (kf.T_wc.linear().col(2).dot(axis) < min_cos) continue;
        near.emplace_back((kf.T_wc.translation() - T_wc.translation()).norm(), id);
    }
    n = std::min(n, near.size());
    std::partial_sort(near.begin(), near.begin() + static_cast<std::ptrdiff_t>(n), near.end());
    for (std::size_t i = 0; i < n; ++i) kfs.push_back(near[i].second);
}

/// Appends to `kfs`, the map's newest keyframes (Map::lastKeyframes), up to `n` of the older
/// ones nearest `T_wc` (see addNearest).
void addNearestOlder(const Map& map, const Eigen::Isometry3d& T_wc, std::size_t n, double min_cos,
                     std::vector<KeyframeId>& kfs) {
    if (kfs.empty()) return;
    addNearest(map, T_wc, n, min_cos, kfs.front(), kfs);
}
}  // namespace

FreeSpaceResult freeSpaceTest(const Map& map, const std::vector<LandmarkId>& landmarks,
                              const Eigen::Isometry3d& T_wc, const cv::Mat& depth,
                              const core::CameraIntrinsics& K, double depth_factor, int window_px,
                              double margin_m, double margin_rel) {
    FreeSpaceResult r;
    // (a depth image of another size than the camera's is no depth, as for OrbExtractor)
    if (depth.empty() || depth.type() != CV_32FC1 || depth.cols != K.width ||
        depth.rows != K.height)
        return r;
    const Eigen::Isometry3d T_cw = T_wc.inverse();
    std::vector<cv::Point3f> pc;
    for (const LandmarkId id : landmarks)
        if (const Landmark* lm = map.landmark(id)) {
            const Eigen::Vector3d p = T_cw * lm->p_w;
            if (p.z() <= 0.1) continue;
            // In the image by the pinhole (10 % beside it allowed): a point far off the axis
            // would fold back into it through a barrel distortion's polynomial.
            const double u = K.fx * p.x() / p.z() + K.cx, v = K.fy * p.y() / p.z() + K.cy;
            if (u > -0.1 * K.width && u < 1.1 * K.width && v > -0.1 * K.height &&
                v < 1.1 * K.height)
                pc.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()),
                                static_cast<float>(p.z()));
        }
    if (pc.empty()) return r;
    // The depth image is the camera's own (distorted) pixels: projected with its distortion.
    std::vector<cv::Point2f> px;
    cv::projectPoints(pc, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), K.cvMatrix(), K.dist, px);
    for (std::size_t i = 0; i < pc.size(); ++i) {
        const int u = static_cast<int>(std::lround(px[i].x)),
                  v = static_cast<int>(std::lround(px[i].y));
        if (u < 0 || v < 0 || u >= depth.cols || v >= depth.rows) continue;
        // The nearest depth around the pixel: a landmark on an edge is not seen through because
        // its pixel, a little off, measures the background.
        float nearest = 0;
        for (int y = std::max(0, v - window_px); y <= std::min(depth.rows - 1, v + window_px);
             ++y) {
            const float* row = depth.ptr<float>(y);
            for (int x = std::max(0, u - window_px); x <= std::min(depth.cols - 1, u + window_px);
                 ++x)
                if (row[x] > 0 && (nearest == 0 || row[x] < nearest)) nearest = row[x];
        }
        if (nearest == 0) continue;
        nearest = static_cast<float>(nearest * depth_factor);  // the landmarks' scale
        ++r.checked;
        const double z = pc[i].z;
        if (nearest > z + margin_m + margin_rel * z) ++r.seen_through;
    }
    return r;
}

std::optional<Eigen::Isometry3d> Tracker::relocalize(const FrameFeatures& f, const Map& map,
                                                     const core::CameraIntrinsics& K,
                                                     double timestamp, const cv::Mat* depth,
                                                     double depth_factor) const {
    // Candidates: the newest keyframes and the ones nearest to the last pose, facing anywhere.
    // In a loaded map (localizing) its newest keyframes say nothing of where the camera is,
    // nor, while lost, does the last pose: the place index's most alike keyframes are
    // verified by PnP (or, without it, every keyframe is matched and the reloc_keyframes with
    // the most matches verified).
    std::vector<KeyframeId> cands;
    if (localizing_) {
        for (const auto& [id, kf] : map.keyframes()) cands.push_back(id);
    } else {
        cands = map.lastKeyframes(opts_.reloc_keyframes / 2 + 1);
        addNearestOlder(map, last_T_wc_,
                        static_cast<std::size_t>(opts_.reloc_keyframes) - cands.size(),
                        -std::numeric_limits<double>::infinity(), cands);
    }
    struct Candidate {
        const Keyframe* kf = nullptr;
        std::vector<int> rows;                   ///< its keypoints with a landmark
        std::vector<std::pair<int, int>> pairs;  ///< (frame keypoint, row)
    };
    const auto matchesOf = [&](KeyframeId id, const cv::Mat& query) {
        Candidate c;
        c.kf = &map.keyframe(id);
        for (int i = 0; i < static_cast<int>(c.kf->landmark_of_kp.size()); ++i)
            if (c.kf->landmark_of_kp[i] != kNoId) c.rows.push_back(i);
        if (static_cast<int>(c.rows.size()) < opts_.reloc_min_inliers) return c;
        cv::Mat train(static_cast<int>(c.rows.size()), 32, CV_8U);
        for (std::size_t r = 0; r < c.rows.size(); ++r)
            c.kf->features.descriptors.row(c.rows[r]).copyTo(train.row(static_cast<int>(r)));
        for (const auto& [q, t] :
             matchBruteForce(query, train, opts_.reloc_max_hamming, opts_.reloc_ratio))
            c.pairs.emplace_back(q, t);
        return c;
    };
    std::optional<Eigen::Isometry3d> best;
    int best_inliers = 0;
    const auto verify = [&](const Candidate& c) {
        if (static_cast<int>(c.pairs.size()) < opts_.reloc_min_inliers) return;
        std::vector<PoseObservation> obs;
        for (const auto& [q, t] : c.pairs)
            obs.push_back(observationOf(f, q, map.landmark(c.kf->landmark_of_kp[c.rows[t]])->p_w,
                                        opts_.scale_factor));
        // No pose could have reloc_min_inliers of these: the RANSAC would run all its
        // iterations to fail (a frame that is nowhere in the map).
        if (!inlierBoundReaches(obs, opts_.reloc_min_inliers, K, opts_.refine)) return;
        auto pnp_opts = opts_.pnp;
        pnp_opts.iterations = std::max(pnp_opts.iterations, 300);
        pnp_opts.min_inliers = opts_.reloc_min_inliers;
        const auto pnp = solvePnpRansac(obs, K, pnp_opts);
        if (!pnp) return;
        const auto refined = refinePose(obs, pnp->T_wc, K, opts_.refine);
        if (refined.n_inliers < opts_.reloc_min_inliers || refined.n_inliers <= best_inliers ||
            !relocPlausible(refined.T_wc, timestamp))
            return;
        // In a loaded map, a pose found on pictures that are elsewhere in the map too sees
        // through the map's landmarks around it.
        if (testsFreeSpace(depth) &&
            seenThrough(freeSpaceTest(map, localMap(map, refined.T_wc), refined.T_wc, *depth, K,
                                      depth_factor)))
            return;
        best_inliers = refined.n_inliers;
        best = refined.T_wc;
    };
    // A map of reloc_keyframes keyframes or fewer, localizing with the place index: all of
    // them.
    const auto n_cands = static_cast<std::size_t>(opts_.reloc_keyframes);
    if (!localizing_ || (place_ && cands.size() <= n_cands)) {
        for (KeyframeId id : cands) verify(matchesOf(id, f.descriptors));
        return best;
    }
    // The candidates are the keyframes whose words are most like the frame's; without the
    // place index, the keyframes are ranked by the matches of the frame's strongest quarter
    // of keypoints (200 at least), which costs a quarter of matching them all. The best are
    // then matched with every keypoint and verified.
    // The index finds fewer than reloc_keyframes where most words are in every keyframe (a
    // map of one keyframe has no word that tells keyframes apart): ranked by matches instead.
    if (place_) {
        if (const auto found = place_->query(f.descriptors, n_cands); found.size() == n_cands) {
            for (const auto& [score, id] : found)
                if (map.keyframes().count(id)) verify(matchesOf(id, f.descriptors));
            return best;
        }
    }
    const int n_rank =
        std::min(static_cast<int>(f.size()), std::max(200, static_cast<int>(f.size()) / 4));
    std::vector<int> order(f.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
    std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
        return f.keypoints[static_cast<std::size_t>(a)].response >
               f.keypoints[static_cast<std::size_t>(b)].response;
    });
    cv::Mat strongest(n_rank, 32, CV_8U);
    for (int r = 0; r < n_rank; ++r) f.descriptors.row(order[r]).copyTo(strongest.row(r));
    std::vector<std::pair<std::size_t, KeyframeId>> ranked;  // (matches, keyframe)
    for (KeyframeId id : cands)
        if (const std::size_t n = matchesOf(id, strongest).pairs.size(); n > 0)
            ranked.emplace_back(n, id);
    std::stable_sort(ranked.begin(), ranked.end(),
                     [](const auto& a, const auto& b) { return a.first > b.first; });
    if (ranked.size() > static_cast<std::size_t>(opts_.reloc_keyframes))
        ranked.resize(static_cast<std::size_t>(opts_.reloc_keyframes));
    for (const auto& [n, id] : ranked) verify(matchesOf(id, f.descriptors));
    return best;
}

std::vector<LandmarkId> Tracker::localMap(const Map& map, const Eigen::Isometry3d& T_wc) const {
    const double min_cos = std::cos(opts_.near_max_angle_deg * M_PI / 180.0);
    std::vector<KeyframeId> kfs;
    if (localizing_) {
        // A loaded map: the localize_keyframes nearest that face the camera's way stand for
        // the newest; fewer than local_keyframes of them (a relocalized pose whose keyframes
        // all face away found no local map) are topped up with the nearest facing anywhere.
        // (local_keyframes nearest facing anywhere, with near_keyframes facing its way:
        // walking_xyz in walking_halfsphere's map 5.0 mm of ATE, against 4.5 with 15 facing.)
        addNearest(map, T_wc, static_cast<std::size_t>(opts_.localize_keyframes), min_cos, kNoId,
                   kfs);
        if (kfs.size() < static_cast<std::size_t>(opts_.local_keyframes))
            addNearest(map, T_wc, static_cast<std::size_t>(opts_.local_keyframes) - kfs.size(),
                       -std::numeric_limits<double>::infinity(), kNoId, kfs);
        return map.landmarksOf(kfs);
    }
    kfs = map.lastKeyframes(static_cast<std::size_t>(opts_.local_keyframes));
    // Extending a loaded map, the older keyframes near the camera are the map's, not the
    // run's own: at least local_keyframes of them (the TUM INIs' near_keyframes = 0 left them
    // out, and new landmarks doubled theirs).
    const int near =
        loaded_map_ ? std::max(opts_.near_keyframes, opts_.local_keyframes) : opts_.near_keyframes;
    addNearestOlder(map, T_wc, static_cast<std::size_t>(near), min_cos, kfs);
    return map.landmarksOf(kfs);
}

TrackResult Tracker::track(const TrackInput& in, Map& map, const core::CameraIntrinsics& K) {
    TrackResult res;
    const FrameFeatures& f = *in.features;
    res.landmark_of_kp.assign(f.size(), kNoId);
    if (state_ == TrackingState::NotInitialized) {
        res.state = state_;
        res.reason = "not initialized";
        return res;
    }
    // While lost, the last tracked pose is frames old and a one-frame prior says nothing
    // of how far the camera went since: the frame keeps that pose, as without a prior.
    const auto prev_cur = in.T_prev_cur_prior && state_ != TrackingState::Lost
                              ? in.T_prev_cur_prior
                              : predictPrevCur(in.timestamp);
    const Eigen::Isometry3d pred = last_T_wc_ * prev_cur.value_or(Eigen::Isometry3d::Identity());
    res.T_wc = pred;
    const auto local = localMap(map, pred);

    std::optional<PoseRefineResult> ok;
    const std::vector<LandmarkId>* used_local = &local;  // the local map the pose was found in
    const bool was_lost = state_ == TrackingState::Lost;
    std::vector<LandmarkId> in_view, reloc_local;
    if (!was_lost && f.size() > 0) ok = trackWithMap(f, map, K, pred, local, res, in_view);
    if (!ok && f.size() > 0) {
        // Relocalize against keyframes, then track the local map from that pose.
        TrackResult reloc_res;
        if (const auto T = relocalize(f, map, K, in.timestamp, in.depth, in.depth_factor)) {
            auto near = localMap(map, *T);
            std::vector<LandmarkId> reloc_in_view;
            ok = trackWithMap(f, map, K, *T, near, reloc_res, reloc_in_view);
            // The local map may pull the pose away again (its newest keyframes can be the
            // bad poses that lost the track): the bound holds for the final pose too.
            if (ok && !relocPlausible(ok->T_wc, in.timestamp)) ok.reset();
            if (ok) {
                const std::string why = res.reason;
                res = reloc_res;
                res.reason = was_lost ? "" : "relocalized after: " + why;
                in_view = std::move(reloc_in_view);
                reloc_local = std::move(near);
                used_local = &reloc_local;
            }
        }
        if (!ok && res.reason.empty()) res.reason = "relocalization failed";
    }
    // In a loaded map, a pose tracked on from a wrong relocalization keeps finding the
    // pictures it was found on, but the depth sees through the map around it (walking_xyz
    // seed 15 in seed 14's map: 0.02-0.45 of the landmarks against at most 0.012 on the true
    // track): lost, and relocalized (or not) from the next frame.
    if (ok && testsFreeSpace(in.depth)) {
        const auto fs = freeSpaceTest(map, *used_local, ok->T_wc, *in.depth, K, in.depth_factor);
        if (seenThrough(fs)) {
            unanchored_ = true;
            ok.reset();
            res = TrackResult{};
            res.reason = "the depth sees through " + std::to_string(fs.seen_through) + " of " +
                         std::to_string(fs.checked) + " map landmarks at the pose found";
        }
    }
    if (f.size() == 0) res.reason = "no features";
    if (!ok) {
        state_ = TrackingState::Lost;
        has_velocity_ = false;
        res.state = state_;
        res.T_wc = pred;
        res.pose_valid = false;
        res.landmark_of_kp.assign(f.size(), kNoId);
        // Keep last_T_wc_: the next frame predicts from the last good pose.
        return res;
    }
    // The culling counters, for the pose kept only: a relocalization the jump bound refused
    // (a false match on repeated texture, say) counts no landmark as seen or found.
    for (LandmarkId id : in_view) ++map.landmark(id)->n_visible;
    for (LandmarkId id : res.landmark_of_kp)
        if (id != kNoId) ++map.landmark(id)->n_found;
    const double dt = in.timestamp - last_t_;
    velocity_ = last_T_wc_.inverse() * ok->T_wc;
    velocity_dt_ = dt;
    has_velocity_ = !was_lost && dt > 0 && dt <= opts_.max_motion_dt;
    last_T_wc_ = ok->T_wc;
    last_t_ = in.timestamp;
    localized_ = true;
    unanchored_ = false;
    state_ = (was_lost || !res.reason.empty()) ? TrackingState::Relocalized : TrackingState::Ok;
    res.state = state_;
    if (state_ == TrackingState::Relocalized) state_ = TrackingState::Ok;
    res.T_wc = ok->T_wc;
    res.pose_valid = true;
    res.n_inliers = ok->n_inliers;
    res.rms_px = ok->rms_px;
    return res;
}

}  // namespace devslam::slam
