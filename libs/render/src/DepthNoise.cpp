#include <devslam/core/Config.h>
#include <devslam/render/DepthNoise.h>

#include <mrpt/config/CConfigFileBase.h>

#include <opencv2/imgproc.hpp>

#include <cmath>
#include <random>

namespace devslam::render {

void DepthNoiseOptions::loadFromConfig(const mrpt::config::CConfigFileBase& cfg,
                                       const std::string& s) {
    core::requireKnownKeys(cfg, s,
                           {"enabled", "min_range", "max_range", "sigma_a", "sigma_b", "baseline",
                            "disparity_step", "edge_jump", "edge_dilate", "dropout"});
    enabled = core::readBool(cfg, s, "enabled", enabled);
    min_range = core::readDouble(cfg, s, "min_range", min_range);
    max_range = core::readDouble(cfg, s, "max_range", max_range);
    sigma_a = core::readDouble(cfg, s, "sigma_a", sigma_a);
    sigma_b = core::readDouble(cfg, s, "sigma_b", sigma_b);
    baseline = core::readDouble(cfg, s, "baseline", baseline);
    disparity_step = core::readDouble(cfg, s, "disparity_step", disparity_step);
    edge_jump = core::readDouble(cfg, s, "edge_jump", edge_jump);
    edge_dilate = core::readInt(cfg, s, "edge_dilate", edge_dilate);
    dropout = core::readDouble(cfg, s, "dropout", dropout);
    core::requireValue(min_range >= 0, s, "min_range", "must be >= 0 [m]");
    core::requireValue(max_range > min_range, s, "max_range", "must be > min_range [m]");
    core::requireValue(sigma_a >= 0, s, "sigma_a", "must be >= 0");
    core::requireValue(sigma_b >= 0, s, "sigma_b", "must be >= 0");
    core::requireValue(baseline > 0, s, "baseline", "must be > 0 [m]");
    core::requireValue(disparity_step >= 0, s, "disparity_step", "must be >= 0 [px]");
    core::requireValue(edge_jump > 0, s, "edge_jump", "must be > 0");
    core::requireValue(edge_dilate >= 0 && edge_dilate <= 10, s, "edge_dilate",
                       "must be 0..10 [px]");
    core::requireValue(dropout >= 0 && dropout < 1, s, "dropout", "must be in [0, 1)");
}

double depthSigma(const DepthNoiseOptions& o, double z) {
    const double d = z - 0.4;
    return o.sigma_a + o.sigma_b * d * d;
}

cv::Mat applyDepthNoise(const cv::Mat& depth, const DepthNoiseOptions& o, double fx,
                        std::uint64_t seed) {
    CV_Assert(depth.type() == CV_32FC1);
    cv::Mat out = depth.clone();
    if (!o.enabled) return out;
    const int H = depth.rows, W = depth.cols;

    // Discontinuities: a 4-neighbour much farther or nearer (or missing) -> missing.
    cv::Mat edge(H, W, CV_8UC1, cv::Scalar(0));
    for (int v = 0; v < H; ++v)
        for (int u = 0; u < W; ++u) {
            const float z = depth.at<float>(v, u);
            if (z <= 0) continue;
            const int nu[4] = {u - 1, u + 1, u, u}, nv[4] = {v, v, v - 1, v + 1};
            for (int k = 0; k < 4; ++k) {
                if (nu[k] < 0 || nv[k] < 0 || nu[k] >= W || nv[k] >= H) continue;
                const float zn = depth.at<float>(nv[k], nu[k]);
                if (zn <= 0 || std::abs(zn - z) > o.edge_jump * z) {
                    edge.at<uchar>(v, u) = 255;
                    break;
                }
            }
        }
    if (o.edge_dilate > 0)
        cv::dilate(edge, edge,
                   cv::getStructuringElement(
                       cv::MORPH_RECT, cv::Size(2 * o.edge_dilate + 1, 2 * o.edge_dilate + 1)));

    std::mt19937_64 rng(seed);
    std::normal_distribution<double> gauss(0.0, 1.0);
    std::uniform_real_distribution<double> uni(0.0, 1.0);
    const double fb = fx * o.baseline;  // disparity = fb / z [px]
    for (int v = 0; v < H; ++v)
        for (int u = 0; u < W; ++u) {
            float& z = out.at<float>(v, u);
            // Draw both numbers for every pixel so the stream does not depend on the scene.
            const double n = gauss(rng), r = uni(rng);
            if (z <= 0) continue;
            if (z < o.min_range || z > o.max_range || edge.at<uchar>(v, u) || r < o.dropout) {
                z = 0.f;
                continue;
            }
            double zn = z + depthSigma(o, z) * n;
            if (o.disparity_step > 0 && zn > 0) {
                const double disp = std::round(fb / zn / o.disparity_step) * o.disparity_step;
                zn = disp > 0 ? fb / disp : 0.0;
            }
            z = (zn >= o.min_range && zn <= o.max_range) ? float(zn) : 0.f;
        }
    return out;
}

}  // namespace devslam::render
