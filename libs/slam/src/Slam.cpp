#include <devslam/core/Config.h>
#include <devslam/core/Pose.h>
#include <devslam/slam/Slam.h>

#include <mrpt/config/CConfigFileBase.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iterator>
#include <stdexcept>
#include <utility>

namespace devslam::slam {

void MappingOptions::loadFromConfig(const mrpt::config::CConfigFileBase& c, const std::string& s) {
    core::requireKnownKeys(
        c, s,
        {"min_init_points", "cull_min_found_ratio", "cull_min_visible", "cull_keyframe_age",
         "cull_ratio_keyframes", "redundant_keyframe_ratio", "redundant_keyframe_observers",
         "odometry_sigma_t", "odometry_sigma_r_deg", "depth_time_compensation", "refine_frames"});
    depth_time_compensation =
        core::readBool(c, s, "depth_time_compensation", depth_time_compensation);
    refine_frames = core::readBool(c, s, "refine_frames", refine_frames);
    min_init_points = core::readInt(c, s, "min_init_points", min_init_points);
    cull_min_found_ratio = core::readDouble(c, s, "cull_min_found_ratio", cull_min_found_ratio);
    cull_min_visible = core::readInt(c, s, "cull_min_visible", cull_min_visible);
    cull_keyframe_age = core::readInt(c, s, "cull_keyframe_age", cull_keyframe_age);
    cull_ratio_keyframes = core::readInt(c, s, "cull_ratio_keyframes", cull_ratio_keyframes);
    redundant_keyframe_ratio =
        core::readDouble(c, s, "redundant_keyframe_ratio", redundant_keyframe_ratio);
    redundant_keyframe_observers =
        core::readInt(c, s, "redundant_keyframe_observers", redundant_keyframe_observers);
    odometry_sigma_t = core::readDouble(c, s, "odometry_sigma_t", odometry_sigma_t);
    odometry_sigma_r_deg = core::readDouble(c, s, "odometry_sigma_r_deg", odometry_sigma_r_deg);
    core::requireValue(min_init_points >= 10, s, "min_init_points", "must be >= 10");
    core::requireValue(cull_min_found_ratio >= 0 && cull_min_found_ratio < 1, s,
                       "cull_min_found_ratio", "must be in [0, 1)");
    core::requireValue(cull_min_visible >= 0, s, "cull_min_visible", "must be >= 0");
    core::requireValue(cull_keyframe_age >= 1, s, "cull_keyframe_age",
                       "must be >= 1 (0 culled every new landmark at once)");
    core::requireValue(cull_ratio_keyframes >= 0, s, "cull_ratio_keyframes",
                       "must be >= 0 (0: at any age)");
    core::requireValue(redundant_keyframe_ratio >= 0 && redundant_keyframe_ratio <= 1, s,
                       "redundant_keyframe_ratio", "must be in [0, 1] (0: no keyframe culling)");
    core::requireValue(redundant_keyframe_observers >= 1, s, "redundant_keyframe_observers",
                       "must be >= 1");
    // The pose graph's information is 1 / sigma^2: 1e-200 made it inf, 1e200 zero.
    core::requireValue(odometry_sigma_t >= 1e-6 && odometry_sigma_t <= 1e3, s, "odometry_sigma_t",
                       "must be in [1e-6, 1e3] [m]");
    core::requireValue(odometry_sigma_r_deg >= 1e-6 && odometry_sigma_r_deg <= 1e3, s,
                       "odometry_sigma_r_deg", "must be in [1e-6, 1e3] [deg]");
}

void MappingOptions::saveToConfig(mrpt::config::CConfigFileBase& c, const std::string& s) const {
    core::writeKey(c, s, "min_init_points", min_init_points);
    core::writeKey(c, s, "cull_min_found_ratio", cull_min_found_ratio);
    core::writeKey(c, s, "cull_min_visible", cull_min_visible);
    core::writeKey(c, s, "cull_keyframe_age", cull_keyframe_age);
    core::writeKey(c, s, "cull_ratio_keyframes", cull_ratio_keyframes);
    core::writeKey(c, s, "redundant_keyframe_ratio", redundant_keyframe_ratio);
    core::writeKey(c, s, "redundant_keyframe_observers", redundant_keyframe_observers);
    core::writeKey(c, s, "odometry_sigma_t", odometry_sigma_t);
    core::writeKey(c, s, "odometry_sigma_r_deg", odometry_sigma_r_deg);
    core::writeKey(c, s, "depth_time_compensation", depth_time_compensation);
    core::writeKey(c, s, "refine_frames", refine_frames);
}

std::optional<double> depthStamp(const core::Frame& frame) {
    return frame.depth_timestamp;
}

void compensateDepthTime(FrameFeatures& f, const Eigen::Isometry3d& T_prev_cur, double dt_prev,
                         double t_rgb, double t_depth) {
    if (dt_prev <= 0) return;
    // Fraction of the last interval between the depth and the colour exposure (negative:
    // depth earlier); pose of the depth camera in the colour camera = (T_prev_cur)^a.
    const double a = (t_depth - t_rgb) / dt_prev;
    const Eigen::AngleAxisd aa(T_prev_cur.linear());
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = Eigen::AngleAxisd(aa.angle() * a, aa.axis()).toRotationMatrix();
    T.translation() = T_prev_cur.translation() * a;
    for (std::size_t i = 0; i < f.size(); ++i) {
        if (f.depth[i] <= 0) continue;
        const double z = (T * f.points_c[i]).z();  // the new depth; the ray stays
        if (!(z > 0)) continue;
        f.points_c[i] *= z / f.points_c[i].z();
        f.depth[i] = static_cast<float>(z);
    }
}

const std::vector<std::string>& SlamOptions::sections() {
    static const std::vector<std::string> k{"orb",      "tracker",      "keyframes", "mapping",
                                            "local_ba", "loop_closure", "pose_graph"};
    return k;
}

SlamOptions SlamOptions::fromConfig(const mrpt::config::CConfigFileBase& cfg) {
    SlamOptions o;
    o.orb.loadFromConfig(cfg, "orb");
    o.tracker.loadFromConfig(cfg, "tracker");
    o.keyframes.loadFromConfig(cfg, "keyframes");
    o.mapping.loadFromConfig(cfg, "mapping");
    o.local_ba.loadFromConfig(cfg, "local_ba");
    o.loop.loadFromConfig(cfg, "loop_closure");
    core::requireKnownKeys(cfg, "pose_graph", {"max_iterations"});
    o.pose_graph.max_iterations = core::readInt(cfg, "pose_graph", "max_iterations", 100);
    core::requireValue(o.pose_graph.max_iterations > 0 && o.pose_graph.max_iterations <= 10000,
                       "pose_graph", "max_iterations", "must be in [1, 10000]");
    // More than a frame can track meant no keyframe after the first: the map stopped growing
    // and the track was lost once the camera left its view.
    core::requireValue(
        o.keyframes.min_tracked >= 0 && o.keyframes.min_tracked <= o.orb.n_features, "keyframes",
        "min_tracked",
        "must be in [0, [orb] n_features] (" + std::to_string(o.orb.n_features) + ")");
    // The level sigmas of tracking and BA follow the ORB pyramid.
    o.local_ba.scale_factor = o.orb.scale_factor;
    o.tracker.scale_factor = o.orb.scale_factor;
    o.loop.scale_factor = o.orb.scale_factor;
    return o;
}

void SlamOptions::saveToConfig(mrpt::config::CConfigFileBase& cfg) const {
    orb.saveToConfig(cfg, "orb");
    tracker.saveToConfig(cfg, "tracker");
    keyframes.saveToConfig(cfg, "keyframes");
    mapping.saveToConfig(cfg, "mapping");
    local_ba.saveToConfig(cfg, "local_ba");
    loop.saveToConfig(cfg, "loop_closure");
    core::writeKey(cfg, "pose_graph", "max_iterations", pose_graph.max_iterations);
}

Slam::Slam(const SlamOptions& opts) : opts_(opts), orb_(opts.orb), tracker_(opts.tracker) {}

FrameFeatures Slam::extract(const core::Frame& frame, const cv::Mat& mask) const {
    FrameFeatures f = orb_.extract(frame, mask);
    if (opts_.mapping.depth_time_compensation) {
        const auto td = depthStamp(frame);
        const auto v = tracker_.predictPrevCur(frame.timestamp);
        const double dt = frame.timestamp - tracker_.lastTimestamp();
        if (td && v && std::abs(*td - frame.timestamp) < 0.1)
            compensateDepthTime(f, *v, dt, frame.timestamp, *td);
    }
    return f;
}

TrackResult Slam::track(const core::Frame& frame, const FrameFeatures& features,
                        const std::optional<Eigen::Isometry3d>& prior) {
    TrackResult res;
    FrameRecord rec;
    rec.t = frame.timestamp;
    if (tracker_.state() == TrackingState::NotInitialized) {
        int n_depth = 0;
        for (float z : features.depth) n_depth += z > 0 ? 1 : 0;
        res.landmark_of_kp.assign(features.size(), kNoId);
        if (n_depth >= opts_.mapping.min_init_points) {
            // The first keyframe defines the world frame.
            res.state = TrackingState::Ok;
            res.pose_valid = true;
            res.T_wc = Eigen::Isometry3d::Identity();
            pending_init_ = true;
            tracker_.initialize(res.T_wc, frame.timestamp);
            rec.valid = true;
        } else {
            res.state = TrackingState::NotInitialized;
            // (of how many: a black frame has no keypoint at all, which read as a depth
            // problem)
            res.reason = "not initialized: " + std::to_string(n_depth) + " of " +
                         std::to_string(features.size()) + " keypoints with depth";
        }
        records_.push_back(rec);
        return res;
    }
    const TrackInput in{&features, frame.timestamp, prior, &frame.depth, opts_.orb.depth_factor};
    res = tracker_.track(in, map_, frame.K);
    rec.valid = res.pose_valid;
    const auto last = map_.lastKeyframes(1);
    if (!last.empty()) {
        rec.ref_kf = last.front();
        rec.T_ref_c = map_.keyframe(rec.ref_kf).T_wc.inverse() * res.T_wc;
    } else {
        rec.T_ref_c = res.T_wc;
    }
    // (A loaded map is not adjusted, so nothing is held for refinement.)
    if (res.pose_valid && opts_.mapping.refine_frames && !localizing_) {
        for (std::size_t i = 0; i < features.size(); ++i) {
            const LandmarkId lm = res.landmark_of_kp[i];
            if (lm == kNoId) continue;
            const auto o =
                observationOf(features, i, Eigen::Vector3d::Zero(), opts_.orb.scale_factor);
            rec.obs.push_back({lm, static_cast<float>(o.uv.x()), static_cast<float>(o.uv.y()),
                               static_cast<float>(o.depth), static_cast<float>(o.inv_sigma2),
                               static_cast<float>(o.weight)});
        }
    }
    records_.push_back(std::move(rec));
    return res;
}

MappingResult Slam::mapStep(const core::Frame& frame, FrameFeatures features,
                            const TrackResult& track) {
    MappingResult out;
    if (!track.pose_valid || (localizing_ && !extend_)) return out;
    ++frames_since_kf_;
    int n_close_tracked = 0, n_close_untracked = 0;
    for (std::size_t i = 0; i < features.size(); ++i) {
        if (features.depth[i] <= 0) continue;
        if (track.landmark_of_kp[i] != kNoId)
            ++n_close_tracked;
        else
            ++n_close_untracked;
    }
    // The reference count for the tracked-ratio rule: the first frame tracked after a keyframe.
    if (tracked_at_last_kf_ < 0) tracked_at_last_kf_ = track.n_inliers;
    if (!pending_init_) {
        KeyframeSelectorInput in;
        in.frames_since_last_kf = frames_since_kf_;
        in.n_tracked = track.n_inliers;
        in.n_tracked_at_last_kf = tracked_at_last_kf_;
        in.n_close_tracked = n_close_tracked;
        in.n_close_untracked = n_close_untracked;
        const auto& last = map_.keyframe(map_.lastKeyframes(1).front());
        const Eigen::Isometry3d d = last.T_wc.inverse() * track.T_wc;
        in.translation = d.translation().norm();
        in.rotation_deg = Eigen::AngleAxisd(d.linear()).angle() * 180.0 / M_PI;
        const auto dec = decideKeyframe(in, opts_.keyframes);
        out.reason = dec.reason;
        if (!dec.insert) return out;
    }
    pending_init_ = false;
    Keyframe kf;
    kf.frame_index = frame.index;
    kf.timestamp = frame.timestamp;
    kf.T_wc = track.T_wc;
    kf.features = std::move(features);
    const KeyframeId id = map_.addKeyframe(std::move(kf));
    if (localizing_) {  // extend_: mapping from here on, as a SLAM run's
        localizing_ = false;
        tracker_.finishLocalizing();
    }
    Keyframe& k = map_.keyframe(id);
    for (std::size_t i = 0; i < k.features.size(); ++i) {
        const LandmarkId lm = track.landmark_of_kp[i];
        if (lm != kNoId && map_.landmark(lm)) {
            map_.addObservation(lm, id, static_cast<int>(i));
        } else if (k.features.depth[i] > 0) {
            map_.addLandmark(k.T_wc * k.features.points_c[i],
                             k.features.descriptors.row(static_cast<int>(i)), k.features.colors[i],
                             id, static_cast<int>(i));
            ++out.new_landmarks;
        }
    }
    out.keyframe_inserted = true;
    out.keyframe = id;
    frames_since_kf_ = 0;
    tracked_at_last_kf_ = -1;
    if (!records_.empty()) {
        records_.back().ref_kf = id;
        records_.back().T_ref_c = Eigen::Isometry3d::Identity();
        records_.back().is_keyframe = true;
        records_.back().obs.clear();
    }
    // Cull landmarks that are rarely found where they should be seen, or that no later
    // keyframe confirmed.
    std::vector<LandmarkId> cull;
    for (const auto& [lid, lm] : map_.landmarks()) {
        // (A landmark behind a person, masked or not, is counted visible and not found: at
        // any age the test wears away the structure where people stand or sit.)
        const bool young = opts_.mapping.cull_ratio_keyframes == 0 ||
                           lm.created_kf >= id - opts_.mapping.cull_ratio_keyframes;
        const bool rarely_found = young && lm.n_visible >= opts_.mapping.cull_min_visible &&
                                  lm.n_found < opts_.mapping.cull_min_found_ratio * lm.n_visible;
        const bool unconfirmed =
            lm.created_kf == id - opts_.mapping.cull_keyframe_age && lm.observations.size() < 2;
        if (rarely_found || unconfirmed) cull.push_back(lid);
    }
    for (LandmarkId lid : cull) map_.removeLandmark(lid);
    out.culled_landmarks = static_cast<int>(cull.size());
    if (opts_.local_ba.enabled) out.ba = localBundleAdjust(map_, id, frame.K, opts_.local_ba);
    out.culled_keyframes = cullKeyframes(id);
    // Without local BA nothing moved to refine against until finalize(), but the frames
    // whose keyframe left the window are released all the same (else a long run keeps
    // every frame's observations).
    // With a final BA over more keyframes than the window, the frames of those keyframes
    // stay held (not refined) until finalize() refines them against the final map.
    if (opts_.mapping.refine_frames)
        refineFrames(oldestOfNewest(opts_.local_ba.window), oldestOfNewest(heldWindow()), frame.K,
                     opts_.local_ba.enabled);
    // The tracker continues from the (possibly adjusted) keyframe pose.
    tracker_.applyCorrection(map_.keyframe(id).T_wc * track.T_wc.inverse());
    return out;
}

int Slam::cullKeyframes(KeyframeId newest) {
    if (opts_.mapping.redundant_keyframe_ratio <= 0) return 0;
    // Kept: the first keyframe (the world frame and the pose graph's gauge), the newest,
    // and the keyframes of closed or pending loops (the graph's loop edges).
    std::vector<KeyframeId> keep{map_.keyframes().begin()->first, newest};
    for (const auto& l : loops_) keep.insert(keep.end(), {l.old_kf, l.new_kf});
    if (pending_loop_) keep.insert(keep.end(), {pending_loop_->old_kf, pending_loop_->new_kf});
    int culled = 0;
    // Oldest first: a keyframe removed no longer counts as an observer of the next ones.
    for (KeyframeId k : map_.lastKeyframes(static_cast<std::size_t>(opts_.local_ba.window))) {
        if (std::find(keep.begin(), keep.end(), k) != keep.end()) continue;
        if (map_.redundantFraction(k, opts_.mapping.redundant_keyframe_observers) <
            opts_.mapping.redundant_keyframe_ratio)
            continue;
        // Its frames (a contiguous run: records_ is in time order and each frame references
        // the newest keyframe when it was tracked) keep their poses, relative to the
        // keyframe before it.
        // (The keyframe before it exists: the first keyframe is kept.)
        const KeyframeId p = std::prev(map_.keyframes().find(k))->first;
        const Eigen::Isometry3d T_p_k = map_.keyframe(p).T_wc.inverse() * map_.keyframe(k).T_wc;
        for (auto r = records_.rbegin(); r != records_.rend() && r->ref_kf >= k; ++r) {
            if (r->ref_kf != k) continue;
            r->ref_kf = p;
            r->T_ref_c = T_p_k * r->T_ref_c;
            r->is_keyframe = false;
        }
        (void)map_.removeKeyframe(k);
        ++culled;
    }
    return culled;
}

int Slam::heldWindow() const {
    const auto& ba = opts_.local_ba;
    return ba.enabled && ba.final_window > 0 ? std::max(ba.window, ba.final_window) : ba.window;
}

KeyframeId Slam::oldestOfNewest(int n) const {
    const auto kfs = map_.lastKeyframes(static_cast<std::size_t>(n));
    return kfs.empty() ? kNoId : kfs.front();
}

void Slam::refineFrames(KeyframeId refine_from, KeyframeId keep_from,
                        const core::CameraIntrinsics& K, bool adjust) {
    if (keep_from == kNoId) return;
    bool release = true;
    std::vector<PoseObservation> obs;
    for (std::size_t i = first_record_with_obs_; i < records_.size(); ++i) {
        FrameRecord& r = records_[i];
        if (r.obs.empty()) {
            if (release) first_record_with_obs_ = i + 1;
            continue;
        }
        if (r.ref_kf < keep_from) {  // the keyframe has left the held window: final
            r.obs.clear();
            r.obs.shrink_to_fit();
            if (release) first_record_with_obs_ = i + 1;
            continue;
        }
        release = false;
        // (a frame before the first keyframe, ref_kf kNoId, was released above)
        if (!adjust || r.ref_kf < refine_from || r.is_keyframe || !r.valid) continue;
        obs.clear();
        obs.reserve(r.obs.size());
        for (const auto& h : r.obs) {
            const Landmark* l = map_.landmark(h.lm);
            if (!l) continue;
            obs.push_back({l->p_w, {h.u, h.v}, h.depth, h.inv_sigma2, h.weight});
        }
        if (static_cast<int>(obs.size()) < opts_.tracker.min_inliers) continue;
        const Eigen::Isometry3d T_wk = map_.keyframe(r.ref_kf).T_wc;
        const auto ref = refinePose(obs, T_wk * r.T_ref_c, K, opts_.tracker.refine);
        if (ref.n_inliers >= opts_.tracker.min_inliers) r.T_ref_c = T_wk.inverse() * ref.T_wc;
    }
}

std::size_t Slam::framesHeldForRefinement() const {
    return static_cast<std::size_t>(std::count_if(
        records_.begin(), records_.end(), [](const FrameRecord& r) { return !r.obs.empty(); }));
}

LocalBaResult Slam::finalize(const core::CameraIntrinsics& K) {
    LocalBaResult ba;
    const auto last = map_.lastKeyframes(1);
    if (last.empty() || localizing_) return ba;
    if (opts_.local_ba.enabled) {
        LocalBaOptions o = opts_.local_ba;
        if (o.final_window > 0) o.window = o.final_window;
        ba = localBundleAdjust(map_, last.front(), K, o);
    }
    // Every frame still held (mapStep: those of the final BA's keyframes too) against the
    // final map.
    if (opts_.mapping.refine_frames) {
        const KeyframeId oldest = oldestOfNewest(heldWindow());
        refineFrames(oldest, oldest, K);
    }
    return ba;
}

BackendResult Slam::backendStep(const MappingResult& mapping, const core::CameraIntrinsics& K) {
    BackendResult out;
    if (!mapping.keyframe_inserted || !opts_.loop.enabled) return out;
    if (!loops_.empty() && mapping.keyframe - loops_.back().new_kf < opts_.loop.cooldown_keyframes)
        return out;
    out.loop = detectLoop(map_, mapping.keyframe, K, opts_.loop, opts_.tracker.refine);
    const int confirm = opts_.loop.confirm_keyframes;
    if (pending_loop_ && mapping.keyframe - pending_loop_->new_kf > confirm) pending_loop_.reset();
    if (!out.loop) return out;
    if (confirm > 0) {
        // Close only a loop that a later keyframe's loop confirms; the newer one waits.
        if (!pending_loop_ || !loopsAgree(map_, *pending_loop_, *out.loop, opts_.loop.confirm_t,
                                          opts_.loop.confirm_deg)) {
            pending_loop_ = out.loop;
            return out;
        }
        loops_.push_back(*pending_loop_);
        pending_loop_.reset();
    }
    loops_.push_back(*out.loop);
    // Odometry edges from the current estimates (consistent), plus every loop edge.
    std::map<std::int64_t, Eigen::Isometry3d> poses;
    for (const auto& [id, kf] : map_.keyframes()) poses[id] = kf.T_wc;
    std::vector<PoseGraphEdge> edges;
    const auto odo_info = diagonalInformation(opts_.mapping.odometry_sigma_t,
                                              opts_.mapping.odometry_sigma_r_deg * M_PI / 180.0);
    for (auto it = poses.begin(); std::next(it) != poses.end(); ++it) {
        auto nx = std::next(it);
        edges.push_back({it->first, nx->first, it->second.inverse() * nx->second, odo_info});
    }
    const auto loop_info =
        diagonalInformation(opts_.loop.sigma_t, opts_.loop.sigma_r_deg * M_PI / 180.0);
    for (const auto& l : loops_) edges.push_back({l.old_kf, l.new_kf, l.T_old_new, loop_info});
    out.graph = optimizePoseGraph(poses, edges, poses.begin()->first, opts_.pose_graph);
    applyCorrections(out.graph.poses);
    out.loop_closed = true;
    return out;
}

void Slam::applyCorrections(const std::map<std::int64_t, Eigen::Isometry3d>& new_poses) {
    std::map<KeyframeId, Eigen::Isometry3d> delta;
    for (auto& [id, kf] : map_.keyframes()) {
        auto it = new_poses.find(id);
        if (it == new_poses.end()) continue;
        delta[id] = it->second * kf.T_wc.inverse();
        kf.T_wc = it->second;
    }
    for (auto& [lid, lm] : map_.landmarks()) {
        auto it = delta.find(lm.ref_kf);
        if (it != delta.end()) lm.p_w = it->second * lm.p_w;
    }
    if (!delta.empty()) tracker_.applyCorrection(delta.rbegin()->second);
}

FrameResult Slam::process(const core::Frame& frame, const cv::Mat& mask,
                          const std::optional<Eigen::Isometry3d>& prior) {
    FrameResult r;
    r.index = frame.index;
    r.timestamp = frame.timestamp;
    FrameFeatures f = extract(frame, mask);
    r.n_features = static_cast<int>(f.size());
    r.n_masked = f.n_masked;
    r.track = track(frame, f, prior);
    r.mapping = mapStep(frame, std::move(f), r.track);
    r.backend = backendStep(r.mapping, frame.K);
    return r;
}

void Slam::localizeIn(Map map, bool extend) {
    if (!records_.empty()) throw std::logic_error("Slam::localizeIn: called after the first frame");
    if (map.keyframes().empty())
        throw std::invalid_argument("Slam::localizeIn: the map has no keyframe");
    map_ = std::move(map);
    localizing_ = true;
    loaded_ = true;
    extend_ = extend;
    tracker_.startLocalizing(map_);
}

core::Trajectory Slam::trajectory() const {
    core::Trajectory out;
    out.reserve(records_.size());
    for (const auto& r : records_) {
        Eigen::Isometry3d T = r.T_ref_c;
        if (r.ref_kf != kNoId) T = map_.keyframe(r.ref_kf).T_wc * r.T_ref_c;
        out.push_back({r.t, core::toCPose3D(T)});
    }
    return out;
}

std::vector<std::size_t> Slam::lostFrames() const {
    std::vector<std::size_t> out;
    for (std::size_t i = 0; i < records_.size(); ++i)
        if (!records_[i].valid) out.push_back(i);
    return out;
}

std::vector<Slam::ClosedLoop> Slam::closedLoops() const {
    std::vector<ClosedLoop> out;
    for (const auto& l : loops_)
        out.push_back({map_.keyframe(l.old_kf).timestamp, map_.keyframe(l.new_kf).timestamp,
                       l.n_inliers, l.T_old_new});
    return out;
}

core::Trajectory Slam::keyframeTrajectory() const {
    core::Trajectory out;
    for (const auto& [id, kf] : map_.keyframes())
        out.push_back({kf.timestamp, core::toCPose3D(kf.T_wc)});
    return out;
}

}  // namespace devslam::slam
