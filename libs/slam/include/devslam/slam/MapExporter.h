#pragma once
/// Map products: a coloured point cloud (PLY), an MRPT 3D scene (.3Dscene, opens in
/// SceneViewer3D), and a 2D occupancy grid for the navigator (COccupancyGridMap2D, PNG and
/// MRPT's serialized .gridmap).
///
/// Frames: the SLAM world is the first keyframe's optical frame (x right, y down, z
/// forward). The 3D scene and the grid use the robot-style "nav" frame of that camera:
/// x_nav = z (forward), y_nav = -x (left), z_nav = -y (up).
///
/// Usage:
///   devslam::slam::writePly("map.ply", slam.map());
///   auto grid = devslam::slam::buildOccupancyGrid(slam.map(), {});
///   devslam::slam::saveGrid(*grid, "map_grid");   // map_grid.png + map_grid.gridmap
#include <devslam/core/Trajectory.h>
#include <devslam/slam/Map.h>

#include <mrpt/maps/COccupancyGridMap2D.h>

#include <optional>
#include <string>

namespace mrpt::config {
class CConfigFileBase;
}

namespace devslam::slam {

/// The SLAM world (optical) point in the nav frame (see file comment).
[[nodiscard]] inline Eigen::Vector3d opticalToNav(const Eigen::Vector3d& p) {
    return {p.z(), -p.x(), -p.y()};
}

/// ASCII PLY with x y z (SLAM world frame, metres) and red green blue. Throws
/// std::runtime_error naming the path if it cannot be written.
void writePly(const std::string& path, const Map& map);

/// Point cloud, keyframe axes, the estimated trajectory (red) and, if given, the aligned
/// ground truth (green), in the nav frame. Throws std::runtime_error on a write failure.
void write3DScene(const std::string& path, const Map& map, const core::Trajectory& estimate,
                  const std::optional<core::Trajectory>& ground_truth = std::nullopt);

struct GridMapOptions {
    double resolution = 0.05;  ///< [m] cell side
    double min_height = -1.2;  ///< [m] landmarks below this height (nav z, relative to the
                               ///< first camera) are floor, not obstacles
    double max_height = 0.5;   ///< [m] above this: ceiling, ignored
    double margin = 0.5;       ///< [m] grid border around the data
    double max_range = 5.0;    ///< [m] longer rays are not traced

    void loadFromConfig(const mrpt::config::CConfigFileBase& cfg,
                        const std::string& section = "grid_map");
};

/// Occupancy grid (P(free) cells, MRPT convention) from the landmarks: each keyframe traces
/// free space from its camera to the landmarks it observes within the height band and
/// marks the landmark cell occupied. std::nullopt for an empty map.
[[nodiscard]] std::optional<mrpt::maps::COccupancyGridMap2D> buildOccupancyGrid(
    const Map& map, const GridMapOptions& opts);

/// Writes `<stem>.png` (north-up picture) and `<stem>.gridmap` (MRPT archive, gz). Throws
/// std::runtime_error naming the file on failure.
void saveGrid(const mrpt::maps::COccupancyGridMap2D& grid, const std::string& stem);

}  // namespace devslam::slam
