#pragma once
/// The RGB-D SLAM system: ORB extraction (dynamic mask applied), tracking, keyframe
/// insertion with local mapping (landmark creation, culling, local BA), and the back end
/// (loop detection, MRPT pose graph). Stages are separate calls so that the caller can time
/// them; process() runs them all.
///
///   Frame + mask ─► extract ─► track ─► mapStep (keyframe? new landmarks, cull, local BA)
///                                              └─► backendStep (loop? pose graph, correct map)
///
/// Usage:
///   devslam::slam::Slam slam(devslam::slam::SlamOptions::fromConfig(*cfg));
///   while (auto f = reader->next()) { auto r = slam.process(*f, mask); }
///   auto traj = slam.trajectory();           // every frame, lost ones flagged
/// Not thread-safe; deterministic (OpenCV's RANSAC draws from a fixed-seed generator).
#include <devslam/core/Frame.h>
#include <devslam/core/Trajectory.h>
#include <devslam/slam/KeyframeSelector.h>
#include <devslam/slam/LocalBundleAdjuster.h>
#include <devslam/slam/LoopDetector.h>
#include <devslam/slam/Map.h>
#include <devslam/slam/OrbExtractor.h>
#include <devslam/slam/PoseGraph.h>
#include <devslam/slam/Tracker.h>

#include <optional>
#include <string>
#include <vector>

namespace mrpt::config {
class CConfigFileBase;
}

namespace devslam::slam {

/// Local-mapping rules besides keyframe selection and BA.
struct MappingOptions {
    int min_init_points = 100;  ///< keypoints with depth needed to start the map
    double cull_min_found_ratio =
        0.25;                   ///< found/visible below this (after cull_min_visible) -> removed
    int cull_min_visible = 6;   ///< visible count before the ratio test applies
    int cull_keyframe_age = 3;  ///< landmarks this many keyframes old need >= 2 observations
    /// The found/visible test applies to landmarks created in the last this many keyframes
    /// (ORB-SLAM2: about 3); 0: at any age
    int cull_ratio_keyframes = 0;
    /// A keyframe of the local-BA window (not the newest, the first or a loop's) is removed
    /// when at least this fraction of its landmarks is observed by
    /// `redundant_keyframe_observers` other keyframes at the same or a finer scale
    /// (ORB-SLAM2's keyframe culling, 0.9 there); 0: keyframes are never removed. Bounds the
    /// map of a camera that stands still (a robot waiting adds a keyframe every max_frames).
    double redundant_keyframe_ratio = 0.0;
    int redundant_keyframe_observers = 3;
    double odometry_sigma_t = 0.01;     ///< [m] consecutive-keyframe edge std in the pose graph
    double odometry_sigma_r_deg = 0.5;  ///< [deg]
    /// Move depth points to the colour image's time with the constant-velocity model when
    /// the depth image has its own stamp (TUM: up to 20 ms apart; see depthStamp()).
    bool depth_time_compensation = true;
    /// After each local BA, re-refine the poses of the frames between the optimised
    /// keyframes against the adjusted landmarks (frames get keyframe-like accuracy); with
    /// LocalBaOptions::final_window, once more after the final BA for the frames of every
    /// keyframe it adjusts (their inliers are held until then, 32 bytes each: +0.1-6 MB of
    /// peak memory on the bench's 750-frame runs).
    bool refine_frames = true;

    void loadFromConfig(const mrpt::config::CConfigFileBase& cfg,
                        const std::string& section = "mapping");
    void saveToConfig(mrpt::config::CConfigFileBase& cfg,
                      const std::string& section = "mapping") const;
};

/// Stamp of the depth image when it has its own (a TUM folder's depth.txt: Frame's
/// depth_timestamp); std::nullopt otherwise (rawlogs: depth and colour share the
/// observation's stamp). Before, it was read from the depth file's name, so that a folder
/// whose stamps were shifted (names kept) lost the compensation without a word.
[[nodiscard]] std::optional<double> depthStamp(const core::Frame& frame);

/// Moves the depths of `f` from the depth image's time to the colour image's: each point
/// keeps its keypoint's ray and takes the depth z of T_cur_depth * p, with T_cur_depth
/// interpolated from the motion `T_prev_cur` over `dt_prev` [s] (constant velocity). (The
/// depth pixel under a keypoint saw another point of the surface; moved whole, that point
/// left its keypoint by as far as the image moved in between: 2.6 px for 0.5 m/s sideways
/// at 2 m and 20 ms. Its depth is the surface's along the keypoint's ray, exactly so for a
/// plane facing the camera or a motion along the ray.)
void compensateDepthTime(FrameFeatures& f, const Eigen::Isometry3d& T_prev_cur, double dt_prev,
                         double t_rgb, double t_depth);

struct SlamOptions {
    OrbExtractor::Options orb;
    TrackerOptions tracker;
    KeyframeSelectorOptions keyframes;
    MappingOptions mapping;
    LocalBaOptions local_ba;
    LoopOptions loop;
    PoseGraphOptions pose_graph;

    /// Sections [orb] [tracker] [keyframes] [mapping] [local_ba] [loop_closure]
    /// [pose_graph] (all optional; unknown keys throw naming section and key).
    [[nodiscard]] static SlamOptions fromConfig(const mrpt::config::CConfigFileBase& cfg);
    /// The sections fromConfig reads, for a caller that checks a whole file's sections.
    [[nodiscard]] static const std::vector<std::string>& sections();
    void saveToConfig(mrpt::config::CConfigFileBase& cfg) const;
};

struct MappingResult {
    bool keyframe_inserted = false;
    KeyframeReason reason = KeyframeReason::None;
    KeyframeId keyframe = kNoId;
    int new_landmarks = 0;
    int culled_landmarks = 0;
    int culled_keyframes = 0;  ///< redundant keyframes removed (redundant_keyframe_ratio)
    LocalBaResult ba;
};

struct BackendResult {
    bool loop_closed = false;
    std::optional<LoopConstraint> loop;
    PoseGraphResult graph;  ///< filled when a loop was closed
};

/// Everything about one processed frame.
struct FrameResult {
    std::size_t index = 0;
    double timestamp = 0.0;
    TrackResult track;
    MappingResult mapping;
    BackendResult backend;
    int n_features = 0;
    int n_masked = 0;
};

class Slam {
  public:
    explicit Slam(const SlamOptions& opts);

    /// ORB features with depth (and depth-time compensation, see MappingOptions).
    [[nodiscard]] FrameFeatures extract(const core::Frame& frame, const cv::Mat& mask) const;
    /// Tracks (or, first, initializes on) the frame; records its trajectory entry.
    [[nodiscard]] TrackResult track(const core::Frame& frame, const FrameFeatures& features,
                                    const std::optional<Eigen::Isometry3d>& T_prev_cur_prior = {});
    /// Keyframe decision and local mapping for the frame just tracked.
    [[nodiscard]] MappingResult mapStep(const core::Frame& frame, FrameFeatures features,
                                        const TrackResult& track);
    /// Loop detection and pose-graph optimisation after a keyframe insertion.
    [[nodiscard]] BackendResult backendStep(const MappingResult& mapping,
                                            const core::CameraIntrinsics& K);
    /// End of sequence: a last BA over the newest keyframes (LocalBaOptions::final_window
    /// of them, else the local window) and the re-refinement of the frames that reference
    /// those keyframes against the final map (see MappingOptions::refine_frames). Returns
    /// that BA's result (empty when local BA is off or there is no keyframe).
    LocalBaResult finalize(const core::CameraIntrinsics& K);
    /// All stages for one frame.
    [[nodiscard]] FrameResult process(
        const core::Frame& frame, const cv::Mat& mask,
        const std::optional<Eigen::Isometry3d>& T_prev_cur_prior = {});

    /// Prediction for the dynamic filter (see Tracker::predictPrevCur).
    [[nodiscard]] std::optional<Eigen::Isometry3d> predictPrevCur(double timestamp) const {
        return tracker_.predictPrevCur(timestamp);
    }
    /// Constant-velocity motion over `dt` [s] (see Tracker::predictMotion); for a filter
    /// that runs one frame ahead of the tracker.
    [[nodiscard]] std::optional<Eigen::Isometry3d> predictMotion(double dt) const {
        return tracker_.predictMotion(dt);
    }
    /// Pose of every frame so far (relative to its reference keyframe, so later keyframe
    /// corrections carry over). Lost frames hold their motion-model prediction.
    [[nodiscard]] core::Trajectory trajectory() const;
    /// Indices (0-based, in processing order) of frames without a tracked pose.
    [[nodiscard]] std::vector<std::size_t> lostFrames() const;
    [[nodiscard]] core::Trajectory keyframeTrajectory() const;
    [[nodiscard]] const Map& map() const { return map_; }
    /// Localization only, in a map made before (loadMap): before the first frame, takes
    /// `map` as the map and keeps it as it is. Each frame is tracked against the keyframes
    /// nearest it; the first frames are lost until one relocalizes against any keyframe of
    /// the map. No keyframe, landmark, local BA or loop is made (mapStep, backendStep and
    /// finalize do nothing), so poses are in the map's frame and the map stays valid for the
    /// next run. Throws std::logic_error after a frame, std::invalid_argument for an empty
    /// map.
    ///
    /// With `extend`, the run maps too once it has found its pose: from the first frame
    /// tracked in the map it inserts keyframes and landmarks, adjusts and closes loops as a
    /// SLAM run does, in the map's frame (older keyframes and landmarks move with the local
    /// BA, loops and the final BA like any others).
    void localizeIn(Map map, bool extend = false);
    /// localizeIn was called.
    [[nodiscard]] bool localizing() const { return loaded_; }
    /// localizeIn was called and some frame has found its pose in the map.
    [[nodiscard]] bool localized() const { return loaded_ && tracker_.trackedSinceStart(); }
    /// The place index localizeIn trained on the map ([tracker] place_recognition), or null.
    [[nodiscard]] const PlaceIndex* placeIndex() const { return tracker_.placeIndex(); }
    [[nodiscard]] int loopsClosed() const { return static_cast<int>(loops_.size()); }
    /// A loop the back end closed, as measured when it was verified.
    struct ClosedLoop {
        double t_old = 0, t_new = 0;  ///< timestamps of the two keyframes
        int inliers = 0;              ///< verified PnP inliers
        Eigen::Isometry3d T_old_new = Eigen::Isometry3d::Identity();  ///< measured relative pose
    };
    /// Every loop closed so far, in closing order.
    [[nodiscard]] std::vector<ClosedLoop> closedLoops() const;
    [[nodiscard]] const SlamOptions& options() const { return opts_; }
    /// Frames whose observations are still kept for refine_frames (those referencing a
    /// keyframe in the local-BA window, or in the final BA's when final_window is set);
    /// bounded by the window in keyframes, whatever the sequence's length.
    [[nodiscard]] std::size_t framesHeldForRefinement() const;

  private:
    /// A tracked inlier as a frame record holds it: 32 bytes where a PoseObservation with
    /// its landmark id takes 80 (the point is the landmark's current one, looked up at
    /// refinement; pixels are floats in cv::KeyPoint already).
    struct HeldObservation {
        LandmarkId lm = kNoId;
        float u = 0, v = 0;  ///< [px]
        float depth = 0;     ///< [m], 0 = none
        float inv_sigma2 = 1, weight = 1;
    };
    struct FrameRecord {
        double t = 0.0;
        KeyframeId ref_kf = kNoId;  ///< kNoId: pose is absolute (before the first keyframe)
        Eigen::Isometry3d T_ref_c = Eigen::Isometry3d::Identity();
        bool valid = false;
        bool is_keyframe = false;
        /// Inlier observations kept while the reference keyframe is in the BA window (or
        /// in the final BA's, LocalBaOptions::final_window), so the frame can be
        /// re-refined against the adjusted map (then released).
        std::vector<HeldObservation> obs;
    };
    void applyCorrections(const std::map<std::int64_t, Eigen::Isometry3d>& new_poses);
    /// Motion-only refinement, against the current landmark positions, of the non-keyframe
    /// frames whose reference keyframe is `refine_from` or newer (only when `adjust`);
    /// the observations of frames older than `keep_from` are released.
    void refineFrames(KeyframeId refine_from, KeyframeId keep_from,
                      const core::CameraIntrinsics& K, bool adjust = true);
    /// Keyframes whose frames keep their observations: the local-BA window, or the final
    /// BA's when that is larger (the frames are refined once more after it).
    [[nodiscard]] int heldWindow() const;
    /// The oldest of the newest `n` keyframes (kNoId when the map has none).
    [[nodiscard]] KeyframeId oldestOfNewest(int n) const;
    /// Removes the redundant keyframes of the local window before `newest` (see
    /// MappingOptions::redundant_keyframe_ratio); their frames move to the keyframe before.
    int cullKeyframes(KeyframeId newest);
    std::size_t first_record_with_obs_ = 0;

    SlamOptions opts_;
    OrbExtractor orb_;
    Tracker tracker_;
    Map map_;
    std::vector<FrameRecord> records_;
    std::vector<LoopConstraint> loops_;  ///< closed, in closing order (the graph's loop edges)
    std::optional<LoopConstraint> pending_loop_;  ///< verified, awaiting confirmation
    int frames_since_kf_ = 0;
    int tracked_at_last_kf_ = 0;
    bool pending_init_ = false;
    bool localizing_ = false;    ///< localizeIn, and (extend_) no keyframe of its own yet
    bool extend_ = false;        ///< localizeIn's extend
    bool loaded_ = false;        ///< localizeIn was called
};

}  // namespace devslam::slam
