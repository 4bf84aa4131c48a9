#pragma once
/// OpenCV's built-in HOG + linear SVM people detector (Dalal & Triggs 2005): the fallback
/// when no network model is available. Needs no file; slower and less accurate than YOLO.
///
/// Usage:
///   HogDetector det({});
///   auto people = det.detect(bgr);
#include <devslam/detect/PersonDetector.h>

#include <opencv2/objdetect.hpp>

namespace devslam::detect {

class HogDetector final : public PersonDetector {
  public:
    struct Options {
        double hit_threshold = 0.0;  ///< SVM margin a window needs
        int win_stride = 8;          ///< [px] window step
        double scale = 1.05;         ///< pyramid scale step
        int group_threshold = 2;     ///< min overlapping windows to keep a group
        double min_score = 0.65;     ///< [0, 1] min reported score (logistic of the SVM weight)
        double resize = 1.0;         ///< image scale before detection (people >= ~128/resize px)

        void loadFromConfig(const mrpt::config::CConfigFileBase& cfg, const std::string& section);
        void saveToConfig(mrpt::config::CConfigFileBase& cfg, const std::string& section) const;
    };
    explicit HogDetector(const Options& opts);
    [[nodiscard]] std::vector<Detection> detect(const cv::Mat& bgr) override;
    [[nodiscard]] std::string name() const override;

  private:
    Options opts_;
    cv::HOGDescriptor hog_;
};

}  // namespace devslam::detect
