#pragma once
/// Frame-to-map tracking: constant-velocity prediction, projection matching against the
/// local map, cv::solvePnPRansac, motion-only refinement, a second finer projection pass,
/// and relocalization against keyframes when tracking is lost.
///
/// States:  NotInitialized --(first keyframe)--> Ok <--> Lost
///          (Ok after Lost is reported once as Relocalized)
///
/// Usage:
///   Tracker tracker(opts);
///   tracker.initialize(T_wc0, t0);                       // after the first keyframe
///   auto r = tracker.track({&features, t, prior}, map, K);
/// Not thread-safe.
#include <devslam/core/Camera.h>
#include <devslam/slam/Map.h>
#include <devslam/slam/Matching.h>
#include <devslam/slam/PlaceIndex.h>
#include <devslam/slam/PoseSolver.h>

#include <memory>
#include <optional>
#include <string>

namespace mrpt::config {
class CConfigFileBase;
}

namespace devslam::slam {

enum class TrackingState { NotInitialized, Ok, Relocalized, Lost };
[[nodiscard]] std::string toString(TrackingState s);

struct TrackerOptions {
    ProjectionMatchOptions projection;  ///< first pass (radius around the prediction)
    double fine_radius = 4.0;           ///< [px] second pass around the refined pose
    double wide_radius_factor = 3.0;    ///< first pass retried with radius * this when too few
    PnpRansacOptions pnp;
    PoseRefineOptions refine;
    int min_matches = 20;         ///< fewer projection matches: wide search, then relocalize
    int min_inliers = 20;         ///< fewer inliers after refinement: tracking failed
    int local_keyframes = 10;     ///< the local map = landmarks of the last N keyframes
    /// ... and of the N keyframes nearest the predicted camera (centre distance), among
    /// those whose optical axis is within near_max_angle_deg of its own: a revisited place
    /// is tracked against its old landmarks instead of growing new ones. 0: newest only.
    int near_keyframes = 0;
    double near_max_angle_deg = 45.0;  ///< [deg]
    /// Localizing in a loaded map (startLocalizing): the local map = landmarks of the N
    /// keyframes nearest the camera among those facing within near_max_angle_deg (a map made
    /// on another path: more of them, more matches; walking_xyz in walking_halfsphere's map
    /// 4.5 mm of ATE with 15, 3.5 with 35).
    int localize_keyframes = 30;
    double max_motion_dt = 0.25;  ///< [s] larger frame gaps: no velocity extrapolation
    int reloc_keyframes = 10;     ///< keyframes tried when relocalizing (newest, nearest)
    /// Localizing in a loaded map: a lost frame's candidate keyframes are those whose bag of
    /// words (PlaceIndex, trained on the map when it is loaded) is most like the frame's;
    /// false: every keyframe is matched with the frame's strongest keypoints and ranked by
    /// matches (about 2 ms a keyframe).
    bool place_recognition = true;
    /// Localizing in a loaded map: a pose, relocalized or tracked, is refused (the frame
    /// lost) when the frame's depth image sees through more than this fraction of the map's
    /// landmarks that it measures depth at (freeSpaceTest over the local map at that pose, at
    /// least 20 landmarks checked); 1: no test. A place whose pictures are found elsewhere in
    /// the map (a room with the same photos cropped otherwise) relocalized 0.3-1.3 m off
    /// without it, and was tracked on there.
    double localize_max_see_through = 0.07;
    int reloc_min_inliers = 25;   ///< PnP inliers needed to relocalize
    int reloc_max_hamming = 64;   ///< brute-force matching threshold
    double reloc_ratio = 0.8;     ///< brute-force ratio test
    /// A relocalized pose must lie within reloc_max_jump + reloc_max_speed * (time since the
    /// last tracked frame) of the last tracked pose, and its rotation within
    /// reloc_max_jump_deg + reloc_max_rate_deg * that time: after a short loss, a pose far
    /// away is a false match (repeated textures), and it would break the trajectory. After
    /// a long loss the bound grows and anything goes. reloc_max_speed <= 0: no bound.
    double reloc_max_jump = 0.1;       ///< [m]
    double reloc_max_speed = 1.0;      ///< [m/s]
    double reloc_max_jump_deg = 10.0;  ///< [deg]
    double reloc_max_rate_deg = 90.0;  ///< [deg/s]
    double scale_factor = 1.3;    ///< ORB pyramid scale for level sigmas (copied from [orb])

    void loadFromConfig(const mrpt::config::CConfigFileBase& cfg,
                        const std::string& section = "tracker");
    void saveToConfig(mrpt::config::CConfigFileBase& cfg,
                      const std::string& section = "tracker") const;
};

struct TrackInput {
    const FrameFeatures* features = nullptr;
    double timestamp = 0.0;  ///< [s]
    /// Pose of this camera in the previous one (p_prev = T * p_cur) from elsewhere (e.g. the
    /// dynamic filter's refined ego-motion); replaces the velocity model when set. Not used
    /// while the tracker is lost (the last tracked pose is then frames old; relocalisation
    /// needs no prior).
    std::optional<Eigen::Isometry3d> T_prev_cur_prior;
    /// The frame's depth image (CV_32FC1 [m], 0 = none, in the image's own, distorted,
    /// pixels), for the free-space test of the poses found while localizing in a loaded map
    /// (relocalized and tracked); null: none.
    const cv::Mat* depth = nullptr;
    /// [orb] depth_factor: the landmarks' depths are the image's times this.
    double depth_factor = 1.0;
};

/// What the depth image says of a camera pose: of the landmarks that project into the
/// image, those where it measures depth nearby, and those it sees through.
struct FreeSpaceResult {
    int checked = 0;       ///< projected, with a measured depth within the window
    int seen_through = 0;  ///< every depth measured there is farther than the landmark
};

/// Free-space test of a camera pose `T_wc` (Tracker, while localizing: each relocalized and
/// tracked pose): each of `landmarks` in front of the camera and in its view is projected
/// into `depth` (with K's distortion; a depth of another size than K's checks nothing), whose
/// values are multiplied by `depth_factor` ([orb] depth_factor, the landmarks' scale);
/// where a pixel within `window_px` of it measures depth, the landmark is checked, and it is
/// seen through when the nearest of those depths is farther than the landmark by more than
/// `margin_m + margin_rel * depth`. Something nearer (a person, a chair) may hide a landmark;
/// a camera that sees through a landmark's place is not where the pose puts it.
[[nodiscard]] FreeSpaceResult freeSpaceTest(const Map& map,
                                            const std::vector<LandmarkId>& landmarks,
                                            const Eigen::Isometry3d& T_wc, const cv::Mat& depth,
                                            const core::CameraIntrinsics& K,
                                            double depth_factor = 1.0, int window_px = 1,
                                            double margin_m = 0.05, double margin_rel = 0.05);

struct TrackResult {
    TrackingState state = TrackingState::NotInitialized;
    Eigen::Isometry3d T_wc = Eigen::Isometry3d::Identity();  ///< estimate, or prediction if Lost
    bool pose_valid = false;                 ///< false: T_wc is only the motion-model prediction
    int n_matches = 0;                       ///< correspondences given to the refinement
    int n_inliers = 0;                       ///< inliers after refinement
    int n_in_view = 0;                       ///< local-map landmarks projecting into the image
    double rms_px = 0.0;                     ///< inlier reprojection RMS [px]
    std::vector<LandmarkId> landmark_of_kp;  ///< per keypoint: inlier landmark or kNoId
    std::string reason;                      ///< why tracking failed (empty when Ok)
};

class Tracker {
  public:
    explicit Tracker(const TrackerOptions& opts) : opts_(opts) {}

    /// Starts tracking at a pose (the first keyframe's).
    void initialize(const Eigen::Isometry3d& T_wc, double timestamp);
    /// Starts localizing in a map made before (Slam::localizeIn): lost until a frame
    /// relocalizes against any of its keyframes (no jump bound for that first pose). From
    /// then on the local map is the keyframes nearest the camera, not the map's newest, and
    /// a lost frame is matched against every keyframe, the reloc_keyframes with the most
    /// matches verified.
    /// Trains the place index on `map` (place_recognition), which must not lose keyframes
    /// while localizing.
    void startLocalizing(const Map& map);
    /// Back to a SLAM run's local map and relocalization (Slam::localizeIn's extend, once
    /// the run has made a keyframe of its own), with at least local_keyframes of the older
    /// keyframes nearest the camera (the loaded map's) beside its newest.
    void finishLocalizing() {
        localizing_ = false;
        place_.reset();
    }
    /// A frame has been tracked since startLocalizing (or since the start).
    [[nodiscard]] bool trackedSinceStart() const { return localized_; }
    /// The loaded map's place index; null when not localizing (or no longer: finishLocalizing)
    /// or place_recognition is off.
    [[nodiscard]] const PlaceIndex* placeIndex() const { return place_.get(); }
    /// Tracks one frame against `map`; updates the landmarks' visible/found counters.
    [[nodiscard]] TrackResult track(const TrackInput& in, Map& map,
                                    const core::CameraIntrinsics& K);
    /// Constant-velocity prediction of the next camera in the last one (p_prev = T * p_cur)
    /// for a frame at `timestamp`; nullopt when unknown (not initialized, lost, big gap).
    [[nodiscard]] std::optional<Eigen::Isometry3d> predictPrevCur(double timestamp) const;
    /// Constant-velocity motion over an interval `dt` [s] between two consecutive frames
    /// (p_prev = T * p_cur); nullopt when unknown, identity without a velocity or dt too big.
    [[nodiscard]] std::optional<Eigen::Isometry3d> predictMotion(double dt) const;
    /// Moves the tracker's last pose by a world correction (after loop closure).
    void applyCorrection(const Eigen::Isometry3d& T_new_old);
    [[nodiscard]] TrackingState state() const { return state_; }
    [[nodiscard]] const Eigen::Isometry3d& lastPose() const { return last_T_wc_; }
    [[nodiscard]] double lastTimestamp() const { return last_t_; }

    /// Whether a relocalized pose at `timestamp` is within the jump bound (reloc_max_jump,
    /// reloc_max_speed, ...) of the last tracked pose.
    [[nodiscard]] bool relocPlausible(const Eigen::Isometry3d& T_wc, double timestamp) const;

  private:
    /// `in_view`: the local landmarks that projected into the image in the fine pass (their
    /// visible counters are the caller's to update, once the pose is kept).
    std::optional<PoseRefineResult> trackWithMap(const FrameFeatures& f, const Map& map,
                                                 const core::CameraIntrinsics& K,
                                                 const Eigen::Isometry3d& pred,
                                                 const std::vector<LandmarkId>& local,
                                                 TrackResult& res,
                                                 std::vector<LandmarkId>& in_view) const;
    /// `timestamp`: of the frame, for the jump bound.
    /// `depth`: the frame's depth image for the free-space test (localizing), or null.
    std::optional<Eigen::Isometry3d> relocalize(const FrameFeatures& f, const Map& map,
                                                const core::CameraIntrinsics& K, double timestamp,
                                                const cv::Mat* depth, double depth_factor) const;

    /// Whether poses are put to the free-space test: localizing, with a depth image, and
    /// localize_max_see_through below 1.
    [[nodiscard]] bool testsFreeSpace(const cv::Mat* depth) const {
        return localizing_ && depth && opts_.localize_max_see_through < 1;
    }
    /// Whether a free-space test refuses its pose: more than localize_max_see_through of at
    /// least 20 checked landmarks seen through.
    [[nodiscard]] bool seenThrough(const FreeSpaceResult& fs) const {
        return fs.checked >= 20 && fs.seen_through > opts_.localize_max_see_through * fs.checked;
    }

    /// The landmarks of the local map for a camera at `T_wc` (local_keyframes newest,
    /// near_keyframes nearest).
    std::vector<LandmarkId> localMap(const Map& map, const Eigen::Isometry3d& T_wc) const;

    TrackerOptions opts_;
    TrackingState state_ = TrackingState::NotInitialized;
    Eigen::Isometry3d last_T_wc_ = Eigen::Isometry3d::Identity();
    Eigen::Isometry3d velocity_ = Eigen::Isometry3d::Identity();  ///< T_prev_cur of the last step
    bool has_velocity_ = false;
    double last_t_ = 0.0;
    double velocity_dt_ = 0.0;
    bool localizing_ = false;  ///< startLocalizing: the map was loaded, not made here
    bool loaded_map_ = false;  ///< startLocalizing was called (finishLocalizing keeps it)
    bool localized_ = false;   ///< a frame has been tracked (since startLocalizing)
    /// The free-space test refused the last pose kept: the next relocalization has no jump
    /// bound (the last pose was the wrong one), as before the first.
    bool unanchored_ = false;
    /// The loaded map's place index (startLocalizing with place_recognition); shared, so that
    /// the tracker stays copyable.
    std::shared_ptr<const PlaceIndex> place_;
};

}  // namespace devslam::slam
