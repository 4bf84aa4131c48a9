#pragma once
/// Person (potentially dynamic object) detection: one interface, two implementations
/// (YOLO through cv::dnn, OpenCV's HOG people detector), selected by name from INI.
///
/// Usage:
///   auto cfg = devslam::core::loadIni("config_ini/detector_yolo_fastest.ini");
///   auto det = devslam::detect::makeDetector(*cfg);            // section [detector]
///   for (const auto& d : det->detect(frame.bgr)) draw(d.box);  // person boxes only
#include <memory>
#include <opencv2/core/mat.hpp>
#include <opencv2/core/types.hpp>
#include <string>
#include <vector>

namespace mrpt::config {
class CConfigFileBase;
}

namespace devslam::detect {

/// One detected object, in pixels of the image passed to detect().
struct Detection {
    cv::Rect2f box;          ///< [px] top-left corner, width, height (clipped to the image)
    int class_id = -1;       ///< index in the model's class list (COCO: 0 = person)
    std::string class_name;  ///< e.g. "person"
    float score = 0.f;       ///< [0, 1] confidence (YOLO: objectness * class score)
};

/// A detector of potentially dynamic objects. Not thread-safe (cv::dnn nets are not).
class PersonDetector {
  public:
    virtual ~PersonDetector() = default;
    /// Detections of the classes configured as potentially dynamic only, best first.
    /// `bgr` is CV_8UC3 of any size; throws std::invalid_argument for another type.
    [[nodiscard]] virtual std::vector<Detection> detect(const cv::Mat& bgr) = 0;
    /// Short description for logs, e.g. "yolo(yolo-fastest-1.1-xl.cfg, 320x320)".
    [[nodiscard]] virtual std::string name() const = 0;
};

/// Names accepted by `detector = ...` in makeDetector(): {"yolo", "hog"}.
[[nodiscard]] std::vector<std::string> detectorNames();

/// Builds the detector selected by `detector = yolo | hog` in `[section]` and loads its
/// options from the same section (unknown keys rejected). An unknown name throws
/// std::invalid_argument listing the known names; a missing/corrupt model file throws
/// std::runtime_error naming the file.
[[nodiscard]] std::unique_ptr<PersonDetector> makeDetector(const mrpt::config::CConfigFileBase& cfg,
                                                           const std::string& section = "detector");

/// Intersection over union of two boxes (0 when either is empty).
[[nodiscard]] float iou(const cv::Rect2f& a, const cv::Rect2f& b);

}  // namespace devslam::detect
