#include <devslam/core/Config.h>
#include <devslam/slam/OrbExtractor.h>

#include <mrpt/config/CConfigFileBase.h>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

namespace devslam::slam {

void OrbExtractor::Options::loadFromConfig(const mrpt::config::CConfigFileBase& c,
                                           const std::string& s) {
    core::requireKnownKeys(
        c, s,
        {"n_features", "scale_factor", "n_levels", "fast_threshold", "min_fast_threshold",
         "oversample", "grid_cols", "grid_rows", "min_depth", "max_depth", "depth_factor",
         "detect_outside_mask", "depth_edge_threshold"});
    n_features = core::readInt(c, s, "n_features", n_features);
    scale_factor = core::readDouble(c, s, "scale_factor", scale_factor);
    n_levels = core::readInt(c, s, "n_levels", n_levels);
    fast_threshold = core::readInt(c, s, "fast_threshold", fast_threshold);
    min_fast_threshold = core::readInt(c, s, "min_fast_threshold", min_fast_threshold);
    oversample = core::readDouble(c, s, "oversample", oversample);
    detect_outside_mask = core::readBool(c, s, "detect_outside_mask", detect_outside_mask);
    depth_edge_threshold = core::readDouble(c, s, "depth_edge_threshold", depth_edge_threshold);
    core::requireValue(depth_edge_threshold >= 0, s, "depth_edge_threshold", "must be >= 0");
    grid_cols = core::readInt(c, s, "grid_cols", grid_cols);
    grid_rows = core::readInt(c, s, "grid_rows", grid_rows);
    min_depth = core::readDouble(c, s, "min_depth", min_depth);
    max_depth = core::readDouble(c, s, "max_depth", max_depth);
    depth_factor = core::readDouble(c, s, "depth_factor", depth_factor);
    core::requireValue(depth_factor > 0.5 && depth_factor < 2.0, s, "depth_factor",
                       "must be in (0.5, 2)");
    // Upper bounds too: 1e9 features, levels or grid cells ran out of memory, crashed
    // (grid_cols) or ran for minutes per frame instead of saying which key was wrong.
    core::requireValue(n_features > 0 && n_features <= 100000, s, "n_features",
                       "must be in [1, 100000]");
    core::requireValue(scale_factor > 1.0 && scale_factor <= 4.0, s, "scale_factor",
                       "must be in (1, 4]");
    core::requireValue(n_levels >= 1 && n_levels <= 32, s, "n_levels", "must be in [1, 32]");
    core::requireValue(std::pow(scale_factor, n_levels - 1) <= 64.0, s, "n_levels",
                       "with this scale_factor the coarsest level would be under 1/64 of the "
                       "image (scale_factor^(n_levels-1) must be <= 64)");
    core::requireValue(oversample >= 1.0 && oversample <= 10.0, s, "oversample",
                       "must be in [1, 10]");
    core::requireValue(fast_threshold >= 1 && fast_threshold <= 255, s, "fast_threshold",
                       "must be in [1, 255] (grey levels)");
    core::requireValue(min_fast_threshold >= 1 && min_fast_threshold <= fast_threshold, s,
                       "min_fast_threshold", "must be in [1, fast_threshold]");
    core::requireValue(grid_cols >= 1 && grid_rows >= 1 && grid_cols <= 200 && grid_rows <= 200,
                       s, "grid_cols/grid_rows", "must be in [1, 200]");
    core::requireValue(max_depth > min_depth && min_depth >= 0, s, "min_depth/max_depth",
                       "need 0 <= min_depth < max_depth");
}

void OrbExtractor::Options::saveToConfig(mrpt::config::CConfigFileBase& c,
                                         const std::string& s) const {
    core::writeKey(c, s, "n_features", n_features);
    core::writeKey(c, s, "scale_factor", scale_factor);
    core::writeKey(c, s, "n_levels", n_levels);
    core::writeKey(c, s, "fast_threshold", fast_threshold);
    core::writeKey(c, s, "min_fast_threshold", min_fast_threshold);
    core::writeKey(c, s, "oversample", oversample);
    core::writeKey(c, s, "detect_outside_mask", detect_outside_mask);
    core::writeKey(c, s, "depth_edge_threshold", depth_edge_threshold);
    core::writeKey(c, s, "grid_cols", grid_cols);
    core::writeKey(c, s, "grid_rows", grid_rows);
    core::writeKey(c, s, "min_depth", min_depth);
    core::writeKey(c, s, "max_depth", max_depth);
    core::writeKey(c, s, "depth_factor", depth_factor);
}

OrbExtractor::OrbExtractor(const Options& opts) : opts_(opts) {
    const int n = static_cast<int>(opts_.n_features * opts_.oversample);
    orb_ = cv::ORB::create(n, static_cast<float>(opts_.scale_factor), opts_.n_levels, 19, 0, 2,
                           cv::ORB::HARRIS_SCORE, 31, opts_.fast_threshold);
    orb_low_ = cv::ORB::create(n, static_cast<float>(opts_.scale_factor), opts_.n_levels, 19, 0, 2,
                               cv::ORB::HARRIS_SCORE, 31, opts_.min_fast_threshold);
}

std::vector<int> spreadOverGrid(const std::vector<cv::KeyPoint>& kps, cv::Size image, int cols,
                                int rows, int n) {
    std::vector<int> order(kps.size());
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(),
                     [&](int a, int b) { return kps[a].response > kps[b].response; });
    if (static_cast<int>(kps.size()) <= n) {
        std::sort(order.begin(), order.end());
        return order;
    }
    const int per_cell = std::max(1, n / (cols * rows));
    std::vector<int> count(static_cast<std::size_t>(cols * rows), 0);
    std::vector<char> taken(kps.size(), 0);
    std::vector<int> out;
    out.reserve(n);
    for (int i : order) {
        const int cx = std::clamp(static_cast<int>(kps[i].pt.x * cols / image.width), 0, cols - 1);
        const int cy = std::clamp(static_cast<int>(kps[i].pt.y * rows / image.height), 0, rows - 1);
        int& c = count[cy * cols + cx];
        if (c < per_cell && static_cast<int>(out.size()) < n) {
            ++c;
            taken[i] = 1;
            out.push_back(i);
        }
    }
    for (int i : order) {
        if (static_cast<int>(out.size()) >= n) break;
        if (!taken[i]) out.push_back(i);
    }
    std::sort(out.begin(), out.end());
    return out;
}

/// True when the valid depths of the 5x5 window around (u, v) spread more than
/// `threshold` times the centre depth (an occlusion edge).
static bool onDepthEdge(const cv::Mat& depth, int u, int v, double threshold) {
    constexpr int r = 2;
    if (u < r || v < r || u >= depth.cols - r || v >= depth.rows - r) return true;
    const float zc = depth.at<float>(v, u);
    float lo = zc, hi = zc;
    for (int dv = -r; dv <= r; ++dv) {
        const float* row = depth.ptr<float>(v + dv);
        for (int du = -r; du <= r; ++du) {
            const float z = row[u + du];
            if (!(z > 0.f)) continue;  // holes: Kinect shadows, not evidence either way
            lo = std::min(lo, z);
            hi = std::max(hi, z);
        }
    }
    return hi - lo > threshold * zc;
}

void undistortKeypoints(FrameFeatures& f, const core::CameraIntrinsics& K) {
    if (!K.distorted() || f.keypoints.empty()) return;
    std::vector<cv::Point2f> in(f.keypoints.size());
    for (std::size_t i = 0; i < in.size(); ++i) in[i] = f.keypoints[i].pt;
    const std::vector<cv::Point2f> out = core::undistortPixels(in, K);
    f.image_pt = in;
    for (std::size_t i = 0; i < in.size(); ++i) {
        f.keypoints[i].pt = out[i];
        if (f.depth[i] > 0) f.points_c[i] = core::backproject(out[i].x, out[i].y, f.depth[i], K);
    }
}

FrameFeatures OrbExtractor::extract(const core::Frame& frame, const cv::Mat& mask) const {
    if (!mask.empty() && (mask.type() != CV_8UC1 || mask.size() != frame.bgr.size()))
        throw std::invalid_argument("orb extractor: mask must be CV_8UC1 of the frame size");
    FrameFeatures f;
    if (frame.bgr.empty()) return f;
    // cv::ORB scales level l to cvRound(side / scale_factor^l) px and asserts inside
    // cv::resize when that is 0 (a 1x1 frame): refused here, naming the frame.
    const int side = std::min(frame.bgr.cols, frame.bgr.rows);
    if (cvRound(side / std::pow(opts_.scale_factor, opts_.n_levels - 1)) < 1)
        throw std::invalid_argument(
            "orb extractor: frame " + std::to_string(frame.index) +
            (frame.rgb_source.empty() ? std::string() : " (" + frame.rgb_source + ")") + " is " +
            std::to_string(frame.bgr.cols) + "x" + std::to_string(frame.bgr.rows) +
            " px, too small for the ORB pyramid's " + std::to_string(opts_.n_levels) +
            " levels ([orb] n_levels, scale_factor): its last level would have no pixel");
    cv::Mat gray;
    cv::cvtColor(frame.bgr, gray, cv::COLOR_BGR2GRAY);
    std::vector<cv::KeyPoint> kps;
    cv::Mat desc;
    cv::Mat allowed;  // ORB's mask: non-zero = detect here
    if (!mask.empty()) {
        f.masked_fraction = cv::countNonZero(mask) / static_cast<double>(mask.total());
        if (opts_.detect_outside_mask) allowed = mask == 0;
    }
    orb_->detectAndCompute(gray, allowed, kps, desc);
    if (static_cast<int>(kps.size()) < opts_.n_features / 2) {
        kps.clear();
        orb_low_->detectAndCompute(gray, allowed, kps, desc);
    }
    // Drop keypoints in the dynamic mask (after detection, so the count is reported).
    std::vector<int> keep_idx;
    keep_idx.reserve(kps.size());
    std::vector<cv::KeyPoint> unmasked;
    unmasked.reserve(kps.size());
    for (int i = 0; i < static_cast<int>(kps.size()); ++i) {
        const int u = std::clamp(cvRound(kps[i].pt.x), 0, gray.cols - 1);
        const int v = std::clamp(cvRound(kps[i].pt.y), 0, gray.rows - 1);
        if (!mask.empty() && mask.at<uchar>(v, u) != 0) {
            ++f.n_masked;
            continue;
        }
        keep_idx.push_back(i);
        unmasked.push_back(kps[i]);
    }
    const auto sel =
        spreadOverGrid(unmasked, gray.size(), opts_.grid_cols, opts_.grid_rows, opts_.n_features);
    f.keypoints.reserve(sel.size());
    f.descriptors.create(static_cast<int>(sel.size()), 32, CV_8U);
    f.depth.reserve(sel.size());
    f.points_c.reserve(sel.size());
    f.colors.reserve(sel.size());
    const bool has_depth = !frame.depth.empty() && frame.depth.size() == frame.bgr.size();
    for (std::size_t r = 0; r < sel.size(); ++r) {
        const int i = keep_idx[sel[r]];
        const cv::KeyPoint& kp = kps[i];
        f.keypoints.push_back(kp);
        desc.row(i).copyTo(f.descriptors.row(static_cast<int>(r)));
        const int u = std::clamp(cvRound(kp.pt.x), 0, gray.cols - 1);
        const int v = std::clamp(cvRound(kp.pt.y), 0, gray.rows - 1);
        float z = has_depth ? frame.depth.at<float>(v, u) : 0.f;
        z *= static_cast<float>(opts_.depth_factor);
        if (!(z >= opts_.min_depth && z <= opts_.max_depth)) z = 0.f;  // also rejects NaN
        if (z > 0.f && opts_.depth_edge_threshold > 0 &&
            onDepthEdge(frame.depth, u, v, opts_.depth_edge_threshold))
            z = 0.f;
        f.depth.push_back(z);
        f.points_c.push_back(z > 0 ? core::backproject(kp.pt.x, kp.pt.y, z, frame.K)
                                   : Eigen::Vector3d::Zero());
        f.colors.push_back(frame.bgr.at<cv::Vec3b>(v, u));
    }
    undistortKeypoints(f, frame.K);
    return f;
}

}  // namespace devslam::slam
