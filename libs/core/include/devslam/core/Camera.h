#pragma once
/// Pinhole camera intrinsics and the back-projection/projection math every stage shares.
///
/// Usage:
///   auto K = devslam::core::CameraIntrinsics::fromPreset("freiburg1");
///   Eigen::Vector3d p = devslam::core::backproject(320.0, 240.0, 1.5, K);
///   auto uv = devslam::core::project(p, K);   // std::nullopt behind the camera

#include <Eigen/Core>
#include <opencv2/core/types.hpp>

#include <array>
#include <optional>
#include <string>
#include <vector>

namespace mrpt::config {
class CConfigFileBase;
}
namespace mrpt::img {
class TCamera;
}

namespace devslam::core {

/// Pinhole intrinsics of a registered RGB-D camera (depth already aligned to colour).
struct CameraIntrinsics {
    double fx = 525.0;  ///< focal length along u [px]
    double fy = 525.0;  ///< focal length along v [px]
    double cx = 319.5;  ///< principal point u [px]
    double cy = 239.5;  ///< principal point v [px]
    int width = 640;    ///< image width [px]
    int height = 480;   ///< image height [px]
    /// Radial-tangential distortion k1 k2 p1 p2 k3 (OpenCV order). TUM images are used
    /// as published (not undistorted), like the TUM benchmark tools and ORB-SLAM do.
    std::array<double, 5> dist{0, 0, 0, 0, 0};

    /// Known presets: "freiburg1", "freiburg2", "freiburg3", "ros_default" (also "fr1".."fr3").
    /// Throws std::invalid_argument naming the preset and the known list.
    [[nodiscard]] static CameraIntrinsics fromPreset(const std::string& name);
    [[nodiscard]] static std::vector<std::string> presetNames();

    /// Reads `[section]`: either `preset = freiburg1`, or `fx fy cx cy` (required then),
    /// optional `width height` and `dist = [k1 k2 p1 p2 k3]`. Keys given beside a preset
    /// override it. Throws naming section and key on a missing or non-positive value.
    [[nodiscard]] static CameraIntrinsics fromConfig(const mrpt::config::CConfigFileBase& cfg,
                                                     const std::string& section);
    void saveToConfig(mrpt::config::CConfigFileBase& cfg, const std::string& section) const;

    /// The same camera at a resolution scaled by `s` (an image resized by `s`): pixel
    /// centres kept exact, cx' = (cx + 0.5) s - 0.5; width and height rounded. Distortion
    /// coefficients are unchanged (they act on normalised coordinates).
    [[nodiscard]] CameraIntrinsics scaled(double s) const;

    /// The 3x3 camera matrix.
    [[nodiscard]] Eigen::Matrix3d matrix() const;
    /// The same, for OpenCV's calib3d functions.
    [[nodiscard]] cv::Matx33d cvMatrix() const;
    /// As an MRPT camera model (for CObservation3DRangeScan).
    [[nodiscard]] mrpt::img::TCamera toMrpt() const;
    [[nodiscard]] static CameraIntrinsics fromMrpt(const mrpt::img::TCamera& cam);

    /// What makes these intrinsics unusable, or "" when nothing does: focal lengths finite and
    /// in [1, 1e5] px (0, inf or 1e-300 from a damaged file made the SLAM's grid map loop
    /// forever), a principal point finite and inside the image, a finite distortion.
    [[nodiscard]] std::string problem() const;

    /// True when a distortion coefficient is not zero.
    [[nodiscard]] bool distorted() const;

    bool operator==(const CameraIntrinsics& o) const;
};

/// Pixels of this camera to the pixels an undistorted camera with the same fx fy cx cy
/// would have seen them at (OpenCV's model, cv::undistortPoints): the pixels the pinhole
/// backproject() and project() are exact for. The input itself when !K.distorted().
[[nodiscard]] std::vector<cv::Point2f> undistortPixels(const std::vector<cv::Point2f>& px,
                                                       const CameraIntrinsics& K);

/// Pixel (u, v) with depth z [m] to a point in the optical frame (x right, y down, z forward).
[[nodiscard]] inline Eigen::Vector3d backproject(double u, double v, double z,
                                                 const CameraIntrinsics& K) {
    return {(u - K.cx) * z / K.fx, (v - K.cy) * z / K.fy, z};
}

/// Optical-frame point to pixel; std::nullopt when the point is not in front of the camera.
[[nodiscard]] inline std::optional<Eigen::Vector2d> project(const Eigen::Vector3d& p,
                                                            const CameraIntrinsics& K) {
    constexpr double kMinDepth = 1e-6;  // [m]
    if (p.z() <= kMinDepth) return std::nullopt;
    return Eigen::Vector2d{K.fx * p.x() / p.z() + K.cx, K.fy * p.y() / p.z() + K.cy};
}

}  // namespace devslam::core
