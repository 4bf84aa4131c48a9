#include <devslam/nav/MapPlan.h>

#include <devslam/core/GzFile.h>
#include <devslam/core/Picture.h>
#include <devslam/nav/RoutePicture.h>

#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/serialization/CArchive.h>

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace devslam::nav {

mrpt::maps::COccupancyGridMap2D loadGridMap(const std::string& path) {
    if (std::filesystem::is_directory(path))
        throw std::runtime_error(path + ": is a folder, not a grid map file");
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
    // 30000 x 30000 cells (a 4 MB file) took 9.7 GB before std::bad_alloc, naming no file.
    if (const double cells = double(grid.getSizeX()) * double(grid.getSizeY());
        cells > kMaxGridCells)
        throw std::runtime_error(path + ": the grid map has " + std::to_string(grid.getSizeX()) +
                                 " x " + std::to_string(grid.getSizeY()) +
                                 " cells, more than the planner takes (1e8)");
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
    cv::Mat img(gh * k + kTitleBandHeight, gw * k, CV_8UC3, cv::Scalar(255, 255, 255));
    for (int y = 0; y < gh; ++y)
        for (int x = 0; x < gw; ++x) {
            const auto v = static_cast<unsigned char>(std::lround(255.0 * grid.getCell(x, y)));
            // y up in the map, down in the image
            img(cv::Rect(x * k, kTitleBandHeight + (gh - 1 - y) * k, k, k))
                .setTo(cv::Scalar(v, v, v));
        }
    const ToPixel px = [&](const mrpt::math::TPoint2D& q) {
        return cv::Point(
            static_cast<int>(std::lround((q.x - grid.getXMin()) / grid.getResolution() * k)),
            img.rows - 1 -
                static_cast<int>(std::lround((q.y - grid.getYMin()) / grid.getResolution() * k)));
    };
    drawMetreGrid(img, px, grid.getXMin(), grid.getXMax(), grid.getYMin(), grid.getYMax(),
                  cv::Scalar(200, 220, 200));
    if (plan.path) drawRoute(img, px, plan.path->points, plan.waypoints);
    drawStartGoal(img, px, plan.from, plan.to);
    std::ostringstream os;
    os.precision(3);
    os << title << ": ";
    if (plan.path)
        os << "path " << plan.path->length << " m, " << plan.waypoints.size()
           << (plan.waypoints.size() == 1 ? " waypoint" : " waypoints")
           << ", clearance >= " << plan.min_clearance << " m";
    else
        os << "no path";
    drawTitleBand(img, os.str(),
                  "white free, black occupied, grey unknown; blue: A* + waypoints; green: "
                  "start; star: goal; 1 m grid");
    core::writePngWhole(path, img);
}

}  // namespace devslam::nav
