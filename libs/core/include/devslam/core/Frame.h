#pragma once
/// One RGB-D frame, the unit of data that flows through the whole pipeline.
///
/// Usage:
///   devslam::core::Frame f = reader.next().value();
///   float z = f.depth.at<float>(v, u);   // metres, 0 = no measurement
///   if (f.hasDepth(u, v)) { ... }

#include <devslam/core/Camera.h>

#include <opencv2/core/mat.hpp>

#include <cstddef>
#include <optional>
#include <string>

namespace devslam::core {

struct Frame {
    std::size_t index = 0;   ///< 0-based position in its sequence
    double timestamp = 0.0;  ///< [s] (unix time for TUM and rawlogs)
    cv::Mat bgr;             ///< CV_8UC3, BGR like cv::imread
    cv::Mat depth;           ///< CV_32FC1 [m], registered to bgr, 0 = missing
    CameraIntrinsics K;      ///< intrinsics of bgr and depth
    /// Raw depth units per metre in the source (5000 for TUM PNGs, 1000 for OpenNI mm).
    /// Kept so that writers reproduce the source bit-exactly.
    double depth_scale = 5000.0;
    std::string rgb_source;    ///< where the colour image came from (for messages, converters)
    std::string depth_source;  ///< where the depth image came from
    /// [s] when the depth image was taken apart from the colour image (TUM: its depth.txt
    /// stamp, up to 20 ms off); unset when both share `timestamp` (rawlogs, renders).
    std::optional<double> depth_timestamp;

    [[nodiscard]] bool hasDepth(int u, int v) const {
        return u >= 0 && v >= 0 && u < depth.cols && v < depth.rows && depth.at<float>(v, u) > 0.f;
    }
    /// The depth as the source's raw 16-bit units (round(depth * depth_scale)).
    [[nodiscard]] cv::Mat rawDepth16() const;
    /// The depth as 16-bit units at another scale (round(depth * units_per_metre), saturated).
    [[nodiscard]] cv::Mat rawDepth16(double units_per_metre) const;
};

/// Checks the invariants above (types, equal sizes, intrinsics size); throws
/// std::runtime_error naming `what` (a file or frame) and the violated invariant.
void validateFrame(const Frame& f, const std::string& what);

/// Throws std::runtime_error naming `what` when a depth of `f` is beyond 16 bits at
/// `units_per_metre` (rawDepth16 would store it as 65535 units: a wall that is not there),
/// `format` naming what the depth goes into ("a TUM depth PNG").
void requireDepthFits16(const Frame& f, double units_per_metre, const std::string& what,
                        const std::string& format);

}  // namespace devslam::core
