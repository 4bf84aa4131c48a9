#include <devslam/nav/RoutePicture.h>

#include <opencv2/imgproc.hpp>

#include <cmath>

namespace devslam::nav {

namespace {
const cv::Scalar kRouteColour(220, 120, 0);  // BGR
}

void drawMetreGrid(cv::Mat& img, const ToPixel& px, double x_min, double x_max, double y_min,
                   double y_max, const cv::Scalar& colour) {
    for (double x = std::ceil(x_min); x <= x_max; x += 1.0)
        cv::line(img, px({x, y_min}), px({x, y_max}), colour, 1);
    for (double y = std::ceil(y_min); y <= y_max; y += 1.0)
        cv::line(img, px({x_min, y}), px({x_max, y}), colour, 1);
}

void drawRoute(cv::Mat& img, const ToPixel& px, const std::vector<mrpt::math::TPoint2D>& route,
               const std::vector<mrpt::math::TPoint2D>& waypoints) {
    std::vector<cv::Point> pts;
    for (const auto& q : route) pts.push_back(px(q));
    if (pts.size() >= 2) cv::polylines(img, pts, false, kRouteColour, 2, cv::LINE_AA);
    for (const auto& q : waypoints)
        cv::circle(img, px(q), 4, kRouteColour, cv::FILLED, cv::LINE_AA);
}

void drawStartGoal(cv::Mat& img, const ToPixel& px, const mrpt::math::TPoint2D& start,
                   const mrpt::math::TPoint2D& goal) {
    cv::drawMarker(img, px(start), cv::Scalar(0, 160, 0), cv::MARKER_SQUARE, 16, 2);
    cv::drawMarker(img, px(goal), cv::Scalar(0, 0, 210), cv::MARKER_STAR, 18, 2);
}

void drawTitleBand(cv::Mat& img, const std::string& title, const std::string& legend) {
    cv::rectangle(img, cv::Point(0, 0), cv::Point(img.cols, kTitleBandHeight - 1),
                  cv::Scalar(250, 250, 250), cv::FILLED);
    cv::putText(img, title, cv::Point(8, 16), cv::FONT_HERSHEY_SIMPLEX, 0.48, cv::Scalar(0, 0, 0),
                1, cv::LINE_AA);
    cv::putText(img, legend, cv::Point(8, 33), cv::FONT_HERSHEY_SIMPLEX, 0.38,
                cv::Scalar(60, 60, 60), 1, cv::LINE_AA);
}

}  // namespace devslam::nav
