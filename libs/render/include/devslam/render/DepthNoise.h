#pragma once
/// Kinect-like degradation of a perfect depth image: missing values below the minimum and
/// beyond the maximum range and at depth discontinuities, random dropouts, axial noise
/// growing with range (Nguyen, Izadi, Lovell 2012: sigma(z) = a + b (z - 0.4)^2), and the
/// structured-light disparity quantization (1/8 px steps with focal f and baseline B).
/// Deterministic for a seed.
///
/// Usage:
///   devslam::render::DepthNoiseOptions o;
///   cv::Mat noisy = devslam::render::applyDepthNoise(clean, o, fx, seed);

#include <opencv2/core/mat.hpp>

#include <cstdint>
#include <string>

namespace mrpt::config {
class CConfigFileBase;
}

namespace devslam::render {

struct DepthNoiseOptions {
    bool enabled = true;      ///< false: the perfect depth is written as is
    double min_range = 0.4;   ///< closer than this is missing [m]
    double max_range = 5.0;   ///< farther than this is missing [m]
    double sigma_a = 0.0012;  ///< constant part of the axial noise std [m]
    double sigma_b = 0.0019;  ///< quadratic part: sigma += b (z - 0.4)^2 [1/m]
    double baseline = 0.075;  ///< projector-camera baseline for the disparity quantization [m]
    double disparity_step = 0.125;  ///< disparity quantum [px]; 0 = no quantization
    double edge_jump =
        0.05;             ///< a neighbour farther by this fraction of z marks a discontinuity [-]
    int edge_dilate = 1;  ///< pixels around a discontinuity that are also missing [px]
    double dropout = 0.002;  ///< probability of a random missing pixel [-]

    /// Reads `[section]` (all keys optional; unknown keys rejected; ranges checked).
    void loadFromConfig(const mrpt::config::CConfigFileBase& cfg, const std::string& section);
};

/// Returns the degraded copy of `depth` (CV_32FC1 metres, 0 = missing); `fx` [px] is the
/// focal length used by the disparity quantization. Same inputs and seed -> same output.
[[nodiscard]] cv::Mat applyDepthNoise(const cv::Mat& depth, const DepthNoiseOptions& o, double fx,
                                      std::uint64_t seed);

/// Standard deviation of the axial noise at range z [m].
[[nodiscard]] double depthSigma(const DepthNoiseOptions& o, double z);

}  // namespace devslam::render
