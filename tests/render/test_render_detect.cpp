// The real person detector (devslam::detect, YOLO-Fastest through cv::dnn) must find the
// rendered people: the synthetic benchmark is only meaningful if the filter sees them.
#include <devslam/core/Config.h>
#include <devslam/detect/PersonDetector.h>
#include <devslam/render/Scenario.h>
#include <devslam/render/SequenceRenderer.h>

#include <gtest/gtest.h>

#include <iostream>

using namespace devslam;

TEST(RenderDetect, YoloFindsTheRenderedPeople) {
    const std::string root = DEVSLAM_SOURCE_DIR;
    auto cfg = core::loadIni(root + "/config_ini/detector_yolo_fastest.ini");
    auto det = detect::makeDetector(*cfg);
    render::SequenceRenderer r(render::loadScenario(root + "/sim_worlds/synth/short_walking.ini"));
    constexpr int kMinPixels = 3000;  // people smaller or more hidden than this are not counted
    int n[2] = {0, 0}, hit[2] = {0, 0};
    for (std::size_t i = 0; i < r.frameCount(); i += 6) {
        const auto f = r.render(i);
        const auto dets = det->detect(f.frame.bgr);
        for (const auto& p : f.persons) {
            if (p.visible_pixels < kMinPixels) continue;
            bool found = false;
            for (const auto& d : dets) found |= detect::iou(d.box, cv::Rect2f(p.box)) > 0.4f;
            ++n[p.moving];
            hit[p.moving] += found;
        }
    }
    std::cout << "detected (IoU > 0.4): walking " << hit[1] << "/" << n[1] << ", sitting " << hit[0]
              << "/" << n[0] << "\n";
    ASSERT_GE(n[1], 8);
    EXPECT_GE(hit[1], 0.8 * n[1]);
    EXPECT_GE(hit[0] + hit[1], 0.7 * (n[0] + n[1]));
}
