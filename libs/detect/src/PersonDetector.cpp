#include <devslam/detect/HogDetector.h>
#include <devslam/detect/PersonDetector.h>
#include <devslam/detect/YoloDetector.h>

#include <mrpt/config/CConfigFileBase.h>

#include <stdexcept>

namespace devslam::detect {

std::vector<std::string> detectorNames() {
    return {"yolo", "hog"};
}

std::unique_ptr<PersonDetector> makeDetector(const mrpt::config::CConfigFileBase& cfg,
                                             const std::string& section) {
    const std::string name = cfg.read_string(section, "detector", "yolo");
    if (name == "yolo") {
        YoloDetector::Options o;
        o.loadFromConfig(cfg, section);
        try {
            return std::make_unique<YoloDetector>(o);
        } catch (const std::invalid_argument& e) {  // an option: UnknownClass, conf_threshold
            throw std::invalid_argument("[" + section + "] " + e.what());
        } catch (const std::runtime_error& e) {  // a file it names: missing, or does not load
            throw std::runtime_error("[" + section + "] " + e.what());
        }
    }
    if (name == "hog") {
        HogDetector::Options o;
        o.loadFromConfig(cfg, section);
        return std::make_unique<HogDetector>(o);
    }
    std::string known;
    for (const auto& n : detectorNames()) known += (known.empty() ? "" : ", ") + n;
    throw std::invalid_argument("[" + section + "] detector: unknown detector '" + name +
                                "' (known: " + known + ")");
}

float iou(const cv::Rect2f& a, const cv::Rect2f& b) {
    const float inter = (a & b).area();
    const float uni = a.area() + b.area() - inter;
    return uni > 0.f ? inter / uni : 0.f;
}

}  // namespace devslam::detect
