#pragma once
/// Plain data shared by the SLAM stages: ids, extracted frame features, keyframes and
/// landmarks. Poses are T_wc (camera optical frame -> world, p_w = T_wc * p_c); the world
/// frame is the optical frame of the first keyframe (x right, y down, z forward).
#include <Eigen/Geometry>
#include <opencv2/core/mat.hpp>
#include <opencv2/core/types.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <vector>

namespace devslam::slam {

using KeyframeId = std::int64_t;  ///< strong-ish id, never reused; -1 = none
using LandmarkId = std::int64_t;  ///< never reused; -1 = none
constexpr std::int64_t kNoId = -1;

/// ORB features of one frame with their depth (see OrbExtractor).
struct FrameFeatures {
    std::vector<cv::KeyPoint> keypoints;    ///< [px], octave = pyramid level
    cv::Mat descriptors;                    ///< CV_8U, one 32-byte row per keypoint
    std::vector<float> depth;               ///< [m] per keypoint, 0 = none (missing/out of range)
    std::vector<Eigen::Vector3d> points_c;  ///< back-projected point [m] (valid iff depth > 0)
    std::vector<cv::Vec3b> colors;          ///< BGR at the keypoint
    /// [px] each keypoint where the image shows it, when undistortKeypoints moved the
    /// keypoints (a camera with distortion); empty: keypoints[i].pt. Image regions (the
    /// filter's, in weighWhere) are looked up here.
    std::vector<cv::Point2f> image_pt;
    int n_masked = 0;            ///< keypoints dropped because they fell in the dynamic mask
    double masked_fraction = 0;  ///< fraction of the image covered by the dynamic mask
    /// Per keypoint, multiplies its information (1/sigma^2) in the optimisations of tracking,
    /// relocalisation, loop checks and bundle adjustment; empty: all 1 (devslam-run gives
    /// keypoints on people the filter judged static a lower weight when [dynamic_filter]
    /// static_person_weight < 1). What it does to their outlier tests: gate_exponent.
    std::vector<float> weight;
    /// How a weight w acts on the chi2 tests (and Huber corners), which see w^p / sigma^2:
    /// p = 1, as a noisier measurement: the gate in pixels widens by 1/sqrt(w); p = 0, as
    /// any keypoint; p = -1, as a suspect: it narrows by sqrt(w). In the optimisation the
    /// information is w / sigma^2 whatever p ([dynamic_filter] static_person_gate).
    double gate_exponent = 1.0;
    [[nodiscard]] std::size_t size() const { return keypoints.size(); }
    /// Lowers the weight of the keypoints where `where` (CV_8UC1, the frame's size) is set
    /// to `w` (a lower weight already there is kept); the first call sets every other
    /// weight to 1. Throws std::invalid_argument for another type; a keypoint outside
    /// `where` keeps its weight. `where` is in the image's pixels (image_pt).
    void weighWhere(const cv::Mat& where, float w) {
        if (where.type() != CV_8UC1)
            throw std::invalid_argument("FrameFeatures::weighWhere: the region must be CV_8UC1");
        if (weight.empty()) weight.assign(keypoints.size(), 1.f);
        for (std::size_t i = 0; i < keypoints.size(); ++i) {
            const cv::Point2f& pt = image_pt.empty() ? keypoints[i].pt : image_pt[i];
            const int x = static_cast<int>(pt.x);
            const int y = static_cast<int>(pt.y);
            if (x >= 0 && y >= 0 && x < where.cols && y < where.rows &&
                where.at<unsigned char>(y, x) != 0)
                weight[i] = std::min(weight[i], w);
        }
    }
    /// The information the outlier tests see for keypoint i: w^p / sigma^2 (sigma =
    /// scale_factor^octave px, w its weight, p gate_exponent). PoseObservation::inv_sigma2.
    [[nodiscard]] double information(std::size_t i, double scale_factor) const {
        const double s = std::pow(scale_factor, keypoints[i].octave);
        if (weight.empty() || gate_exponent == 1.0)  // w / sigma^2, as before p existed
            return (weight.empty() ? 1.0 : static_cast<double>(weight[i])) / (s * s);
        return std::pow(static_cast<double>(weight[i]), gate_exponent) / (s * s);
    }
    /// What multiplies information(i) in the optimisations, so that they see w / sigma^2:
    /// w^(1 - p) (1 with p = 1 or no weights). PoseObservation::weight.
    [[nodiscard]] double weightOf(std::size_t i) const {
        if (weight.empty() || gate_exponent == 1.0) return 1.0;
        return std::pow(static_cast<double>(weight[i]), 1.0 - gate_exponent);
    }
};

/// A keyframe: a frame kept in the map, with the landmark each keypoint observes.
struct Keyframe {
    KeyframeId id = kNoId;
    std::size_t frame_index = 0;  ///< index of the source frame
    double timestamp = 0.0;       ///< [s]
    Eigen::Isometry3d T_wc = Eigen::Isometry3d::Identity();
    FrameFeatures features;
    std::vector<LandmarkId> landmark_of_kp;  ///< per keypoint, kNoId = none
};

/// A 3D point of the map.
struct Landmark {
    LandmarkId id = kNoId;
    Eigen::Vector3d p_w = Eigen::Vector3d::Zero();  ///< [m] world
    cv::Mat descriptor;                             ///< 1x32 CV_8U (of the reference observation)
    cv::Vec3b color{0, 0, 0};                       ///< BGR
    /// The keyframe its position moves with when a loop corrects the keyframes: the one
    /// that created it, or, once that one is culled, its oldest remaining observer.
    KeyframeId ref_kf = kNoId;
    KeyframeId created_kf = kNoId;  ///< keyframe that created it (its age; may be culled)
    int n_visible = 0;                              ///< times it projected inside a tracked frame
    int n_found = 0;  ///< times it was matched (inlier) in a tracked frame
    std::vector<std::pair<KeyframeId, int>> observations;  ///< (keyframe, keypoint index)
};

}  // namespace devslam::slam
