#include <devslam/core/Camera.h>
#include <devslam/core/Config.h>
#include <devslam/core/Parse.h>

#include <mrpt/config/CConfigFileBase.h>
#include <mrpt/img/TCamera.h>
#include <opencv2/calib3d.hpp>

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>
#include <stdexcept>

namespace devslam::core {
namespace {

// Published calibrations of the TUM RGB-D benchmark
// (https://cvg.cit.tum.de/data/datasets/rgbd-dataset/file_formats#intrinsic_camera_calibration_of_the_kinect).
const std::map<std::string, CameraIntrinsics>& presets() {
    static const std::map<std::string, CameraIntrinsics> kPresets = [] {
        std::map<std::string, CameraIntrinsics> m;
        CameraIntrinsics fr1;
        fr1.fx = 517.3, fr1.fy = 516.5, fr1.cx = 318.6, fr1.cy = 255.3;
        fr1.dist = {0.2624, -0.9531, -0.0054, 0.0026, 1.1633};
        CameraIntrinsics fr2;
        fr2.fx = 520.9, fr2.fy = 521.0, fr2.cx = 325.1, fr2.cy = 249.7;
        fr2.dist = {0.2312, -0.7849, -0.0033, -0.0001, 0.9172};
        CameraIntrinsics fr3;  // fr3 images are already undistorted
        fr3.fx = 535.4, fr3.fy = 539.2, fr3.cx = 320.1, fr3.cy = 247.6;
        CameraIntrinsics ros;  // ROS / OpenNI default
        m["freiburg1"] = fr1;
        m["freiburg2"] = fr2;
        m["freiburg3"] = fr3;
        m["ros_default"] = ros;
        m["fr1"] = fr1;
        m["fr2"] = fr2;
        m["fr3"] = fr3;
        return m;
    }();
    return kPresets;
}

}  // namespace

std::vector<std::string> CameraIntrinsics::presetNames() {
    std::vector<std::string> names;
    for (const auto& [name, k] : presets()) names.push_back(name);
    return names;
}

CameraIntrinsics CameraIntrinsics::fromPreset(const std::string& name) {
    const auto it = presets().find(name);
    if (it == presets().end()) {
        std::string known;
        for (const auto& n : presetNames()) known += (known.empty() ? "" : ", ") + n;
        throw std::invalid_argument("unknown camera preset '" + name + "' (known: " + known + ")");
    }
    return it->second;
}

namespace {
/// A focal length in [1, 1e5] px: 0, inf or 1e-300 from a damaged file made the SLAM's grid map
/// loop forever.
bool usableFocal(double f) { return f >= 1.0 && f <= 1e5; }
/// A distortion coefficient in [-100, 100]: k1 = 1e6 folded every depth pixel out of the
/// colour image (a frame without depth, without a word); real lenses, fisheyes included, stay
/// well inside.
bool usableDistortion(double d) { return std::abs(d) <= 100; }
}  // namespace

std::string CameraIntrinsics::problem() const {
    const auto str = [](double v) {
        std::ostringstream o;
        o << v;
        return o.str();
    };
    if (!usableFocal(fx) || !usableFocal(fy))
        return "focal lengths fx " + str(fx) + ", fy " + str(fy) + " px: must be in [1, 1e5]";
    if (!(cx >= 0 && cx < width && cy >= 0 && cy < height))
        return "principal point (" + str(cx) + ", " + str(cy) + ") lies outside the " +
               std::to_string(width) + "x" + std::to_string(height) + " image";
    for (const double d : dist)
        if (!usableDistortion(d))
            return "a distortion coefficient is " + str(d) + ": must be in [-100, 100]";
    return {};
}

CameraIntrinsics CameraIntrinsics::fromConfig(const mrpt::config::CConfigFileBase& c,
                                              const std::string& s) {
    requireKnownKeys(c, s, {"preset", "fx", "fy", "cx", "cy", "width", "height", "dist"});
    CameraIntrinsics K;
    const std::string preset = c.read_string(s, "preset", "");
    const bool has_preset = !preset.empty();
    if (has_preset) {
        try {
            K = fromPreset(preset);
        } catch (const std::invalid_argument& e) {
            throw std::invalid_argument("[" + s + "] preset: " + e.what());
        }
    }
    K.fx = core::readDouble(c, s, "fx", K.fx, !has_preset);
    K.fy = core::readDouble(c, s, "fy", K.fy, !has_preset);
    K.cx = core::readDouble(c, s, "cx", K.cx, !has_preset);
    K.cy = core::readDouble(c, s, "cy", K.cy, !has_preset);
    K.width = core::readInt(c, s, "width", K.width);
    K.height = core::readInt(c, s, "height", K.height);
    // Not MRPT's read_vector: its std::stod says only "stod" for "0 x 0" and reads "0.1x" as 0.1.
    if (const auto dist_text = readTextIfPresent(c, s, "dist")) {
        const auto d = parseNumberList(*dist_text, "[" + s + "] dist");
        requireValue(d.size() == 5, s, "dist", "must have 5 values k1 k2 p1 p2 k3");
        // (a TUM folder's camera.ini with k1 = 1e9 was taken, and the run lost every frame
        // after the first without a word on the file)
        for (const double v : d)
            requireValue(usableDistortion(v), s, "dist",
                         "each coefficient must be in [-100, 100] (a real lens, a fisheye "
                         "too, stays well inside)");
        std::copy(d.begin(), d.end(), K.dist.begin());
    }
    requireValue(usableFocal(K.fx) && usableFocal(K.fy), s, "fx/fy", "must be in [1, 1e5] px");
    // An image buffer per frame (and the renderer's framebuffer) is width x height: 16000^2
    // took 8 GB before anything was drawn.
    requireValue(K.width > 0 && K.height > 0 && K.width <= 4096 && K.height <= 4096, s,
                 "width/height", "must be 1..4096 [px]");
    requireValue(K.cx >= 0 && K.cx < K.width && K.cy >= 0 && K.cy < K.height, s, "cx/cy",
                 "must lie inside the image");
    return K;
}

void CameraIntrinsics::saveToConfig(mrpt::config::CConfigFileBase& c, const std::string& s) const {
    core::writeKey(c, s, "fx", fx);
    core::writeKey(c, s, "fy", fy);
    core::writeKey(c, s, "cx", cx);
    core::writeKey(c, s, "cy", cy);
    core::writeKey(c, s, "width", width);
    core::writeKey(c, s, "height", height);
    core::writeKey(c, s, "dist", std::vector<double>(dist.begin(), dist.end()));
}

Eigen::Matrix3d CameraIntrinsics::matrix() const {
    Eigen::Matrix3d M;
    M << fx, 0, cx, 0, fy, cy, 0, 0, 1;
    return M;
}

cv::Matx33d CameraIntrinsics::cvMatrix() const {
    return {fx, 0, cx, 0, fy, cy, 0, 0, 1};
}

mrpt::img::TCamera CameraIntrinsics::toMrpt() const {
    mrpt::img::TCamera cam;
    cam.ncols = static_cast<uint32_t>(width);
    cam.nrows = static_cast<uint32_t>(height);
    cam.setIntrinsicParamsFromValues(fx, fy, cx, cy);
    cam.setDistortionPlumbBob(dist[0], dist[1], dist[2], dist[3], dist[4]);
    return cam;
}

CameraIntrinsics CameraIntrinsics::fromMrpt(const mrpt::img::TCamera& cam) {
    CameraIntrinsics K;
    K.fx = cam.fx();
    K.fy = cam.fy();
    K.cx = cam.cx();
    K.cy = cam.cy();
    K.width = static_cast<int>(cam.ncols);
    K.height = static_cast<int>(cam.nrows);
    K.dist = {cam.k1(), cam.k2(), cam.p1(), cam.p2(), cam.k3()};
    return K;
}

CameraIntrinsics CameraIntrinsics::scaled(double s) const {
    CameraIntrinsics o = *this;
    o.fx = fx * s;
    o.fy = fy * s;
    o.cx = (cx + 0.5) * s - 0.5;
    o.cy = (cy + 0.5) * s - 0.5;
    o.width = static_cast<int>(std::lround(width * s));
    o.height = static_cast<int>(std::lround(height * s));
    return o;
}

bool CameraIntrinsics::distorted() const {
    return std::any_of(dist.begin(), dist.end(), [](double d) { return d != 0.0; });
}

std::vector<cv::Point2f> undistortPixels(const std::vector<cv::Point2f>& px,
                                         const CameraIntrinsics& K) {
    if (!K.distorted() || px.empty()) return px;
    const cv::Matx33d Kc = K.cvMatrix();
    const cv::Mat D(1, 5, CV_64F, const_cast<double*>(K.dist.data()));
    std::vector<cv::Point2f> out;
    cv::undistortPoints(px, out, Kc, D, cv::noArray(), Kc);
    return out;
}

bool CameraIntrinsics::operator==(const CameraIntrinsics& o) const {
    return fx == o.fx && fy == o.fy && cx == o.cx && cy == o.cy && width == o.width &&
           height == o.height && dist == o.dist;
}

}  // namespace devslam::core
