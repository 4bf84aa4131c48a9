// Tests of devslam::detect on real photos and on the shipped configuration files.
#include <devslam/core/Config.h>
#include <devslam/detect/HogDetector.h>
#include <devslam/detect/PersonDetector.h>
#include <devslam/detect/YoloDetector.h>

#include <gtest/gtest.h>

#include <mrpt/config/CConfigFileMemory.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include "Scratch.h"
#include "ConfigRoundTrip.h"

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <tuple>
#include <vector>

using namespace devslam;
namespace fs = std::filesystem;

namespace {
const std::string kRoot = DEVSLAM_SOURCE_DIR;

cv::Mat readImage(const std::string& rel) {
    cv::Mat m = cv::imread(kRoot + "/" + rel);
    if (m.empty()) throw std::runtime_error("cannot read " + rel);
    return m;
}

// Hand-measured box of the person in data/images/person.jpg (640x424), read off a 25 px
// grid drawn over the photo: hat top y~98, boots bottom y~375, blue jacket's left edge
// x~190, glove's right edge x~275.
const cv::Rect2f kPersonBox(190.f, 98.f, 85.f, 277.f);

std::unique_ptr<detect::PersonDetector> fromIni(const std::string& rel) {
    auto cfg = core::loadIni(kRoot + "/" + rel);
    return detect::makeDetector(*cfg);
}
}  // namespace

TEST(DetectIou, KnownValues) {
    EXPECT_FLOAT_EQ(detect::iou({0, 0, 10, 10}, {0, 0, 10, 10}), 1.f);
    EXPECT_FLOAT_EQ(detect::iou({0, 0, 10, 10}, {5, 0, 10, 10}), 50.f / 150.f);
    EXPECT_FLOAT_EQ(detect::iou({0, 0, 10, 10}, {20, 20, 5, 5}), 0.f);
    EXPECT_FLOAT_EQ(detect::iou({0, 0, 0, 0}, {0, 0, 0, 0}), 0.f);
}

TEST(DetectYolo, PersonPhotoGivesOneMatchingPerson) {
    auto det = fromIni("config_ini/detector_yolo_fastest.ini");
    const auto dets = det->detect(readImage("data/images/person.jpg"));
    ASSERT_EQ(dets.size(), 1u) << "the photo holds one person (and a dog and a horse)";
    EXPECT_EQ(dets[0].class_name, "person");
    EXPECT_EQ(dets[0].class_id, 0);
    EXPECT_GT(dets[0].score, 0.5f);
    EXPECT_GE(detect::iou(dets[0].box, kPersonBox), 0.7f)
        << "box " << dets[0].box << " vs hand-measured " << kPersonBox;
}

TEST(DetectYolo, DogPhotoGivesNoPerson) {
    auto det = fromIni("config_ini/detector_yolo_fastest.ini");
    EXPECT_TRUE(det->detect(readImage("data/images/dog.jpg")).empty());
}

TEST(DetectYolo, SmallModelAlsoFindsThePersonAndNoneOnTheDogPhoto) {
    auto det = fromIni("config_ini/detector_yolo_fastest_small.ini");
    const auto dets = det->detect(readImage("data/images/person.jpg"));
    ASSERT_EQ(dets.size(), 1u);
    EXPECT_GE(detect::iou(dets[0].box, kPersonBox), 0.7f) << dets[0].box;
    EXPECT_TRUE(det->detect(readImage("data/images/dog.jpg")).empty());
}

TEST(DetectYolo, OtherClassesCanBeSelected) {
    auto cfg = core::loadIni(kRoot + "/config_ini/detector_yolo_fastest.ini");
    cfg->write("detector", "classes", std::string("dog"));
    auto det = detect::makeDetector(*cfg);
    const auto dets = det->detect(readImage("data/images/person.jpg"));
    ASSERT_EQ(dets.size(), 1u);
    EXPECT_EQ(dets[0].class_name, "dog");
    EXPECT_EQ(dets[0].class_id, 16);
    // The dog stands left of the person, roughly x 65..205, y 262..345 (hand-measured).
    EXPECT_GE(detect::iou(dets[0].box, cv::Rect2f(65.f, 262.f, 140.f, 83.f)), 0.5f) << dets[0].box;
}

TEST(DetectYolo, DeterministicOutput) {
    auto det = fromIni("config_ini/detector_yolo_fastest.ini");
    const cv::Mat img = readImage("data/images/person.jpg");
    const auto a = det->detect(img);
    const auto b = det->detect(img);
    ASSERT_FALSE(a.empty());
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t i = 0; i < a.size(); ++i) {  // one net, one image: the same bits
        EXPECT_EQ(a[i].box, b[i].box) << i;
        EXPECT_EQ(a[i].score, b[i].score) << i;
        EXPECT_EQ(a[i].class_id, b[i].class_id) << i;
        EXPECT_EQ(a[i].class_name, b[i].class_name) << i;
    }
}

TEST(DetectYolo, Yolov4TinyCfgParsesIntoANetwork) {
    // The INI for the paper's YOLOv4-tiny loads; its weights are not shipped, so only the
    // cfg is parsed (random weights) and the missing weights give a clear error.
    auto cfg = core::loadIni(kRoot + "/config_ini/detector_yolov4_tiny.ini");
    detect::YoloDetector::Options o;
    o.loadFromConfig(*cfg, "detector");
    EXPECT_EQ(o.input_width, 416);
    const cv::dnn::Net net = detect::readDarknetCfg(o.model);
    EXPECT_FALSE(net.empty());
    EXPECT_EQ(net.getUnconnectedOutLayersNames().size(), 2u) << "two [yolo] heads";
    try {
        (void)detect::makeDetector(*cfg);
        FAIL() << "expected an error for the missing weights";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("yolov4-tiny.weights"), std::string::npos) << e.what();
    }
}

// What OpenCV's darknet reader does not check: a `groups` of 0 (a floating-point exception
// that killed the process without a word), a [route] or [shortcut] reference outside the
// layers before it (a bare "vector::_M_range_check"), a [yolo] mask index past its anchors
// (read past the list: extra boxes of no anchor). Each is named by file, line, section and
// key; every shipped cfg passes.
TEST(DetectYolo, DarknetCfgReferencesAndGroupsAreChecked) {
    for (const char* cfg :
         {"models/yolo-fastest-1.1/yolo-fastest-1.1-xl.cfg", "models/yolo-fastest-1.1/yolo-fastest-1.1.cfg",
          "models/yolo-fastest-1.1/yolo-fastest-1.1_body.cfg", "models/yolov4-tiny.cfg"})
        EXPECT_NO_THROW(detect::checkDarknetCfg(kRoot + "/" + cfg)) << cfg;
    const std::string xl = kRoot + "/models/yolo-fastest-1.1/yolo-fastest-1.1-xl.cfg";
    std::string text;
    {
        std::ifstream in(xl);
        text.assign(std::istreambuf_iterator<char>(in), {});
    }
    const fs::path dir = devslam::test::scratchPath("yolo_cfg_check");
    fs::create_directories(dir);
    // The first occurrence of `from` replaced by `to`; the error of loading that cfg.
    const auto errorOf = [&](const std::string& from, const std::string& to) {
        std::string t = text;
        const auto at = t.find(from);
        EXPECT_NE(at, std::string::npos) << from;
        if (at != std::string::npos) t.replace(at, from.size(), to);
        const std::string path = (dir / "bad.cfg").string();
        std::ofstream(path) << t;
        try {
            detect::checkDarknetCfg(path);
        } catch (const std::runtime_error& e) {
            return std::string(e.what());
        }
        return std::string();
    };
    const std::string bad = "darknet cfg '" + (dir / "bad.cfg").string() + "' line ";
    std::string m = errorOf("groups=16", "groups=0");
    EXPECT_EQ(m.rfind(bad, 0), 0u) << m;
    EXPECT_NE(m.find(": [convolutional] groups: must be an integer >= 1"), std::string::npos) << m;
    m = errorOf("\nlayers=-", "\nlayers=-999\n#");
    EXPECT_NE(m.find("[route] layers: -999 is not one of the "), std::string::npos) << m;
    m = errorOf("\nfrom=-", "\nfrom=999\n#");
    EXPECT_NE(m.find("[shortcut] from: 999 is not one of the "), std::string::npos) << m;
    m = errorOf("\nmask = ", "\nmask = 99,");
    EXPECT_NE(m.find("[yolo] mask: 99 is not one of its 6 anchors (0..5)"), std::string::npos) << m;
    // Anchors are numbers, not always whole (k-means anchors): only counted.
    EXPECT_EQ(errorOf("anchors = 12, 18,", "anchors = 12.5, 18.25,"), "");
    m = errorOf("\nfrom=-", "\nfrom=x\n#");
    EXPECT_NE(m.find("[shortcut] from: 'x' is not an integer in [-1e6, 1e6]"), std::string::npos)
        << m;
    fs::remove_all(dir);
}

TEST(DetectYolo, OnnxOutputIsDecoded) {
    // tests/detect/data/constant_yolo.onnx (written by make_constant_yolo_onnx.py next to
    // it) outputs four fixed YOLOv5-style rows in input pixels whatever the image: a person
    // (objectness 0.9 x class 0.8), an overlapping weaker person (NMS), a dog (not a wanted
    // class) and a person whose objectness passes but whose product 0.27 does not.
    detect::YoloDetector::Options o;
    o.model = kRoot + "/tests/detect/data/constant_yolo.onnx";
    o.weights = "";
    detect::YoloDetector det(o);
    const auto dets = det.detect(cv::Mat(480, 640, CV_8UC3, cv::Scalar(30, 60, 90)));
    ASSERT_EQ(dets.size(), 1u);
    EXPECT_EQ(dets[0].class_name, "person");
    EXPECT_NEAR(dets[0].score, 0.72f, 1e-5);
    // (cx, cy, w, h) = (160, 160, 64, 192) of a 320x320 input, stretched to 640x480
    EXPECT_NEAR(dets[0].box.x, 256.f, 1e-3);
    EXPECT_NEAR(dets[0].box.y, 96.f, 1e-3);
    EXPECT_NEAR(dets[0].box.width, 128.f, 1e-3);
    EXPECT_NEAR(dets[0].box.height, 288.f, 1e-3);
    o.classes = {"person", "dog"};  // now the dog is reported too
    detect::YoloDetector both(o);
    const auto d2 = both.detect(cv::Mat(480, 640, CV_8UC3, cv::Scalar(0, 0, 0)));
    ASSERT_EQ(d2.size(), 2u);
    EXPECT_EQ(d2[0].class_name, "dog");  // highest score first (0.95 x 0.9)
    EXPECT_NEAR(d2[0].box.x, (80.f - 20.f) * 2.f, 1e-3);
}

TEST(DetectYolo, NonFiniteOutputsAreDropped) {
    // constant_yolo.onnx with two of its rows patched (its constant rows lie in the file as
    // raw floats): the first person's objectness and the second person's centre x become
    // NaN, as from corrupted weights. Neither is reported, nor makes the others NaN: the dog
    // still is, unchanged. (The decoder drops a NaN at several steps - scores, box, the
    // clipped box's area - each written so that a NaN fails it; with all of them written
    // as `x < threshold`, the NaN centre came out as a box.)
    const std::string src = kRoot + "/tests/detect/data/constant_yolo.onnx";
    std::ifstream in(src, std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), {});
    const auto patch = [&](std::vector<float> row, std::size_t k) {
        const std::string key(reinterpret_cast<const char*>(row.data()), row.size() * 4);
        const auto at = bytes.find(key);
        ASSERT_NE(at, std::string::npos) << "row not found in " << src;
        ASSERT_EQ(bytes.find(key, at + 1), std::string::npos);
        const float nan = std::numeric_limits<float>::quiet_NaN();
        bytes.replace(at + 4 * k, 4, reinterpret_cast<const char*>(&nan), 4);
    };
    patch({160.f, 160.f, 64.f, 192.f, 0.9f}, 4);  // objectness of the 0.72 person
    patch({164.f, 160.f, 64.f, 192.f, 0.9f}, 0);  // centre x of the 0.45 person
    const fs::path dir = devslam::test::scratchPath("devslam_test_detect_nan");
    fs::create_directories(dir);
    const std::string model = (dir / "nan_yolo.onnx").string();
    std::ofstream(model, std::ios::binary) << bytes;
    detect::YoloDetector::Options o;
    o.model = model;
    o.weights = "";
    o.classes = {"person", "dog"};
    // (Its NaN outputs fail the check at load, CorruptWeightsGiveAClearError; the decoder's
    // own guard is what this test is for.)
    o.validate_on_load = false;
    detect::YoloDetector det(o);
    const auto dets = det.detect(cv::Mat(480, 640, CV_8UC3, cv::Scalar(30, 60, 90)));
    ASSERT_EQ(dets.size(), 1u);
    EXPECT_EQ(dets[0].class_name, "dog");
    EXPECT_NEAR(dets[0].score, 0.95f * 0.9f, 1e-5);
    EXPECT_NEAR(dets[0].box.x, (80.f - 20.f) * 2.f, 1e-3);
    EXPECT_NEAR(dets[0].box.width, 40.f * 2.f, 1e-3);
    fs::remove_all(dir);
}

TEST(DetectYolo, MissingWeightsGiveAClearError) {
    detect::YoloDetector::Options o;
    o.weights = "/nonexistent/dir/model.weights";
    try {
        detect::YoloDetector det(o);
        FAIL();
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("/nonexistent/dir/model.weights"), std::string::npos)
            << e.what();
    }
}

TEST(DetectYolo, CorruptWeightsGiveAClearError) {
    const fs::path dir = devslam::test::scratchPath("devslam_test_detect");
    fs::create_directories(dir);
    // A truncated copy of the real weights (half of the file) and a tiny garbage file.
    const std::string real = kRoot + "/models/yolo-fastest-1.1/yolo-fastest-1.1-xl.weights";
    std::ifstream in(real, std::ios::binary);
    std::vector<char> bytes((std::istreambuf_iterator<char>(in)), {});
    ASSERT_GT(bytes.size(), 100000u);
    const std::string half = (dir / "half.weights").string();
    std::ofstream(half, std::ios::binary).write(bytes.data(), bytes.size() / 2);
    const std::string tiny = (dir / "tiny.weights").string();
    std::ofstream(tiny, std::ios::binary) << "not a darknet weights file";
    // 30 kB short: under 1 % of the file, which the size check used to allow.
    const std::string short_by_30k = (dir / "short.weights").string();
    std::ofstream(short_by_30k, std::ios::binary).write(bytes.data(), bytes.size() - 30000);
    // One float short (its value was left uninitialised: the check allowed 1 kB) or one
    // float too many.
    const std::string short_by_4 = (dir / "short4.weights").string();
    std::ofstream(short_by_4, std::ios::binary).write(bytes.data(), bytes.size() - 4);
    const std::string long_by_4 = (dir / "long4.weights").string();
    std::ofstream(long_by_4, std::ios::binary).write(bytes.data(), bytes.size()) << "0000";
    const std::string folder = (dir / "folder.weights").string();
    fs::create_directories(folder);
    // The right size, but every weight 0 or NaN after the 20-byte header: these loaded, and
    // the detector found nobody, ever, without a word.
    std::vector<char> zeroed = bytes;
    std::fill(zeroed.begin() + 20, zeroed.end(), 0);
    const std::string zero = (dir / "zero.weights").string();
    std::ofstream(zero, std::ios::binary).write(zeroed.data(), zeroed.size());
    std::vector<char> nans = bytes;
    const float nan = std::numeric_limits<float>::quiet_NaN();
    for (std::size_t i = 20; i + 4 <= nans.size(); i += 4) std::memcpy(&nans[i], &nan, 4);
    const std::string nan_w = (dir / "nan.weights").string();
    std::ofstream(nan_w, std::ios::binary).write(nans.data(), nans.size());
    for (const auto& [w, why] :
         std::vector<std::pair<std::string, std::string>>{{half, ""},
                                                          {tiny, ""},
                                                          {short_by_30k, ""},
                                                          {short_by_4, "bytes but cfg"},
                                                          {long_by_4, "bytes but cfg"},
                                                          {folder, ""},
                                                          {zero, "the same objectness"},
                                                          {nan_w, "non-finite outputs"}}) {
        detect::YoloDetector::Options o;
        o.weights = w;
        try {
            detect::YoloDetector det(o);
            FAIL() << "no error for " << w;
        } catch (const std::runtime_error& e) {
            EXPECT_NE(std::string(e.what()).find(w), std::string::npos) << e.what();
            EXPECT_NE(std::string(e.what()).find(why), std::string::npos) << e.what();
        }
    }
    fs::remove_all(dir);
    // Every shipped model passes the exact size check.
    for (const std::string m :
         {"yolo-fastest-1.1", "yolo-fastest-1.1-xl", "yolo-fastest-1.1_body"}) {
        detect::YoloDetector::Options o;
        o.model = kRoot + "/models/yolo-fastest-1.1/" + m + ".cfg";
        o.weights = kRoot + "/models/yolo-fastest-1.1/" + m + ".weights";
        if (m == "yolo-fastest-1.1_body") {
            o.names = kRoot + "/models/yolo-fastest-1.1/body.names";
            o.classes = {"body"};
        }
        EXPECT_NO_THROW(detect::YoloDetector det(o)) << m;
    }
}

TEST(DetectYolo, BadOptionsAreRejected) {
    mrpt::config::CConfigFileMemory cfg;
    cfg.write("detector", "detector", std::string("yolo"));
    cfg.write("detector", "input_widht", 320);
    EXPECT_THROW((void)detect::makeDetector(cfg), std::invalid_argument);
    mrpt::config::CConfigFileMemory cfg2;
    cfg2.write("detector", "input_width", 300);
    EXPECT_THROW((void)detect::makeDetector(cfg2), std::invalid_argument);
    cfg2.write("detector", "input_width", 32000);  // a multiple of 32: minutes per frame
    EXPECT_THROW((void)detect::makeDetector(cfg2), std::invalid_argument);
    mrpt::config::CConfigFileMemory cfg3;
    cfg3.write("detector", "classes", std::string("unicorn"));
    try {  // named by section and key, as the other values (the apps add the file)
        (void)detect::makeDetector(cfg3);
        ADD_FAILURE() << "no error";
    } catch (const std::invalid_argument& e) {
        EXPECT_EQ(std::string(e.what()),
                  "[detector] classes: 'unicorn' is not in 'models/yolo-fastest-1.1/coco.names'");
    }
    // Listed twice, every person came out twice (two tracks each): refused.
    mrpt::config::CConfigFileMemory cfg4;
    cfg4.write("detector", "classes", std::string("person, person"));
    try {
        (void)detect::makeDetector(cfg4);
        ADD_FAILURE() << "no error";
    } catch (const std::invalid_argument& e) {
        EXPECT_EQ(std::string(e.what()), "[detector] classes: 'person' is listed twice");
    }
}

// OpenCV zeroes the class scores at or under a [yolo] layer's `thresh` (0.2 where the cfg
// sets none, as in the shipped cfgs): a conf_threshold under it is refused, naming the floor;
// a cfg that lowers it takes one.
TEST(DetectYolo, ConfThresholdUnderTheModelsFloorIsRefused) {
    const std::string xl = kRoot + "/models/yolo-fastest-1.1/yolo-fastest-1.1-xl.cfg";
    EXPECT_FLOAT_EQ(detect::darknetScoreFloor(xl), 0.2f);
    mrpt::config::CConfigFileMemory cfg;
    cfg.write("detector", "conf_threshold", 0.15);
    try {
        (void)detect::makeDetector(cfg);
        ADD_FAILURE() << "conf_threshold 0.15 was accepted";
    } catch (const std::invalid_argument& e) {
        EXPECT_EQ(std::string(e.what()).rfind("[detector] conf_threshold: 0.15 is below the 0.2 "
                                              "of the [yolo] layers of '",
                                              0),
                  0u)
            << e.what();
    }
    // A copy whose layers set thresh (one 0.01, one 0.1): the floor is the larger.
    const fs::path dir = devslam::test::scratchPath("yolo_floor");
    fs::create_directories(dir);
    std::ifstream in(xl);
    std::ofstream out(dir / "low.cfg");
    int layer = 0;
    for (std::string line; std::getline(in, line);) {
        out << line << "\n";
        if (line == "[yolo]") out << "thresh = " << (layer++ == 0 ? "0.01" : "0.1") << "\n";
    }
    out.close();
    ASSERT_EQ(layer, 2);
    EXPECT_FLOAT_EQ(detect::darknetScoreFloor((dir / "low.cfg").string()), 0.1f);
    cfg.write("detector", "model", (dir / "low.cfg").string());
    cfg.write("detector", "weights",
              kRoot + "/models/yolo-fastest-1.1/yolo-fastest-1.1-xl.weights");
    EXPECT_NO_THROW((void)detect::makeDetector(cfg));
    fs::remove_all(dir);
}

TEST(DetectYolo, OptionsRoundTrip) {
    detect::YoloDetector::Options a;
    a.input_width = 416;
    a.conf_threshold = 0.2f;
    a.classes = {"person", "dog"};
    mrpt::config::CConfigFileMemory cfg;
    a.saveToConfig(cfg, "d");
    detect::YoloDetector::Options b;
    b.loadFromConfig(cfg, "d");
    EXPECT_EQ(b.input_width, 416);
    EXPECT_FLOAT_EQ(b.conf_threshold, 0.2f);
    EXPECT_EQ(b.classes, a.classes);
}

// Every key of both detectors' sections: read back into its own field, at full precision.
TEST(DetectYolo, EveryKeyRoundTrips) {
    test::expectEveryKeyRoundTrips(
        [](const test::Ini& in, test::Ini& out) {
            detect::YoloDetector::Options o;
            o.loadFromConfig(in, "detector");
            o.saveToConfig(out, "detector");
        },
        {{{"detector", "model", {"models/other.cfg"}},
          {"detector", "weights", {"models/other.weights"}},
          {"detector", "names", {"models/other.names"}},
          {"detector", "classes", {"person, dog", "car"}}},
         {{"detector", "detector"}},
         {}});
}

TEST(DetectHog, EveryKeyRoundTrips) {
    test::expectEveryKeyRoundTrips(
        [](const test::Ini& in, test::Ini& out) {
            detect::HogDetector::Options o;
            o.loadFromConfig(in, "detector");
            o.saveToConfig(out, "detector");
        },
        {{}, {{"detector", "detector"}}, {}});
}

TEST(DetectFactory, UnknownNameListsKnownNames) {
    mrpt::config::CConfigFileMemory cfg;
    cfg.write("detector", "detector", std::string("ssd"));
    try {
        (void)detect::makeDetector(cfg);
        FAIL();
    } catch (const std::invalid_argument& e) {
        const std::string msg = e.what();
        EXPECT_NE(msg.find("ssd"), std::string::npos);
        EXPECT_NE(msg.find("yolo"), std::string::npos);
        EXPECT_NE(msg.find("hog"), std::string::npos);
    }
}

TEST(DetectHog, FindsThePersonAndNotTheDog) {
    auto det = fromIni("config_ini/detector_hog.ini");
    EXPECT_EQ(det->name().rfind("hog", 0), 0u);
    const auto dets = det->detect(readImage("data/images/person.jpg"));
    ASSERT_FALSE(dets.empty());
    EXPECT_GE(detect::iou(dets[0].box, kPersonBox), 0.5f) << dets[0].box;
    EXPECT_TRUE(det->detect(readImage("data/images/dog.jpg")).empty());
}

// A scale that would leave no image (cv::resize asserts on it) or a huge one, and a score
// threshold no box can pass (scores lie in (0, 1)), are refused when the INI is read, naming
// the key.
TEST(DetectHog, ResizeOrMinScoreOutOfRangeIsRejected) {
    const std::vector<std::tuple<std::string, double, std::string>> cases = {
        {"resize", 0.001, "[detector] resize: must be in [0.1, 4]"},
        {"resize", 0.0, "[detector] resize: must be in [0.1, 4]"},
        {"resize", 100.0, "[detector] resize: must be in [0.1, 4]"},
        {"min_score", 7.0, "[detector] min_score: must be in [0, 1]"},
        {"min_score", -3.0, "[detector] min_score: must be in [0, 1]"},
        // (one window a frame, or one pyramid level: nobody found, no word)
        {"win_stride", 128, "[detector] win_stride: must be a positive multiple of 8 (HOG cell "
                            "size), at most 64 (the window's width)"},
        {"scale", 1e9, "[detector] scale: must be in (1, 2]"}};
    for (const auto& [key, value, message] : cases) {
        mrpt::config::CConfigFileMemory cfg;
        cfg.write("detector", "detector", std::string("hog"));
        cfg.write("detector", key, value);
        try {
            (void)detect::makeDetector(cfg);
            ADD_FAILURE() << key << " " << value << " was accepted";
        } catch (const std::invalid_argument& e) {
            EXPECT_EQ(std::string(e.what()), message);
        }
    }
}

// An image smaller than the 64x128 window, as given or after `resize`, holds no person the
// SVM can find: none is found (OpenCV's detectMultiScale read out of bounds on it).
TEST(DetectHog, ImageSmallerThanTheWindowHasNoPerson) {
    const cv::Mat person = readImage("data/images/person.jpg");
    for (const auto& [size, resize] : {std::pair{cv::Size(200, 100), 1.0},
                                       {cv::Size(32, 24), 1.0},
                                       {cv::Size(32, 24), 0.5},
                                       {cv::Size(1, 1), 0.1},
                                       {cv::Size(63, 300), 1.0}}) {
        detect::HogDetector::Options o;
        o.resize = resize;
        detect::HogDetector hog(o);
        cv::Mat img;
        cv::resize(person, img, size);
        EXPECT_TRUE(hog.detect(img).empty()) << size << " at resize " << resize;
    }
    // ... but a frame the window fits, shrunk under it by `resize`, is a setting that finds
    // nobody in any frame (it ran, "detect 0.0 ms", no box): an error naming the key.
    {
        detect::HogDetector::Options o;
        o.resize = 0.2;
        detect::HogDetector hog(o);
        cv::Mat img;
        cv::resize(person, img, cv::Size(640, 480));
        try {
            (void)hog.detect(img);
            ADD_FAILURE() << "resize 0.2 on 640x480 found nobody without a word";
        } catch (const std::invalid_argument& e) {
            EXPECT_EQ(std::string(e.what()),
                      "[detector] resize: 0.2 makes a 640x480 frame 128x96 px, smaller than "
                      "HOG's 64x128 window: no person could be found; raise it");
        }
    }
    // The smallest image it scans: the window itself.
    detect::HogDetector hog({});
    cv::Mat img;
    cv::resize(person, img, cv::Size(64, 128));
    EXPECT_NO_THROW((void)hog.detect(img));
}

TEST(Detect, WrongImageTypeThrows) {
    detect::HogDetector hog({});
    EXPECT_THROW((void)hog.detect(cv::Mat(10, 10, CV_8UC1)), std::invalid_argument);
}
