#pragma once
/// YOLO through OpenCV's cv::dnn: darknet .cfg + .weights (YOLOv3/v4/v4-tiny, Yolo-Fastest)
/// or an .onnx export (YOLOv5-style output). Output rows are decoded as
/// [cx, cy, w, h, objectness, class scores...]; boxes of the configured classes above
/// `conf_threshold` are kept after per-class NMS.
///
/// Usage:
///   YoloDetector::Options o;   // defaults: the shipped yolo-fastest-1.1-xl, class person
///   YoloDetector det(o);       // throws std::runtime_error naming a missing/corrupt file
///   auto people = det.detect(bgr);
#include <devslam/detect/PersonDetector.h>

#include <opencv2/dnn.hpp>

#include <stdexcept>

namespace devslam::detect {

class YoloDetector final : public PersonDetector {
  public:
    struct Options {
        /// Darknet .cfg or .onnx. Relative paths are tried from the working directory,
        /// then from the repository root.
        std::string model = "models/yolo-fastest-1.1/yolo-fastest-1.1-xl.cfg";
        std::string weights =
            "models/yolo-fastest-1.1/yolo-fastest-1.1-xl.weights";  ///< darknet only
        std::string names = "models/yolo-fastest-1.1/coco.names";   ///< one class name a line
        int input_width = 320;         ///< [px] network input (multiple of 32)
        int input_height = 320;        ///< [px]
        double conf_threshold = 0.35;  ///< min score (objectness * class score)
        double nms_threshold = 0.45;   ///< IoU above which the weaker box is suppressed
        std::vector<std::string> classes{"person"};  ///< classes reported (potentially dynamic)
        bool validate_on_load = true;  ///< two forward passes at load catch bad weights
        /// Depthwise and 1x1 convolutions by detect::withFastConvolutions (AVX2 kernels, same
        /// output to float rounding); false: all of them by OpenCV's own layer.
        bool fast_convolutions = true;

        /// Keys: model weights names input_width input_height conf_threshold nms_threshold
        /// classes (comma separated) validate_on_load fast_convolutions; unknown keys
        /// (besides `detector`) throw.
        void loadFromConfig(const mrpt::config::CConfigFileBase& cfg, const std::string& section);
        void saveToConfig(mrpt::config::CConfigFileBase& cfg, const std::string& section) const;
    };

    /// A class of Options::classes that the names file does not hold ("classes: 'persn' is
    /// not in '.../coco.names'"; makeDetector adds the INI section).
    struct UnknownClass : std::invalid_argument {
        using std::invalid_argument::invalid_argument;
    };

    /// Throws UnknownClass, or std::runtime_error for a model, weights or names file that is
    /// missing or does not load.
    explicit YoloDetector(const Options& opts);
    [[nodiscard]] std::vector<Detection> detect(const cv::Mat& bgr) override;
    [[nodiscard]] std::string name() const override;
    [[nodiscard]] const std::vector<std::string>& classNames() const { return names_; }

  private:
    Options opts_;
    cv::dnn::Net net_;
    bool onnx_ = false;
    std::vector<std::string> names_;
    std::vector<int> wanted_;  ///< class ids reported
    std::vector<std::string> out_names_;
};

/// Resolves a model path: as given if it exists, else relative to the repository root;
/// throws std::runtime_error naming every path tried when none exists.
[[nodiscard]] std::string resolveModelPath(const std::string& path, const std::string& what);

/// Darknet network from a .cfg alone (random weights), e.g. to check a cfg parses.
/// Throws std::runtime_error naming the file on a parse error.
[[nodiscard]] cv::dnn::Net readDarknetCfg(const std::string& cfg_path);

/// Throws std::runtime_error "darknet cfg '<path>' line N: [section] key: ..." for layer
/// references and sizes OpenCV's darknet reader does not check: a convolution's `groups`
/// below 1 (a floating-point exception, no message), a [route] `layers` or [shortcut] `from`
/// outside the layers before it (a bare vector::_M_range_check), a [yolo] `mask` index past
/// its anchors (read past the list: boxes of no anchor). Called before every darknet load.
void checkDarknetCfg(const std::string& cfg_path);

/// The lowest score a darknet cfg's network returns: the largest `thresh` of its [yolo]
/// layers (OpenCV's default 0.2 where one sets none), at or under which OpenCV zeroes every
/// class score; 0 for a cfg without [yolo] layers.
[[nodiscard]] float darknetScoreFloor(const std::string& cfg_path);

}  // namespace devslam::detect
