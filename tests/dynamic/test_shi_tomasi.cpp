// The filter's Shi-Tomasi selection from a shared eigenvalue map against OpenCV's own
// goodFeaturesToTrack, on a real TUM frame at the filter's working scale.
#include <devslam/dynamic/ShiTomasi.h>
#include <devslam/io/RgbdReader.h>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cstdio>
#include <optional>
#include <stdexcept>
#include <tuple>
#include <vector>

using namespace devslam;

namespace {
const std::string kRoot = DEVSLAM_SOURCE_DIR;

/// The real frames as the filter sees them: gray, at its default flow_scale of 0.5.
std::vector<cv::Mat> workImages() {
    auto reader = io::openRgbd(kRoot + "/data/tum/fr1_xyz_first37", {});
    std::vector<cv::Mat> images;
    while (const auto f = reader->next()) {
        cv::Mat gray, work;
        cv::cvtColor(f->bgr, gray, cv::COLOR_BGR2GRAY);
        cv::resize(gray, work, cv::Size(), 0.5, 0.5, cv::INTER_AREA);
        images.push_back(work);
    }
    return images;
}

/// Frame 10 of them.
cv::Mat workImage() {
    const auto images = workImages();
    if (images.size() < 11) throw std::runtime_error("fr1_xyz_first37 has fewer than 11 frames");
    return images[10];
}
}  // namespace

TEST(ShiTomasi, MapIsCornerMinEigenVal) {
    // compute() builds cv::cornerMinEigenVal's map from faster OpenCV primitives: the values
    // must agree to float rounding, everywhere including the image border, on a real frame
    // and on a synthetic one with corners right at the border.
    cv::Mat synthetic(240, 320, CV_8UC1, cv::Scalar(90));
    cv::rectangle(synthetic, {0, 0, 40, 30}, cv::Scalar(250), cv::FILLED);
    cv::rectangle(synthetic, {150, 100, 60, 50}, cv::Scalar(10), cv::FILLED);
    cv::circle(synthetic, {319, 239}, 25, cv::Scalar(200), cv::FILLED);
    for (const cv::Mat& image : {workImage(), synthetic}) {
        const auto map = dynamic::ShiTomasiMap::compute(image);
        cv::Mat expected;
        cv::cornerMinEigenVal(image, expected, 3, 3);
        double max_val = 0;
        cv::minMaxLoc(expected, nullptr, &max_val);
        ASSERT_GT(max_val, 0.0);
        ASSERT_EQ(map.eig.size(), expected.size());
        ASSERT_EQ(map.eig.type(), CV_32FC1);
        EXPECT_LE(cv::norm(map.eig, expected, cv::NORM_INF), 1e-5 * max_val);
    }
}

TEST(ShiTomasi, WholeImageSelectionIsGoodFeaturesToTrack) {
    // The map is cornerMinEigenVal's to float rounding, not to the bit (it is computed from
    // other primitives), so a corner whose response ties another's to the last bit could
    // swap places on another CPU. On this project's machines the selections are identical
    // on every frame; the test allows 1 % of the corners to differ.
    int frames = 0, identical = 0;
    const auto check = [&](const cv::Mat& image, int n, double q, double d) {
        std::vector<cv::Point2f> expected;
        cv::goodFeaturesToTrack(image, expected, n, q, d);
        const auto got = dynamic::selectShiTomasi(dynamic::ShiTomasiMap::compute(image),
                                                  cv::Rect(0, 0, image.cols, image.rows), n, q, d);
        ASSERT_GT(expected.size(), 50u);
        std::size_t same = 0;
        for (std::size_t i = 0; i < std::min(got.size(), expected.size()); ++i)
            same += got[i] == expected[i];
        EXPECT_GE(same * 100, expected.size() * 99)
            << "max_corners " << n << ", quality " << q << ", distance " << d << ": " << same
            << " of " << expected.size() << " corners in the same place";
        EXPECT_LE(got.size(), expected.size() + expected.size() / 100 + 1);
        ++frames;
        identical += got == expected;
    };
    const cv::Mat work = workImage();
    ASSERT_EQ(work.size(), cv::Size(320, 240));
    // The filter's settings (200, 0.01, 5), a denser one, and no distance / no limit.
    for (const auto& [n, q, d] :
         {std::tuple{200, 0.01, 5.0}, std::tuple{500, 0.001, 2.5}, std::tuple{0, 0.05, 0.0}})
        check(work, n, q, d);
    // The filter's settings on every frame with an associated depth image.
    for (const cv::Mat& image : workImages()) check(image, 200, 0.01, 5.0);
    EXPECT_GE(frames, 33);
    std::printf("identical to goodFeaturesToTrack: %d of %d selections\n", identical, frames);
}

TEST(ShiTomasi, RegionWithMaskMatchesGoodFeaturesToTrackOnTheRegion) {
    // goodFeaturesToTrack on a region sees no pixels outside it for its local-maximum test;
    // the shared map does, so the two may differ on the region's border rows and columns.
    // Everywhere else they agree, and every corner respects the mask and the region.
    const cv::Mat work = workImage();
    const auto map = dynamic::ShiTomasiMap::compute(work);
    const cv::Rect roi(100, 60, 90, 120);
    cv::Mat mask = cv::Mat::zeros(roi.size(), CV_8UC1);
    cv::circle(mask, {45, 60}, 40, 255, cv::FILLED);
    std::vector<cv::Point2f> expected;
    cv::goodFeaturesToTrack(work(roi), expected, 40, 0.01, 2.5, mask);
    const auto got = dynamic::selectShiTomasi(map, roi, 40, 0.01, 2.5, mask);
    ASSERT_GT(expected.size(), 10u);
    ASSERT_LE(got.size(), 40u);
    std::size_t same = 0;
    for (const auto& p : got) {
        const cv::Point local(cvRound(p.x) - roi.x, cvRound(p.y) - roi.y);
        ASSERT_TRUE(cv::Rect({}, roi.size()).contains(local));
        EXPECT_NE(mask.at<uchar>(local), 0);
        for (const auto& e : expected) same += e + cv::Point2f(roi.tl()) == p;
    }
    EXPECT_GE(same, got.size() * 9 / 10) << got.size() << " corners, " << same << " shared";
}

TEST(ShiTomasi, TakenCornersAreNotChosenAgain) {
    // The filter's per-box selection after its image-wide one (same map): the region's own
    // corners, max_corners of them where it has that many, none within min_distance of a
    // corner taken before, whether inside the region or just outside it.
    const cv::Mat work = workImage();
    const auto map = dynamic::ShiTomasiMap::compute(work);
    const cv::Rect roi(100, 60, 90, 120);
    const auto all =
        dynamic::selectShiTomasi(map, cv::Rect(0, 0, work.cols, work.rows), 200, 0.01, 5);
    const auto plain = dynamic::selectShiTomasi(map, roi, 40, 0.01, 2.5);
    std::size_t shared = 0;
    for (const auto& p : plain) shared += std::count(all.begin(), all.end(), p) > 0;
    ASSERT_GT(shared, 3u) << "the region's strongest corners are the image's too";
    const auto own = dynamic::selectShiTomasi(map, roi, 40, 0.01, 2.5, cv::Mat(), all);
    EXPECT_EQ(own.size(), 40u);
    for (const auto& p : own) {
        EXPECT_TRUE(roi.contains(cv::Point(cvRound(p.x), cvRound(p.y))));
        for (const auto& q : all) EXPECT_GE(cv::norm(p - q), 2.5) << p << " near " << q;
    }
    for (std::size_t i = 0; i < own.size(); ++i)
        for (std::size_t j = i + 1; j < own.size(); ++j) EXPECT_GE(cv::norm(own[i] - own[j]), 2.5);
    // Without a spacing, only the taken pixels themselves are left out.
    const auto dense = dynamic::selectShiTomasi(map, roi, 0, 0.01, 0, cv::Mat(), all);
    const auto dense_plain = dynamic::selectShiTomasi(map, roi, 0, 0.01, 0);
    std::size_t in_roi = 0;
    for (const auto& q : all) in_roi += std::count(dense_plain.begin(), dense_plain.end(), q) > 0;
    EXPECT_EQ(dense.size() + in_roi, dense_plain.size());
    for (const auto& p : dense) EXPECT_EQ(std::count(all.begin(), all.end(), p), 0);
}

TEST(ShiTomasi, BadArgumentsAreRejected) {
    const auto map = dynamic::ShiTomasiMap::compute(workImage());
    EXPECT_THROW((void)dynamic::selectShiTomasi(map, cv::Rect(300, 0, 40, 40), 10, 0.01, 5),
                 std::invalid_argument);
    EXPECT_THROW((void)dynamic::selectShiTomasi(map, cv::Rect(0, 0, 40, 40), 10, 0.01, 5,
                                                cv::Mat::zeros(20, 20, CV_8UC1)),
                 std::invalid_argument);
    EXPECT_THROW((void)dynamic::ShiTomasiMap::compute(cv::Mat()), std::invalid_argument);
    EXPECT_THROW((void)dynamic::selectShiTomasi({}, cv::Rect(0, 0, 4, 4), 10, 0.01, 5),
                 std::invalid_argument);
    // An empty region inside the map has no corners (and is no error).
    EXPECT_TRUE(dynamic::selectShiTomasi(map, cv::Rect(50, 50, 0, 0), 10, 0.01, 5).empty());
}
