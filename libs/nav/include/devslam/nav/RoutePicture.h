#pragma once
/// Drawing shared by the route pictures: a plan on a map (nav::writeMapPlanPng) and a
/// simulated run (sim::writeEpisodePng) show the metre grid, the A* route with its waypoints,
/// the start and the goal, and a title band the same way. Each picture maps metres to its
/// pixels with its own `ToPixel` (y up in the world, down in the image).
///
/// Usage:
///   cv::Mat img(h, w, CV_8UC3, cv::Scalar(255, 255, 255));
///   const nav::ToPixel px = [&](const mrpt::math::TPoint2D& q) { return cv::Point(...); };
///   nav::drawRoute(img, px, path.points, waypoints);
///   nav::drawStartGoal(img, px, start, goal);
///   nav::drawTitleBand(img, "run: success, 12 s", "blue: A* + waypoints ...");
#include <mrpt/math/TPoint2D.h>

#include <opencv2/core.hpp>

#include <functional>
#include <string>
#include <vector>

namespace devslam::nav {

using ToPixel = std::function<cv::Point(const mrpt::math::TPoint2D&)>;

/// Height [px] of the band drawTitleBand fills at the top of a picture.
constexpr int kTitleBandHeight = 40;

/// Lines every metre over [x_min, x_max] x [y_min, y_max], in `colour`.
void drawMetreGrid(cv::Mat& img, const ToPixel& px, double x_min, double x_max, double y_min,
                   double y_max, const cv::Scalar& colour);
/// The A* route (blue polyline) and its waypoints (blue dots).
void drawRoute(cv::Mat& img, const ToPixel& px, const std::vector<mrpt::math::TPoint2D>& route,
               const std::vector<mrpt::math::TPoint2D>& waypoints);
/// The start (green square) and the goal (red star).
void drawStartGoal(cv::Mat& img, const ToPixel& px, const mrpt::math::TPoint2D& start,
                   const mrpt::math::TPoint2D& goal);
/// The top kTitleBandHeight rows: a light band with the title and, below it, the legend.
void drawTitleBand(cv::Mat& img, const std::string& title, const std::string& legend);

}  // namespace devslam::nav
