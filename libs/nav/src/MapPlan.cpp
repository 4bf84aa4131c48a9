#include <devslam/nav/MapPlan.h>

#include <devslam/core/GzFile.h>

#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/serialization/CArchive.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace devslam::nav {

mrpt::maps::COccupancyGridMap2D loadGridMap(const std::string& path) {
    if (!std::filesystem::is_regular_file(path))
        throw std::runtime_error(path + ": no such grid map file");
    mrpt::maps::COccupancyGridMap2D grid;
    try {
        mrpt::io::CFileGZInputStream in(path);
        auto arch = mrpt::serialization::archiveFrom(in);
        arch >> grid;
    } catch (const std::exception& e) {
        throw std::runtime_error(path +
                                 ": not an MRPT occupancy grid (a .gridmap as devslam-run "
                                 "writes): " +
                                 core::innermostMessage(e.what()));
    }
    // MRPT reads a cut gz file quietly up to the cut, and the grid keeps what it had.
    if (const std::string gz = core::gzipDamage(path); !gz.empty())
        throw std::runtime_error(path + ": truncated or corrupt gzip stream (" + gz + ")");
    if (grid.getSizeX() == 0 || grid.getSizeY() == 0)
        throw std::runtime_error(path + ": the grid map is empty");
    return grid;
}

MapPlan planOnMap(const mrpt::maps::COccupancyGridMap2D& grid, const mrpt::math::TPoint2D& from,
                  const mrpt::math::TPoint2D& to, const GridPlannerOptions& opts) {
    GridPlanner planner(opts);
    planner.setMap(grid);
    MapPlan p;
    p.from = from;
    p.to = to;
    p.path = planner.plan(from, to);
    if (!p.path) return p;
    p.waypoints = decimateWaypoints(planner, *p.path, opts.waypoint_spacing);
    p.min_clearance = std::numeric_limits<double>::infinity();
    std::size_t unknown = 0;
    for (const auto& q : p.path->points) {
        p.min_clearance = std::min(p.min_clearance, planner.clearance(q));
        const float f = grid.getCell(grid.x2idx(q.x), grid.y2idx(q.y));
        if (std::abs(f - 0.5f) < 0.01f) ++unknown;
    }
    p.unknown_fraction =
        p.path->points.empty() ? 0.0 : double(unknown) / double(p.path->points.size());
    return p;
}

void writeMapPlanPng(const mrpt::maps::COccupancyGridMap2D& grid, const MapPlan& plan,
                     const std::string& path, const std::string& title) {
    const int gw = static_cast<int>(grid.getSizeX()), gh = static_cast<int>(grid.getSizeY());
    // at least 600 px across, whole pixels per cell
    const int k = std::max(1, static_cast<int>(std::ceil(600.0 / std::max(gw, gh))));
    const int margin_top = 40;
    cv::Mat img(gh * k + margin_top, gw * k, CV_8UC3, cv::Scalar(255, 255, 255));
    for (int y = 0; y < gh; ++y)
        for (int x = 0; x < gw; ++x) {
            const auto v = static_cast<unsigned char>(std::lround(255.0 * grid.getCell(x, y)));
            // y up in the map, down in the image
            img(cv::Rect(x * k, margin_top + (gh - 1 - y) * k, k, k)).setTo(cv::Scalar(v, v, v));
        }
    auto px = [&](const mrpt::math::TPoint2D& q) {
        return cv::Point(
            static_cast<int>(std::lround((q.x - grid.getXMin()) / grid.getResolution() * k)),
            margin_top + gh * k - 1 -
                static_cast<int>(std::lround((q.y - grid.getYMin()) / grid.getResolution() * k)));
    };
    for (double x = std::ceil(grid.getXMin()); x <= grid.getXMax(); x += 1.0)
        cv::line(img, px({x, grid.getYMin()}), px({x, grid.getYMax()}), cv::Scalar(200, 220, 200),
                 1);
    for (double y = std::ceil(grid.getYMin()); y <= grid.getYMax(); y += 1.0)
        cv::line(img, px({grid.getXMin(), y}), px({grid.getXMax(), y}), cv::Scalar(200, 220, 200),
                 1);
    if (plan.path) {
        std::vector<cv::Point> pts;
        for (const auto& q : plan.path->points) pts.push_back(px(q));
        if (pts.size() >= 2)
            cv::polylines(img, pts, false, cv::Scalar(220, 120, 0), 2, cv::LINE_AA);
        for (const auto& q : plan.waypoints)
            cv::circle(img, px(q), 4, cv::Scalar(220, 120, 0), cv::FILLED, cv::LINE_AA);
    }
    cv::drawMarker(img, px(plan.from), cv::Scalar(0, 160, 0), cv::MARKER_SQUARE, 14, 2);
    cv::drawMarker(img, px(plan.to), cv::Scalar(0, 0, 220), cv::MARKER_STAR, 16, 2);
    cv::rectangle(img, cv::Point(0, 0), cv::Point(img.cols, margin_top - 1),
                  cv::Scalar(250, 250, 250), cv::FILLED);
    std::ostringstream os;
    os.precision(3);
    os << title << ": ";
    if (plan.path)
        os << "path " << plan.path->length << " m, " << plan.waypoints.size()
           << " waypoints, clearance >= " << plan.min_clearance << " m";
    else
        os << "no path";
    cv::putText(img, os.str(), cv::Point(8, 15), cv::FONT_HERSHEY_SIMPLEX, 0.45,
                cv::Scalar(20, 20, 20), 1, cv::LINE_AA);
    cv::putText(img,
                "white free, black occupied, grey unknown; blue: A* + waypoints; green: "
                "start; star: goal; 1 m grid",
                cv::Point(8, 33), cv::FONT_HERSHEY_SIMPLEX, 0.38, cv::Scalar(60, 60, 60), 1,
                cv::LINE_AA);
    if (!cv::imwrite(path, img)) throw std::runtime_error(path + ": cannot write the picture");
}

}  // namespace devslam::nav
