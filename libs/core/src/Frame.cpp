#include <devslam/core/Frame.h>

#include <opencv2/core.hpp>

#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace devslam::core {

cv::Mat Frame::rawDepth16() const {
    return rawDepth16(depth_scale);
}

cv::Mat Frame::rawDepth16(double units_per_metre) const {
    cv::Mat raw;
    // convertTo rounds to nearest and saturates, so a depth read from uint16 comes back exact.
    depth.convertTo(raw, CV_16U, units_per_metre);
    return raw;
}

void validateFrame(const Frame& f, const std::string& what) {
    auto fail = [&](const std::string& msg) { throw std::runtime_error(what + ": " + msg); };
    if (f.bgr.empty()) fail("colour image is empty");
    if (f.bgr.type() != CV_8UC3) fail("colour image must be 8-bit 3-channel (BGR)");
    if (f.depth.empty()) fail("depth image is empty");
    if (f.depth.type() != CV_32FC1) fail("depth must be float metres (CV_32FC1)");
    if (f.depth.size() != f.bgr.size())
        fail("depth is " + std::to_string(f.depth.cols) + "x" + std::to_string(f.depth.rows) +
             " but colour is " + std::to_string(f.bgr.cols) + "x" + std::to_string(f.bgr.rows));
    if (f.K.width != f.bgr.cols || f.K.height != f.bgr.rows)
        fail("intrinsics are for " + std::to_string(f.K.width) + "x" + std::to_string(f.K.height) +
             " but the image is " + std::to_string(f.bgr.cols) + "x" + std::to_string(f.bgr.rows));
    if (const std::string p = f.K.problem(); !p.empty()) fail("intrinsics: " + p);
    // inf: a rawlog's rangeUnits of 0 (every depth 0 m without a word before)
    if (!(f.depth_scale > 0 && std::isfinite(f.depth_scale)))
        fail("depth_scale must be finite and > 0 (a depth unit of 0 m?)");
}

void requireDepthFits16(const Frame& f, double units_per_metre, const std::string& what,
                        const std::string& format) {
    double max_depth = 0;
    cv::minMaxLoc(f.depth, nullptr, &max_depth);
    if (max_depth * units_per_metre <= 65535.5) return;  // (rounds to 65535 at most)
    char scale[96];
    std::snprintf(scale, sizeof scale, "16 bits at %g per metre: at most %.1f m", units_per_metre,
                  65535.0 / units_per_metre);
    throw std::runtime_error(what + ": depth " + std::to_string(max_depth) + " m does not fit " +
                             format + " (" + scale + ")");
}

}  // namespace devslam::core
