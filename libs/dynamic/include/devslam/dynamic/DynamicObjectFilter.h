#pragma once
/// The dynamic-object filter (Algorithm 1 of the DEV-SLAM paper, with ego-motion
/// compensation): which detected people are really moving, and the mask of image regions
/// whose keypoints the SLAM front end must drop.
///
/// Usage:
///   auto cfg = devslam::core::loadIni("config_ini/dynamic_filter.ini");
///   auto filter = devslam::dynamic::makeFilterFromConfig(*cfg);
///   auto out = filter->step(frame, T_prev_cur_prediction);   // in frame order
///   orb->detect(gray, kps, out.mask.empty() ? cv::noArray() : ~out.mask);
#include <devslam/core/Frame.h>
#include <devslam/detect/PersonDetector.h>

#include <Eigen/Geometry>
#include <array>
#include <memory>
#include <opencv2/core/mat.hpp>
#include <optional>
#include <string>
#include <vector>

namespace mrpt::config {
class CConfigFileBase;
}

namespace devslam::dynamic {

/// What is masked. INI: `mode = none | all_persons | dynamic`.
enum class MaskMode {
    None,        ///< nothing masked, detector never run (ORB-SLAM2-like)
    AllPersons,  ///< every detected person masked (DynaSLAM-like)
    Dynamic      ///< only people classified Moving (DEV-SLAM)
};
/// Parses "none", "all_persons", "dynamic"; throws std::invalid_argument with the known names.
[[nodiscard]] MaskMode parseMaskMode(const std::string& name);
[[nodiscard]] std::string toString(MaskMode mode);

/// Motion state of a tracked box.
enum class BoxState {
    Unknown,  ///< too few tracked points to decide (yet)
    Static,   ///< the object moves with the world (e.g. a seated person)
    Moving    ///< the object moves in the world
};
[[nodiscard]] std::string toString(BoxState state);

/// One person box tracked over frames.
struct TrackedBox {
    int id = -1;     ///< stable over frames (IoU association)
    cv::Rect2f box;  ///< [px] in the current frame
    BoxState state = BoxState::Unknown;
    float score = 0.f;                 ///< detector score of the last detection
    int n_points = 0;  ///< flow points inside the box (in the person's depth band) this step
    /// of which residual > the box's threshold: threshold1, or more where the background's
    /// or the ring around the box's residual flow is larger (docs/dynamic.md)
    int n_dynamic_points = 0;
    bool detected_this_frame = false;  ///< false: box carried by LK flow (or kept) this step
};

/// Result of one step.
struct FilterOutput {
    cv::Mat mask;  ///< CV_8UC1, frame size, 255 = masked (drop keypoints here), 0 = keep
    /// CV_8UC1, frame size, 255 = inside the box of a person judged Static (with
    /// first_frame_as_static also an unmasked person of a frame with no previous one), for
    /// the SLAM's static_person_weight. Empty unless mode Dynamic and that weight < 1.
    cv::Mat static_people;
    std::vector<TrackedBox> boxes;
    bool detector_ran = false;
    double detect_ms = 0, filter_ms = 0;  ///< [ms] wall time of this step's stages
    /// [ms] wall time of the filter's own stages this step (together about filter_ms), in
    /// the order they run; devslam-filter-bench reports their medians
    struct StageTimes {
        double images = 0;      ///< grey image, scaling, LK pyramid; kept for the next step
        double corners = 0;     ///< Shi-Tomasi map of the previous frame, corner selection
        double flow = 0;        ///< pyramidal LK, forward and back
        double boxes = 0;       ///< carrying, association (the detector excluded), depths
        double ego_motion = 0;  ///< 3D of the points, PnP-RANSAC on the background
        double residuals = 0;   ///< residual flow and the image-wide threshold
        double evidence = 0;    ///< per-box evidence, states, forgetting
        double mask = 0;        ///< reported boxes and the mask
        /// the stages above, in that order
        [[nodiscard]] std::array<double, 8> values() const {
            return {images, corners, flow, boxes, ego_motion, residuals, evidence, mask};
        }
    } stage_ms;
    /// Ego-motion refined on background points (p_prev = T * p_cur), if computed.
    std::optional<Eigen::Isometry3d> T_prev_cur_refined;

    /// Diagnostics for overlays (previous-frame point, current-frame point, residual
    /// [px] after ego-motion compensation, inside a person box, dynamic), empty in None.
    struct FlowPoint {
        cv::Point2f prev, cur;
        float residual = 0.f;
        bool in_box = false;
        bool dynamic = false;
    };
    std::vector<FlowPoint> flow;
    double threshold = 0;  ///< [px] residual threshold used this step (see background_factor)
};

/// When the filter's pyramidal LK stops iterating on a point (forward and backward tracks;
/// devslam-filter-bench runs the same LK to measure the forward-backward check).
[[nodiscard]] inline cv::TermCriteria lkTermination() {
    return {cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 10, 0.03};
}

/// Dynamic-object filter. Not thread-safe; consumes frames in order.
class DynamicObjectFilter {
  public:
    struct Options {
        MaskMode mode = MaskMode::Dynamic;
        int detect_every = 1;  ///< run the detector every k-th frame (1 = every frame)

        // Flow points (Shi-Tomasi on the previous frame, pyramidal LK into the current one)
        double flow_scale = 0.5;           ///< corners + LK run on the image scaled by this (speed)
        int max_corners = 200;             ///< corners in the whole image
        int max_corners_per_box = 40;      ///< extra corners seeded inside each person box
        /// Fewer image-wide corners than this away from the person boxes (where the
        /// ego-motion fit takes its points; see nearAnyBox): extra ones are seeded there, up
        /// to this many. 0: none.
        int background_corners = 40;
        double corner_quality = 0.01;      ///< Shi-Tomasi quality level (fraction of best)
        double corner_min_distance = 5.0;  ///< [px of the scaled image] between corners
        int lk_window = 11;                ///< [px of the scaled image] LK window side
        int lk_levels = 2;                 ///< pyramid levels above the base
        double fb_max_error = 1.0;         ///< [px] forward-backward check

        // Ego-motion compensation
        bool refine_ego_motion = true;     ///< refine the prior with PnP-RANSAC on background
        int min_background_points = 12;    ///< fewer: keep the prior
        double ransac_reprojection = 2.0;  ///< [px] PnP-RANSAC inlier threshold
        double max_depth = 8.0;            ///< [m] depths beyond are not trusted

        // Classification (Algorithm 1)
        double threshold1 = 2.0;  ///< [px] residual flow that makes a point dynamic
        /// the residual threshold is max(threshold1, background_factor * 90th percentile of
        /// the background points' residuals): frames where the background itself fits badly
        /// (rgb/depth time offset, blur) do not flag static people. 0 = fixed threshold1.
        double background_factor = 2.0;
        int threshold2_count = 4;          ///< min dynamic points for a moving box
        double threshold2_fraction = 0.4;  ///< and min fraction of the box's points
        int min_points = 6;                ///< fewer points in a box: no new evidence
        double box_shrink = 0.1;           ///< fraction of w/h ignored at each box side
        /// [m] only points within fg_depth_band + 10 % of the person's depth (median depth
        /// of the box's torso region, or of its nearest quarter where that lies more than
        /// this band in front: a person the border cuts) are the person's evidence, and the
        /// per-box corners
        /// are sought there: a near person's low-contrast clothing otherwise loses the
        /// corners to the background seen inside the box, which votes "static".
        /// 0 = every point in the box counts.
        double fg_depth_band = 0.0;
        /// [m] a second vote, with the same threshold2_count and threshold2_fraction, over
        /// the box's points within narrow_vote_band + narrow_vote_slope x the person's depth
        /// of that depth (when at least min_points lie there); either vote makes the box
        /// moving. fg_depth_band has to be wide (a near person's depth spreads over their
        /// body), and a still desk or shelf beside a walker at nearly their depth then
        /// outvotes the walker's points. 0 = off.
        double narrow_vote_band = 0.0;
        double narrow_vote_slope = 0.03;  ///< [m per m of depth]
        /// Slow walkers: a box is also moving when the mean, over its last slow_frames
        /// steps with evidence, of its points' median residual flow vector exceeds
        /// max(slow_threshold, local threshold / 2) [px per frame]. A person walking at
        /// 0.5 m/s 4 m away moves under 2 px a frame, below threshold1 for every single
        /// point, but the same way in every frame, while noise averages out. A walker who
        /// stops is released up to slow_frames - 1 steps later (the window still holds
        /// their walk). 0 = off (per-frame evidence only).
        int slow_frames = 0;
        double slow_threshold = 1.0;  ///< [px per frame]
        /// [m/s] with the person's depth z and the time dt between the frames, the
        /// slow-mover test also needs more than slow_speed * dt * fx / z px per frame: the
        /// same speed moves a near person's pixels farther, so a seated person's sway near
        /// the camera would pass a pixel threshold that a slow walker far away needs.
        /// 0 = the pixel threshold alone (also used for a box without depth, and where the
        /// frames' timestamps do not advance or jump by 1 s or more).
        double slow_speed = 0.0;
        /// People walking towards or away from the camera: their image barely moves (a
        /// point 100 px from the centre of a person 1.5 m away, walking at 0.45 m/s,
        /// moves 1 px a frame), but their depth does. Each step adds the median depth
        /// residual of the box's points (measured depth - the depth ego-motion predicts,
        /// less the background's median) to a window of depth_frames steps; the box is
        /// also moving when the window's sum, the person's depth change the camera's
        /// motion does not explain, exceeds both depth_rate_threshold * depth_frames and
        /// depth_noise_z2 * z^2 (z: the person's depth; a depth camera's error grows with
        /// z^2, and a flat person's depth jumps by whole quantisation steps, ~1 cm at 2 m
        /// for a Kinect). The sum telescopes, so noise does not add up over the window.
        /// 0 = off.
        int depth_frames = 0;
        double depth_rate_threshold = 0.005;  ///< [m per frame]
        double depth_noise_z2 = 0.01;         ///< [1/m]

        // Tracking and hysteresis
        double iou_match = 0.3;         ///< min IoU to associate a detection with a track
        int release_frames = 5;         ///< quiet frames before a Moving box becomes Static
        /// Quiet steps before a new (Unknown) box at the left or right image border (within
        /// mask_margin) becomes Static; elsewhere, and with 1, the first quiet step does it.
        /// While Unknown a box is masked (mask_unknown): a walker entering the view, half
        /// seen, often shows no motion on their first steps.
        int confirm_border_frames = 1;
        int max_missed_detections = 2;  ///< detector runs without a match before a track is dropped
        /// A Moving track outlives detector misses (walkers cut by the border, half hidden),
        /// carried by its points' flow. When neither the detector (unmatched at its last
        /// run) nor the box's points (fewer than min_points) have shown it for
        /// hide_unseen_frames steps, it leaves the boxes and the mask: a walker who left
        /// the view, or a box over a textureless floor, would otherwise be masked forever.
        /// It is remembered until forget_unseen_frames such steps, so a walker who comes
        /// back is matched and masked at once. 0 = never hidden or forgotten.
        int hide_unseen_frames = 5;
        int forget_unseen_frames = 30;  ///< must be >= hide_unseen_frames
        /// boxes within mask_margin of the left or right image border are never unseen:
        /// walkers leave and come back there, and one cut by the border is often both
        /// undetected and without points (the bottom border cuts every near person's box)
        bool keep_border_tracks = true;
        /// detections scoring below this only continue existing tracks (matched after the
        /// confident ones) and never start one; with the detector's conf_threshold below
        /// it, a person the detector grows unsure of stays tracked. 0 = every detection.
        double new_track_score = 0.0;

        // Mask
        int mask_margin = 10;  ///< [px] dilation of each masked box
        /// mode dynamic: also mask boxes whose state is still Unknown (a person first seen,
        /// no flow evidence yet). Unmasked, such a person enters the map for the frames the
        /// evidence takes and corrupts it if they walk.
        bool mask_unknown = true;
        /// with mask_unknown, also mask the Unknown boxes of a frame with no previous frame
        /// (the first, and the first after reset()). No box can have evidence there, so
        /// this masks every person, seated ones too, in the frame the SLAM builds its
        /// first keyframe from. Off by default (docs/dynamic.md, session 11).
        bool mask_unknown_first_frame = false;
        /// Mode dynamic, a frame with no previous one: the Unknown boxes left unmasked there
        /// (mask_unknown_first_frame off) get what the boxes of people judged Static get:
        /// static_person_weight, and the static_person_outline band, which needs no
        /// static_person_outline_after there (nobody can have been held Static yet). That is
        /// the frame the SLAM builds its first keyframe from; without this the people in it
        /// enter the map at full weight (docs/dynamic.md, "The first frame's people").
        bool first_frame_as_static = false;
        /// [px] a masked box edge (the box grown by mask_margin) this close to the image
        /// border is extended to it: a person cut off by the border is detected with a box
        /// that stops short of it, leaving a strip of the person unmasked. 0 snaps only an
        /// edge the margin takes past the border (the whole box is clipped there anyway).
        /// With mask_silhouette the silhouette may reach the border on a snapped side,
        /// through the person's pixels.
        int mask_border_snap = 0;
        /// false: the whole (dilated) box is masked, as in the paper. true: only the box's
        /// pixels within the person's depth band (silhouette_depth_band, else fg_depth_band,
        /// else 0.5 m) or without depth, dilated by mask_margin: the background seen inside
        /// the box stays usable. Falls back to the whole box when the torso has no depth.
        bool mask_silhouette = false;
        /// [m] the silhouette's depth band (+ silhouette_depth_slope x the person's depth)
        /// when > 0;
        /// 0 = fg_depth_band's. The evidence band wants to be wide (a near person's
        /// arms and back), the mask's narrow (the background right behind a person
        /// keeps its features).
        double silhouette_depth_band = 0.0;
        /// With mask_silhouette: the silhouette may reach beyond the box by this fraction
        /// of the box's height (top and bottom) and width (sides), through pixels of the
        /// person's depth band (or without depth) connected to the silhouette inside the
        /// box. A detector's box often stops short of the head or a hand; 0 = the box only.
        double silhouette_grow = 0.0;
        /// The silhouette band's growth with the person's depth: its half-width is
        /// silhouette_depth_band (or its fallbacks) + this x the person's depth (the
        /// evidence band, fg_depth_band, keeps 0.1). A far person's band at 0.1 reached the
        /// wall behind them (docs/dynamic.md, "The silhouette band's slope").
        double silhouette_depth_slope = 0.1;
        /// In (0, 1]: the SLAM's weight for keypoints inside the boxes of people judged
        /// Static (FilterOutput::static_people, mode Dynamic only; devslam-run multiplies
        /// their 1/sigma^2 in tracking, relocalisation, loop checks and local bundle
        /// adjustment by it). The filter does not use it. A seated person who sways or
        /// gestures is not masked, yet their corners move a little; a weight below 1 keeps
        /// them as structure while the background counts more. 1 = like any other keypoint
        /// (docs/dynamic.md, "Weighing seated people down", measures 0.25 and 0.5).
        double static_person_weight = 1.0;
        /// What static_person_weight w does to those keypoints' outlier tests in the SLAM
        /// (slam::FrameFeatures::gate_exponent): 1 (INI `wider`) widens their chi2 gate by
        /// 1/sqrt(w), as for a noisier measurement; 0 (`same`) keeps it; -1 (`narrower`)
        /// narrows it by sqrt(w): a sitter's corner that drifted with the sway is dropped
        /// sooner (docs/dynamic.md, "The weight in the chi2 tests"). Only -1, 0 and 1.
        double static_person_gate = 1.0;
        /// [px] In mode Dynamic, the pixels within this distance of the outline of a person
        /// judged Static are masked, on both sides, where that outline is a depth edge (the
        /// silhouette as mask_silhouette finds it, in the box grown by silhouette_grow; the
        /// person's inside stays unmasked, and so does a box on a flat wall). A swaying
        /// sitter's outline is where their motion shows most and where the wall behind them
        /// is covered and uncovered: corners there are not points of the scene. The person's
        /// depth is measured for it (a box without one: nothing masked). 0 = off.
        int static_person_outline = 0;
        /// [steps] static_person_outline acts on a person from their this-many-th
        /// consecutive step in state Static on: a seated person, not a walker the filter
        /// holds Static for a while (at a border, coming at the camera). 0 or 1 = from
        /// their first Static step.
        int static_person_outline_after = 0;

        /// Reads `[section]`; unknown keys throw std::invalid_argument naming them.
        void loadFromConfig(const mrpt::config::CConfigFileBase& cfg,
                            const std::string& section = "dynamic_filter");
        /// Throws std::invalid_argument "[section] key: must be ..." for the first value out
        /// of range (loadFromConfig and the filter's constructor call it).
        void validate(const std::string& section = "dynamic_filter") const;
        /// The smallest frame side the flow can run on: lk_window at flow_scale, in full
        /// image pixels (MaskMode::None needs none).
        [[nodiscard]] int minFrameSide() const;
        void saveToConfig(mrpt::config::CConfigFileBase& cfg,
                          const std::string& section = "dynamic_filter") const;
    };

    /// `detector` may be null only for MaskMode::None (std::invalid_argument otherwise).
    DynamicObjectFilter(const Options& opts, std::unique_ptr<detect::PersonDetector> detector);
    ~DynamicObjectFilter();
    DynamicObjectFilter(const DynamicObjectFilter&) = delete;
    DynamicObjectFilter& operator=(const DynamicObjectFilter&) = delete;

    /// Processes the next frame. `T_prev_cur_prior`: pose of the current camera in the
    /// previous camera's optical frame (p_prev = T * p_cur), e.g. the tracker's
    /// constant-velocity prediction; nullopt = unknown (identity, refined on background).
    /// Throws std::invalid_argument for a frame that is not CV_8UC3 + CV_32FC1 of equal size.
    [[nodiscard]] FilterOutput step(const core::Frame& frame,
                                    const std::optional<Eigen::Isometry3d>& T_prev_cur_prior);

    [[nodiscard]] const Options& options() const { return opts_; }
    /// Forgets all tracks and the previous frame (e.g. after tracking is lost); later tracks
    /// get new ids, never an earlier track's.
    void reset();

  private:
    struct Impl;
    Options opts_;
    std::unique_ptr<detect::PersonDetector> detector_;
    std::unique_ptr<Impl> impl_;
};

/// Builds detector + filter from one INI (sections [detector] and [dynamic_filter]).
/// `mode_override` replaces the INI's mode (e.g. from a command-line flag). In mode None the
/// detector is built (its section, names and files checked) and dropped: the filter has none.
[[nodiscard]] std::unique_ptr<DynamicObjectFilter> makeFilterFromConfig(
    const mrpt::config::CConfigFileBase& cfg, std::optional<MaskMode> mode_override = {});

}  // namespace devslam::dynamic
