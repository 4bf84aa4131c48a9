#include <devslam/detect/HogDetector.h>

#include <devslam/core/Config.h>

#include <mrpt/config/CConfigFileBase.h>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace devslam::detect {

void HogDetector::Options::loadFromConfig(const mrpt::config::CConfigFileBase& c,
                                          const std::string& s) {
    core::requireKnownKeys(c, s,
                           {"detector", "hit_threshold", "win_stride", "scale", "group_threshold",
                            "min_score", "resize"});
    hit_threshold = core::readDouble(c, s, "hit_threshold", hit_threshold);
    win_stride = core::readInt(c, s, "win_stride", win_stride);
    scale = core::readDouble(c, s, "scale", scale);
    group_threshold = core::readInt(c, s, "group_threshold", group_threshold);
    min_score = core::readDouble(c, s, "min_score", min_score);
    resize = core::readDouble(c, s, "resize", resize);
    // (1e9 left one window a frame, or one pyramid level: nobody found, no word)
    core::requireValue(win_stride > 0 && win_stride % 8 == 0 && win_stride <= 64, s,
                       "win_stride",
                       "must be a positive multiple of 8 (HOG cell size), at most 64 (the "
                       "window's width)");
    core::requireValue(scale > 1.0 && scale <= 2.0, s, "scale", "must be in (1, 2]");
    core::requireValue(group_threshold >= 0, s, "group_threshold", "must be >= 0");
    // A box's score is the logistic of its SVM margin, in (0, 1): 7 would drop every box.
    core::requireValue(min_score >= 0 && min_score <= 1, s, "min_score", "must be in [0, 1]");
    // A tiny scale leaves no image (cv::resize fails on an empty size); a large one grows it
    // by its square in memory and time. People must be ~128/resize px tall to be found.
    core::requireValue(resize >= 0.1 && resize <= 4.0, s, "resize", "must be in [0.1, 4]");
}

void HogDetector::Options::saveToConfig(mrpt::config::CConfigFileBase& c,
                                        const std::string& s) const {
    core::writeKey(c, s, "detector", std::string("hog"));
    core::writeKey(c, s, "hit_threshold", hit_threshold);
    core::writeKey(c, s, "win_stride", win_stride);
    core::writeKey(c, s, "scale", scale);
    core::writeKey(c, s, "group_threshold", group_threshold);
    core::writeKey(c, s, "min_score", min_score);
    core::writeKey(c, s, "resize", resize);
}

HogDetector::HogDetector(const Options& opts) : opts_(opts) {
    hog_.setSVMDetector(cv::HOGDescriptor::getDefaultPeopleDetector());
}

std::string HogDetector::name() const {
    return "hog(default people SVM)";
}

std::vector<Detection> HogDetector::detect(const cv::Mat& bgr) {
    if (bgr.empty() || bgr.type() != CV_8UC3)
        throw std::invalid_argument("hog: detect() needs a non-empty CV_8UC3 image");
    // An image smaller than the SVM's window holds no person it can find, and OpenCV's
    // detectMultiScale does not check: it scans a negative window count and reads out of
    // bounds (a segfault on a 200x100 image, or at resize 0.2 on 640x480).
    const cv::Size scaled(cvRound(bgr.cols * opts_.resize), cvRound(bgr.rows * opts_.resize));
    if (scaled.width < hog_.winSize.width || scaled.height < hog_.winSize.height) {
        // ... but a frame the window fits that `resize` shrinks under it is a setting that
        // finds nobody in any frame (resize 0.2 on 640x480 ran, "detect 0.0 ms", no box).
        if (opts_.resize < 1.0 && bgr.cols >= hog_.winSize.width &&
            bgr.rows >= hog_.winSize.height) {
            std::ostringstream m;
            m << "[detector] resize: " << opts_.resize << " makes a " << bgr.cols << "x"
              << bgr.rows << " frame " << scaled.width << "x" << scaled.height
              << " px, smaller than HOG's " << hog_.winSize.width << "x" << hog_.winSize.height
              << " window: no person could be found; raise it";
            throw std::invalid_argument(m.str());
        }
        return {};
    }
    cv::Mat img = bgr;
    if (opts_.resize != 1.0) cv::resize(bgr, img, scaled);
    std::vector<cv::Rect> rects;
    std::vector<double> weights;
    hog_.detectMultiScale(img, rects, weights, opts_.hit_threshold,
                          cv::Size(opts_.win_stride, opts_.win_stride), cv::Size(), opts_.scale,
                          opts_.group_threshold);
    std::vector<Detection> dets;
    const cv::Rect2f image(0.f, 0.f, static_cast<float>(bgr.cols), static_cast<float>(bgr.rows));
    for (std::size_t i = 0; i < rects.size(); ++i) {
        const double w = i < weights.size() ? weights[i] : 0.0;
        const float score = static_cast<float>(1.0 / (1.0 + std::exp(-w)));
        if (score < opts_.min_score) continue;
        // The default SVM's 64x128 window has ~16 px of margin around the person at each
        // side; shrink it towards the body like a YOLO box: by 15 % of the width and 6 % of
        // the height at each side (about 10 and 8 px of the window: a box that errs large).
        const auto s = static_cast<float>(1.0 / opts_.resize);
        cv::Rect2f b(rects[i].x * s, rects[i].y * s, rects[i].width * s, rects[i].height * s);
        const float mx = 0.15f * b.width, my = 0.06f * b.height;
        b = cv::Rect2f(b.x + mx, b.y + my, b.width - 2 * mx, b.height - 2 * my) & image;
        if (b.area() <= 0.f) continue;
        dets.push_back({b, 0, "person", score});
    }
    std::sort(dets.begin(), dets.end(),
              [](const Detection& a, const Detection& b) { return a.score > b.score; });
    return dets;
}

}  // namespace devslam::detect
