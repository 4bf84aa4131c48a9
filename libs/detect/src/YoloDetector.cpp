#include <devslam/detect/YoloDetector.h>

#include <devslam/detect/FastConvolution.h>

#include <devslam/core/Config.h>
#include <devslam/core/Parse.h>

#include <mrpt/config/CConfigFileBase.h>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <tuple>

namespace devslam::detect {
namespace fs = std::filesystem;

namespace {

std::string trim(const std::string& s) {
    const auto b = s.find_first_not_of(" \t\r\n");
    if (b == std::string::npos) return {};
    const auto e = s.find_last_not_of(" \t\r\n");
    return s.substr(b, e - b + 1);
}

std::vector<std::string> splitList(const std::string& s) {
    std::vector<std::string> out;
    std::stringstream ss(s);
    std::string item;
    while (std::getline(ss, item, ',')) {
        item = trim(item);
        if (!item.empty()) out.push_back(item);
    }
    return out;
}

std::vector<std::string> readNames(const std::string& path) {
    if (fs::is_directory(path))
        throw std::runtime_error("yolo: class names file '" + path + "' is a folder");
    std::ifstream in(path);
    if (!in) throw std::runtime_error("yolo: cannot open class names file '" + path + "'");
    std::vector<std::string> names;
    std::string line;
    while (std::getline(in, line)) {
        line = trim(line);
        if (!line.empty()) names.push_back(line);
    }
    if (names.empty()) throw std::runtime_error("yolo: class names file '" + path + "' is empty");
    return names;
}

const std::vector<std::string> kYoloKeys{
    "detector",         "model",          "weights",       "names",   "input_width",
    "input_height",     "conf_threshold", "nms_threshold", "classes", "validate_on_load",
    "fast_convolutions"};
}  // namespace

std::string resolveModelPath(const std::string& path, const std::string& what) {
    if (path.empty()) throw std::runtime_error(what + ": no file given");
    if (fs::exists(path)) return path;
    std::string tried = "'" + path + "'";
#ifdef DEVSLAM_SOURCE_DIR
    if (fs::path(path).is_relative()) {
        const std::string alt = (fs::path(DEVSLAM_SOURCE_DIR) / path).string();
        if (fs::exists(alt)) return alt;
        tried += " and '" + alt + "'";
    }
#endif
    throw std::runtime_error(what + ": file not found (tried " + tried + ")");
}

namespace {
/// A darknet cfg's sections in order ([net] included), each with its keys: type, the line of
/// its header, and (key, value, line) per key; comments ('#', ';') and blanks dropped.
/// (Hand-written: OpenCV parses the cfg only inside readNetFromDarknet.)
struct CfgSection {
    std::string type;
    int line = 0;
    std::vector<std::tuple<std::string, std::string, int>> keys;
};

std::vector<CfgSection> readCfgSections(const std::string& cfg_path) {
    std::ifstream in(cfg_path);
    if (!in) throw std::runtime_error("cannot open darknet cfg '" + cfg_path + "'");
    std::vector<CfgSection> sections;
    int n = 0;
    for (std::string line; std::getline(in, line);) {
        ++n;
        line = trim(line.substr(0, line.find_first_of("#;")));
        if (line.empty()) continue;
        if (line.front() == '[')  // the type as OpenCV takes it: between the brackets, as is
            sections.push_back({line.substr(1, line.size() - 2), n, {}});
        else if (!sections.empty() && line.find('=') != std::string::npos)
            sections.back().keys.emplace_back(trim(line.substr(0, line.find('='))),
                                              trim(line.substr(line.find('=') + 1)), n);
    }
    return sections;
}
}  // namespace

float darknetScoreFloor(const std::string& cfg_path) {
    // OpenCV's darknet reader gives each [yolo] layer `thresh` (default 0.2) and sets every
    // class score at or below it to 0: no box under it ever comes out.
    constexpr float kOpenCvDefault = 0.2f;
    float highest = 0.f;
    for (const auto& section : readCfgSections(cfg_path)) {
        if (section.type != "yolo") continue;
        float layer = kOpenCvDefault;
        for (const auto& [key, value, line] : section.keys)
            if (key == "thresh")
                layer = static_cast<float>(
                    core::parseNumber(value, "darknet cfg '" + cfg_path + "' thresh"));
        highest = std::max(highest, layer);
    }
    return highest;
}

void checkDarknetCfg(const std::string& cfg_path) {
    // OpenCV's reader asserts none of these (see the header).
    using Layer = CfgSection;
    std::vector<Layer> layers;  // [net] left out: darknet's layer indices count the others
    for (auto& section : readCfgSections(cfg_path))
        if (section.type != "net" && section.type != "network")
            layers.push_back(std::move(section));
    const auto fail = [&](int line, const Layer& l, const std::string& key,
                          const std::string& why) {
        throw std::runtime_error("darknet cfg '" + cfg_path + "' line " + std::to_string(line) +
                                 ": [" + l.type + "] " + key + ": " + why);
    };
    const auto integers = [&](const std::string& text, const std::string& key, int line,
                              const Layer& l) {
        std::vector<int> v;
        std::istringstream ss(text);
        for (std::string item; std::getline(ss, item, ',');) {
            item = trim(item);
            if (item.empty()) continue;
            try {
                v.push_back(static_cast<int>(core::parseInteger(item, key, -1000000, 1000000)));
            } catch (const std::invalid_argument&) {
                fail(line, l, key, "'" + item + "' is not an integer in [-1e6, 1e6]");
            }
        }
        return v;
    };
    for (std::size_t i = 0; i < layers.size(); ++i) {
        const auto& l = layers[i];
        int anchors = -1, num = -1, mask_line = 0;
        std::vector<int> mask;
        for (const auto& [key, value, line] : l.keys) {
            if (l.type == "convolutional" && key == "groups") {
                const auto g = integers(value, key, line, l);
                if (g.size() != 1 || g[0] < 1) fail(line, l, key, "must be an integer >= 1");
            } else if ((l.type == "route" && key == "layers") ||
                       ((l.type == "shortcut" || l.type == "scale_channels" || l.type == "sam") &&
                        key == "from")) {
                for (const int k : integers(value, key, line, l)) {
                    const long at = k < 0 ? static_cast<long>(i) + k : k;
                    if (at < 0 || at >= static_cast<long>(i))
                        fail(line, l, key,
                             std::to_string(k) + " is not one of the " + std::to_string(i) +
                                 " layers before this one (layer " + std::to_string(i) + ")");
                }
            } else if (l.type == "yolo" && key == "anchors") {
                // Counted only: they are numbers, not always whole (k-means anchors).
                int items = 0;
                std::istringstream ss(value);
                for (std::string item; std::getline(ss, item, ',');)
                    items += trim(item).empty() ? 0 : 1;
                anchors = items / 2;
            } else if (l.type == "yolo" && key == "num") {
                const auto v = integers(value, key, line, l);
                num = v.size() == 1 ? v[0] : -1;
            } else if (l.type == "yolo" && key == "mask") {
                mask = integers(value, key, line, l);
                mask_line = line;
            }
        }
        const int have = anchors >= 0 ? anchors : num;
        for (const int m : mask)
            if (have >= 0 && (m < 0 || m >= have))
                fail(mask_line, l, "mask",
                     std::to_string(m) + " is not one of its " + std::to_string(have) +
                         " anchors (0.." + std::to_string(have - 1) + ")");
    }
}

cv::dnn::Net readDarknetCfg(const std::string& cfg_path) {
    const std::string path = resolveModelPath(cfg_path, "darknet cfg");
    checkDarknetCfg(path);
    try {
        cv::dnn::Net net = cv::dnn::readNetFromDarknet(path);
        if (net.empty()) throw std::runtime_error("empty network");
        return net;
    } catch (const cv::Exception& e) {
        throw std::runtime_error("darknet cfg '" + path + "' does not parse: " + e.what());
    }
}

void YoloDetector::Options::loadFromConfig(const mrpt::config::CConfigFileBase& c,
                                           const std::string& s) {
    core::requireKnownKeys(c, s, kYoloKeys);
    model = c.read_string(s, "model", model);
    weights = c.read_string(s, "weights", weights);
    names = c.read_string(s, "names", names);
    input_width = core::readInt(c, s, "input_width", input_width);
    input_height = core::readInt(c, s, "input_height", input_height);
    conf_threshold = core::readDouble(c, s, "conf_threshold", conf_threshold);
    nms_threshold = core::readDouble(c, s, "nms_threshold", nms_threshold);
    if (c.keyExists(s, "classes")) classes = splitList(c.read_string(s, "classes", ""));
    validate_on_load = core::readBool(c, s, "validate_on_load", validate_on_load);
    fast_convolutions = core::readBool(c, s, "fast_convolutions", fast_convolutions);
    // 32000 x 32000 ran for minutes per frame: no darknet model is trained above ~1280.
    core::requireValue(input_width > 0 && input_width <= 2048 && input_width % 32 == 0, s,
                       "input_width", "must be a multiple of 32 in [32, 2048]");
    core::requireValue(input_height > 0 && input_height <= 2048 && input_height % 32 == 0, s,
                       "input_height", "must be a multiple of 32 in [32, 2048]");
    core::requireValue(conf_threshold >= 0 && conf_threshold <= 1, s, "conf_threshold",
                       "must be in [0, 1]");
    core::requireValue(nms_threshold >= 0 && nms_threshold <= 1, s, "nms_threshold",
                       "must be in [0, 1]");
    core::requireValue(!classes.empty(), s, "classes", "needs at least one class name");
}

void YoloDetector::Options::saveToConfig(mrpt::config::CConfigFileBase& c,
                                         const std::string& s) const {
    core::writeKey(c, s, "detector", std::string("yolo"));
    core::writeKey(c, s, "model", model);
    core::writeKey(c, s, "weights", weights);
    core::writeKey(c, s, "names", names);
    core::writeKey(c, s, "input_width", input_width);
    core::writeKey(c, s, "input_height", input_height);
    core::writeKey(c, s, "conf_threshold", conf_threshold);
    core::writeKey(c, s, "nms_threshold", nms_threshold);
    std::string list;
    for (const auto& n : classes) list += (list.empty() ? "" : ", ") + n;
    core::writeKey(c, s, "classes", list);
    core::writeKey(c, s, "validate_on_load", validate_on_load);
    core::writeKey(c, s, "fast_convolutions", fast_convolutions);
}

YoloDetector::YoloDetector(const Options& opts) : opts_(opts) {
    const std::string model = resolveModelPath(opts_.model, "yolo model");
    onnx_ = core::endsWithNoCase(model, ".onnx");
    names_ = readNames(resolveModelPath(opts_.names, "yolo class names"));
    for (const auto& c : opts_.classes) {
        const auto it = std::find(names_.begin(), names_.end(), c);
        if (it == names_.end())
            throw UnknownClass("classes: '" + c + "' is not in '" + opts_.names + "'");
        const int k = static_cast<int>(it - names_.begin());
        // Listed twice, each of its boxes was reported twice (two tracks per person).
        if (std::find(wanted_.begin(), wanted_.end(), k) != wanted_.end())
            throw std::invalid_argument("classes: '" + c + "' is listed twice");
        wanted_.push_back(k);
    }
    std::string weights;
    const auto read = [&](const std::function<cv::dnn::Net()>& reader) {
        return opts_.fast_convolutions ? withFastConvolutions(reader) : reader();
    };
    try {
        if (onnx_) {
            net_ = read([&] { return cv::dnn::readNetFromONNX(model); });
        } else {
            weights = resolveModelPath(opts_.weights, "yolo weights");
            // A truncated or foreign file must not silently give a half-loaded network.
            if (!fs::is_regular_file(weights))
                throw std::runtime_error("yolo weights '" + weights + "' is not a file");
            if (fs::file_size(weights) < 1024)
                throw std::runtime_error("yolo weights '" + weights + "' is too small (" +
                                         std::to_string(fs::file_size(weights)) +
                                         " bytes) to be a darknet weights file");
            // A threshold the network never reaches down to would promise weak boxes (those
            // that only continue tracks) that never come.
            const float lowest = darknetScoreFloor(model);
            if (static_cast<float>(opts_.conf_threshold) < lowest) {
                std::ostringstream msg;
                msg << "conf_threshold: " << opts_.conf_threshold << " is below the " << lowest
                    << " of the [yolo] layers of '" << model
                    << "' (their thresh, 0.2 when the cfg sets none): OpenCV returns no box "
                       "scoring at or under it";
                throw std::invalid_argument(msg.str());
            }
            checkDarknetCfg(model);
            net_ = read([&] { return cv::dnn::readNetFromDarknet(model, weights); });
            // cv::dnn reads a truncated weights file without complaint (missing values
            // stay uninitialised): the file must hold exactly the header and a float32 for
            // every parameter of the cfg but the YOLO layers' anchors (OpenCV keeps them as
            // blobs of its "Region" layers; they come from the cfg). The header is 3 int32
            // (major, minor, revision) and the images seen, an int64 from version 0.2 on.
            std::size_t n_params = 0;
            for (const auto& layer : net_.getLayerNames()) {
                const auto l = net_.getLayer(net_.getLayerId(layer));
                if (l->type == "Region") continue;
                for (const auto& blob : l->blobs) n_params += blob.total();
            }
            std::int32_t version[3] = {0, 0, 0};
            std::ifstream(weights, std::ios::binary)
                .read(reinterpret_cast<char*>(version), sizeof version);
            const std::uintmax_t header = (version[0] * 10 + version[1] >= 2) ? 20 : 16;
            const std::uintmax_t expected = header + 4 * static_cast<std::uintmax_t>(n_params);
            const auto actual = fs::file_size(weights);
            if (actual != expected)
                throw std::runtime_error("yolo weights '" + weights + "' has " +
                                         std::to_string(actual) + " bytes but cfg '" + model +
                                         "' needs " + std::to_string(expected) +
                                         " (truncated file, or weights of another model?)");
        }
    } catch (const cv::Exception& e) {
        throw std::runtime_error("yolo: cannot load model '" + model + "'" +
                                 (weights.empty() ? "" : " with weights '" + weights + "'") + ": " +
                                 e.what());
    }
    if (net_.empty()) throw std::runtime_error("yolo: model '" + model + "' gave an empty network");
    net_.setPreferableBackend(cv::dnn::DNN_BACKEND_OPENCV);
    net_.setPreferableTarget(cv::dnn::DNN_TARGET_CPU);
    out_names_ = net_.getUnconnectedOutLayersNames();
    if (opts_.validate_on_load) {
        const std::string what = "yolo: model '" + model + "'" +
                                 (weights.empty() ? "" : " with weights '" + weights + "'");
        try {
            (void)detect(
                cv::Mat(opts_.input_height, opts_.input_width, CV_8UC3, cv::Scalar(127, 127, 127)));
        } catch (const std::exception& e) {
            throw std::runtime_error(
                what + " fails on a test image (corrupt or mismatched file?): " + e.what());
        }
        // A weights file of the right size but zeroed, or full of NaN, ran without an error
        // and found nobody, ever: its raw outputs on a noise image tell. Any trained network
        // scores the cells of noise differently; zeroed weights give every cell the same
        // objectness (the logistic of 0), NaN weights give NaN.
        cv::Mat noise(opts_.input_height, opts_.input_width, CV_8UC3);
        cv::RNG(1).fill(noise, cv::RNG::UNIFORM, 0, 256);
        net_.setInput(cv::dnn::blobFromImage(noise, 1.0 / 255.0,
                                             cv::Size(opts_.input_width, opts_.input_height),
                                             cv::Scalar(), /*swapRB=*/true, /*crop=*/false));
        std::vector<cv::Mat> outs;
        net_.forward(outs, out_names_);
        double lo = std::numeric_limits<double>::infinity(), hi = -lo;
        std::size_t cells = 0;
        for (cv::Mat out : outs) {
            if (out.dims == 3) out = out.reshape(1, out.size[1]);
            if (!cv::checkRange(out))
                throw std::runtime_error(what +
                                         " gives non-finite outputs (NaN or infinite) on a "
                                         "test image: corrupt weights?");
            if (out.dims != 2 || out.cols < 5 || out.rows == 0) continue;  // detect() said so
            double a = 0, b = 0;
            cv::minMaxLoc(out.col(4), &a, &b);
            lo = std::min(lo, a);
            hi = std::max(hi, b);
            cells += static_cast<std::size_t>(out.rows);
        }
        if (cells > 1 && !(hi - lo > 1e-6))
            throw std::runtime_error(what + " gives every one of its " + std::to_string(cells) +
                                     " outputs the same objectness (" + std::to_string(lo) +
                                     ") on a noise image: zeroed or corrupt weights?");
    }
}

std::string YoloDetector::name() const {
    return "yolo(" + fs::path(opts_.model).filename().string() + ", " +
           std::to_string(opts_.input_width) + "x" + std::to_string(opts_.input_height) + ")";
}

std::vector<Detection> YoloDetector::detect(const cv::Mat& bgr) {
    if (bgr.empty() || bgr.type() != CV_8UC3)
        throw std::invalid_argument("yolo: detect() needs a non-empty CV_8UC3 image");
    // Darknet models are trained on stretched (not letterboxed) RGB images in [0, 1].
    const cv::Mat blob = cv::dnn::blobFromImage(
        bgr, 1.0 / 255.0, cv::Size(opts_.input_width, opts_.input_height), cv::Scalar(),
        /*swapRB=*/true, /*crop=*/false);
    net_.setInput(blob);
    std::vector<cv::Mat> outs;
    net_.forward(outs, out_names_);

    // The network's scores are floats: the thresholds compare at their precision.
    const auto conf = static_cast<float>(opts_.conf_threshold);
    const auto nms = static_cast<float>(opts_.nms_threshold);
    const int n_classes = static_cast<int>(names_.size());
    std::vector<std::vector<cv::Rect2d>> boxes(wanted_.size());
    std::vector<std::vector<float>> scores(wanted_.size());
    for (cv::Mat out : outs) {
        // ONNX exports give 1 x N x (5 + C); darknet gives N x (5 + C).
        if (out.dims == 3) out = out.reshape(1, out.size[1]);
        if (out.dims != 2 || out.cols != 5 + n_classes)
            throw std::runtime_error("yolo: output of " + std::to_string(out.cols) +
                                     " columns, expected 5 + " + std::to_string(n_classes) +
                                     " (the " + std::to_string(n_classes) +
                                     " class names of '" + opts_.names +
                                     "': does that file match the model?)");
        for (int r = 0; r < out.rows; ++r) {
            const float* row = out.ptr<float>(r);
            const float obj = row[4];
            // (not `obj < conf`: a NaN from corrupted weights passed every test below)
            if (!(obj >= conf)) continue;
            for (std::size_t k = 0; k < wanted_.size(); ++k) {
                // cv::dnn's darknet region layer already multiplies class scores by
                // objectness; ONNX (YOLOv5-style) outputs keep them separate.
                const float cls = row[5 + wanted_[k]];
                const float score = onnx_ ? obj * cls : cls;
                if (!(score >= conf)) continue;
                double cx = row[0], cy = row[1], w = row[2], h = row[3];
                if (onnx_) {  // input pixels -> normalized
                    cx /= opts_.input_width;
                    w /= opts_.input_width;
                    cy /= opts_.input_height;
                    h /= opts_.input_height;
                }
                if (!std::isfinite(cx) || !std::isfinite(cy) || !std::isfinite(w) ||
                    !std::isfinite(h))
                    continue;
                boxes[k].emplace_back((cx - w / 2) * bgr.cols, (cy - h / 2) * bgr.rows,
                                      w * bgr.cols, h * bgr.rows);
                scores[k].push_back(score);
            }
        }
    }
    std::vector<Detection> dets;
    const cv::Rect2f image(0.f, 0.f, static_cast<float>(bgr.cols), static_cast<float>(bgr.rows));
    for (std::size_t k = 0; k < wanted_.size(); ++k) {
        std::vector<int> keep;
        cv::dnn::NMSBoxes(boxes[k], scores[k], conf, nms, keep);
        for (int i : keep) {
            const cv::Rect2f b = cv::Rect2f(boxes[k][i]) & image;
            if (!(b.area() > 0.f)) continue;
            dets.push_back({b, wanted_[k], names_[wanted_[k]], scores[k][i]});
        }
    }
    std::sort(dets.begin(), dets.end(),
              [](const Detection& a, const Detection& b) { return a.score > b.score; });
    return dets;
}

}  // namespace devslam::detect
