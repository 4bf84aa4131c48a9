#pragma once
/// Synthetic RGB-D sequences with exact truth for testing and benchmarking the filter:
/// a real photo textured on a tilted wall seen by a camera that translates and rotates,
/// and a real person photo pasted on a billboard that either walks across the scene,
/// stays fixed in the world, or is absent. Ray-cast per pixel, so depth is exact (plus
/// optional Kinect-like noise).
///
/// Usage:
///   SyntheticOptions o; o.person = PersonMotion::Walking;
///   auto seq = makeSyntheticSequence(o, wall_bgr, person_bgr);
///   for (auto& s : seq) filter.step(s.frame, s.T_prev_cur);
#include <devslam/core/Frame.h>

#include <Eigen/Geometry>
#include <opencv2/core/mat.hpp>
#include <optional>
#include <vector>

namespace devslam::dynamic {

enum class PersonMotion { None, Static, Walking };

/// The most frames makeSyntheticSequence makes: the whole sequence is held in memory.
inline constexpr int kMaxSyntheticFrames = 1000;

struct SyntheticOptions {
    int n_frames = 30;  ///< 1..kMaxSyntheticFrames
    PersonMotion person = PersonMotion::Walking;
    double person_speed = 1.2;  ///< [m/s] walking speed along person_direction
    /// walking direction in the world (= first camera) frame: x right, z forward; only its
    /// x and z are used (the billboard stays upright and faces the camera)
    Eigen::Vector3d person_direction{1.0, 0.0, 0.0};
    double person_height = 1.7;   ///< [m] billboard height (width from the photo's aspect)
    double person_depth = 2.2;    ///< [m] billboard distance from the first camera
    double person_x0 = -0.9;      ///< [m] billboard centre x at frame 0 (world = first camera)
    double wall_depth = 4.0;      ///< [m] wall distance at the image centre
    double wall_tilt_deg = 20.0;  ///< [deg] wall rotation about the vertical axis
    double fps = 30.0;            ///< [Hz]
    Eigen::Vector3d cam_velocity{0.45, -0.06, 0.15};  ///< [m/s] in the first camera frame
    Eigen::Vector3d cam_rate_deg{0.3, 15.0, 1.5};     ///< [deg/s] about x (pitch), y, z
    double image_noise = 2.0;                         ///< [grey levels] Gaussian std
    double depth_noise = 0.0015;                      ///< [1/m] depth noise std = depth_noise * z^2
    unsigned seed = 1;
};

struct SyntheticFrame {
    core::Frame frame;
    Eigen::Isometry3d T_w_c;               ///< true camera pose (world = first camera)
    Eigen::Isometry3d T_prev_cur;          ///< true relative pose (identity at frame 0)
    std::optional<cv::Rect2f> person_box;  ///< [px] true box of the billboard, if visible
};

/// Renders the sequence at 640x480 with fr1-like intrinsics. `wall_bgr` and `person_bgr`
/// are CV_8UC3 photos (the person photo is used whole as the billboard texture).
[[nodiscard]] std::vector<SyntheticFrame> makeSyntheticSequence(const SyntheticOptions& opts,
                                                                const cv::Mat& wall_bgr,
                                                                const cv::Mat& person_bgr);

}  // namespace devslam::dynamic
