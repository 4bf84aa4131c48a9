#include "devslam/core/Picture.h"

#include "devslam/core/Results.h"

#include <opencv2/imgcodecs.hpp>

#include <stdexcept>
#include <vector>

namespace devslam::core {

void writePngWhole(const std::string& path, const cv::Mat& image) {
    std::vector<uchar> png;
    bool encoded = false;
    try {
        encoded = !image.empty() && cv::imencode(".png", image, png);
    } catch (const cv::Exception&) {  // a channel count PNG does not hold (2, or over 4)
    }
    if (!encoded) throw std::runtime_error("cannot write '" + path + "': the PNG did not encode");
    writeFileWhole(path, std::string(png.begin(), png.end()));
}

cv::Mat readImage(const std::string& path, int flags, std::string& why) {
    why.clear();
    try {
        return cv::imread(path, flags);
    } catch (const cv::Exception& e) {
        std::string reason = e.err;  // the failed check, without OpenCV's file and line
        while (!reason.empty() && (reason.back() == '\n' || reason.back() == ' '))
            reason.pop_back();
        why = " (OpenCV: " + reason + ")";
        return {};
    }
}

}  // namespace devslam::core
