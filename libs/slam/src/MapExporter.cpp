#include <devslam/core/Config.h>
#include <devslam/core/GzFile.h>
#include <devslam/core/Picture.h>
#include <devslam/core/Pose.h>
#include <devslam/core/Results.h>
#include <devslam/slam/MapExporter.h>

#include <mrpt/config/CConfigFileBase.h>
#include <mrpt/img/CImage.h>
#include <mrpt/opengl/CGridPlaneXY.h>
#include <mrpt/opengl/COpenGLScene.h>
#include <mrpt/opengl/CPointCloudColoured.h>
#include <mrpt/opengl/CSetOfLines.h>
#include <mrpt/opengl/stock_objects.h>
#include <mrpt/serialization/CArchive.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <sstream>
#include <stdexcept>

namespace devslam::slam {

void writePly(const std::string& path, const Map& map) {
    std::ostringstream out;  // written whole or not at all, and a failure says why
    out << "ply\nformat ascii 1.0\ncomment DEV-SLAM landmarks, SLAM world frame (first camera "
           "optical frame), metres\nelement vertex "
        << map.landmarks().size()
        << "\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\n"
           "property uchar green\nproperty uchar blue\nend_header\n";
    // Deterministic order: by landmark id.
    std::vector<LandmarkId> ids;
    ids.reserve(map.landmarks().size());
    for (const auto& [id, lm] : map.landmarks()) ids.push_back(id);
    std::sort(ids.begin(), ids.end());
    char line[128];
    for (LandmarkId id : ids) {
        const Landmark& l = *map.landmark(id);
        std::snprintf(line, sizeof line, "%.5f %.5f %.5f %d %d %d\n", l.p_w.x(), l.p_w.y(),
                      l.p_w.z(), l.color[2], l.color[1], l.color[0]);
        out << line;
    }
    try {
        core::writeFileWhole(path, out.str());
    } catch (const std::exception& e) {  // "cannot write 'PATH': why"
        throw std::runtime_error(std::string("PLY: ") + e.what());
    }
}

namespace {
mrpt::poses::CPose3D navPose(const Eigen::Isometry3d& T_wc) {
    Eigen::Matrix3d R_nav_opt;
    R_nav_opt << 0, 0, 1, -1, 0, 0, 0, -1, 0;
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = R_nav_opt * T_wc.linear();
    T.translation() = R_nav_opt * T_wc.translation();
    return core::toCPose3D(T);
}

mrpt::opengl::CSetOfLines::Ptr polyline(const core::Trajectory& traj, float r, float g, float b) {
    auto lines = mrpt::opengl::CSetOfLines::Create();
    lines->setColor(r, g, b);
    lines->setLineWidth(2.0f);
    for (std::size_t i = 1; i < traj.size(); ++i) {
        const auto a =
            opticalToNav({traj[i - 1].pose.x(), traj[i - 1].pose.y(), traj[i - 1].pose.z()});
        const auto c = opticalToNav({traj[i].pose.x(), traj[i].pose.y(), traj[i].pose.z()});
        lines->appendLine(a.x(), a.y(), a.z(), c.x(), c.y(), c.z());
    }
    return lines;
}
}  // namespace

void write3DScene(const std::string& path, const Map& map, const core::Trajectory& estimate,
                  const std::optional<core::Trajectory>& ground_truth) {
    mrpt::opengl::COpenGLScene scene;
    auto cloud = mrpt::opengl::CPointCloudColoured::Create();
    cloud->setPointSize(3.0f);
    for (const auto& [id, l] : map.landmarks()) {
        const auto p = opticalToNav(l.p_w);
        cloud->push_back(static_cast<float>(p.x()), static_cast<float>(p.y()),
                         static_cast<float>(p.z()), l.color[2] / 255.f, l.color[1] / 255.f,
                         l.color[0] / 255.f);
    }
    scene.insert(cloud);
    for (const auto& [id, kf] : map.keyframes()) {
        auto axes = mrpt::opengl::stock_objects::CornerXYZSimple(0.05f, 2.0f);
        axes->setPose(navPose(kf.T_wc));
        scene.insert(axes);
    }
    scene.insert(polyline(estimate, 1.f, 0.f, 0.f));
    if (ground_truth) scene.insert(polyline(*ground_truth, 0.f, 0.8f, 0.f));
    scene.insert(mrpt::opengl::CGridPlaneXY::Create(-2, 2, -2, 2, -1.0, 0.5));
    // (COpenGLScene::saveToFile's gzip stream cut the file short on a full disk, saying
    // nothing: the same archive through core::writeGzFileWhole.)
    core::writeGzFileWhole(path, "3D scene", [&](mrpt::io::CStream& s) {
        mrpt::serialization::archiveFrom(s) << scene;
    });
}

void GridMapOptions::loadFromConfig(const mrpt::config::CConfigFileBase& c, const std::string& s) {
    core::requireKnownKeys(c, s, {"resolution", "min_height", "max_height", "margin", "max_range"});
    resolution = core::readDouble(c, s, "resolution", resolution);
    min_height = core::readDouble(c, s, "min_height", min_height);
    max_height = core::readDouble(c, s, "max_height", max_height);
    margin = core::readDouble(c, s, "margin", margin);
    max_range = core::readDouble(c, s, "max_range", max_range);
    core::requireValue(resolution >= 0.001 && resolution <= 10, s, "resolution",
                       "must be in [0.001, 10] [m]");
    core::requireValue(max_height > min_height, s, "min_height/max_height",
                       "need min_height < max_height");
    core::requireValue(margin >= 0 && margin <= 100 && max_range > 0 && max_range <= 1000, s,
                       "margin/max_range", "must be in [0, 100] / (0, 1000] [m]");
    // The margins alone make (2 margin / resolution)^2 cells: over the 1e8 the grid may have,
    // the map was refused only when written, at the end of the run.
    core::requireValue(std::pow(2 * margin / resolution, 2) <= 1e8, s, "margin",
                       "2 x margin / resolution squared is more than the 1e8 cells a grid may "
                       "have: lower margin or coarsen resolution");
}

std::optional<mrpt::maps::COccupancyGridMap2D> buildOccupancyGrid(const Map& map,
                                                                  const GridMapOptions& opts) {
    if (map.landmarks().empty() || map.keyframes().empty()) return std::nullopt;
    double x0 = 1e9, x1 = -1e9, y0 = 1e9, y1 = -1e9;
    auto extend = [&](const Eigen::Vector3d& p) {
        if (!p.allFinite()) return;
        x0 = std::min(x0, p.x());
        x1 = std::max(x1, p.x());
        y0 = std::min(y0, p.y());
        y1 = std::max(y1, p.y());
    };
    for (const auto& [id, kf] : map.keyframes()) extend(opticalToNav(kf.T_wc.translation()));
    for (const auto& [id, l] : map.landmarks()) {
        const auto p = opticalToNav(l.p_w);
        if (p.z() >= opts.min_height && p.z() <= opts.max_height) extend(p);
    }
    if (x1 < x0 || y1 < y0) return std::nullopt;  // no finite point
    // A grid MRPT can hold, drawn in seconds: 1e8 cells is 10 x 10 km at 1 m or 100 x 100 m at
    // 1 cm. (Points far from the rest made it loop for good before the cameras were checked.)
    const double cells = (x1 - x0 + 2 * opts.margin) / opts.resolution *
                         ((y1 - y0 + 2 * opts.margin) / opts.resolution);
    if (!(cells <= 1e8)) {
        std::ostringstream m;
        m << "[grid_map] resolution: the map spans " << x1 - x0 << " x " << y1 - y0
          << " m, which at " << opts.resolution << " m (margin " << opts.margin << " m) is "
          << cells << " cells (at most 1e8)";
        throw std::invalid_argument(m.str());
    }
    mrpt::maps::COccupancyGridMap2D grid;
    grid.setSize(static_cast<float>(x0 - opts.margin), static_cast<float>(x1 + opts.margin),
                 static_cast<float>(y0 - opts.margin), static_cast<float>(y1 + opts.margin),
                 static_cast<float>(opts.resolution), 0.5f);
    const int W = static_cast<int>(grid.getSizeX()), H = static_cast<int>(grid.getSizeY());
    for (const auto& [kid, kf] : map.keyframes()) {
        const auto c = opticalToNav(kf.T_wc.translation());
        const int cx = grid.x2idx(static_cast<float>(c.x())),
                  cy = grid.y2idx(static_cast<float>(c.y()));
        for (LandmarkId lid : kf.landmark_of_kp) {
            if (lid == kNoId) continue;
            const Landmark* l = map.landmark(lid);
            if (!l) continue;
            const auto p = opticalToNav(l->p_w);
            // (A NaN passes the tests below, and its cell index is no number: Bresenham's
            // walk to it went on for some 2^31 steps.)
            if (!p.allFinite()) continue;
            if (p.z() < opts.min_height || p.z() > opts.max_height) continue;
            if ((p.head<2>() - c.head<2>()).norm() > opts.max_range) continue;
            const int px = grid.x2idx(static_cast<float>(p.x())),
                      py = grid.y2idx(static_cast<float>(p.y()));
            // Bresenham from the camera cell to the landmark cell: free, then occupied.
            int x = cx, y = cy;
            const int dx = std::abs(px - cx), dy = -std::abs(py - cy);
            const int sx = cx < px ? 1 : -1, sy = cy < py ? 1 : -1;
            int err = dx + dy;
            while (!(x == px && y == py)) {
                if (x >= 0 && y >= 0 && x < W && y < H) grid.updateCell(x, y, 0.55f);
                const int e2 = 2 * err;
                if (e2 >= dy) {
                    err += dy;
                    x += sx;
                }
                if (e2 <= dx) {
                    err += dx;
                    y += sy;
                }
            }
            if (px >= 0 && py >= 0 && px < W && py < H) grid.updateCell(px, py, 0.2f);
        }
    }
    return grid;
}

void saveGrid(const mrpt::maps::COccupancyGridMap2D& grid, const std::string& stem) {
    // (saveAsBitmapFile is getAsImage + cv::imwrite: a cut picture on a full disk, no reason)
    mrpt::img::CImage img;
    grid.getAsImage(img);
    try {
        core::writePngWhole(stem + ".png", img.asCvMatRef());
    } catch (const std::exception& e) {  // "cannot write 'PATH': why"
        throw std::runtime_error(std::string("grid image: ") + e.what());
    }
    core::writeGzFileWhole(stem + ".gridmap", "grid map", [&](mrpt::io::CStream& s) {
        mrpt::serialization::archiveFrom(s) << grid;
    });
}

}  // namespace devslam::slam
