#pragma once
/// TUM trajectory files: `timestamp tx ty tz qx qy qz qw`, '#' comments, any whitespace.
///
/// Usage:
///   auto gt = devslam::io::readTumTrajectory("groundtruth.txt");
///   devslam::io::writeTumTrajectory("est.txt", est);

#include <devslam/core/Trajectory.h>

#include <string>

namespace devslam::io {

/// Positions beyond this [m] are refused by readTumTrajectory.
inline constexpr double kMaxTrajectoryCoordinate = 1e6;

/// Throws std::runtime_error "<path> line N: ..." for a line without 8 numbers, a
/// non-unit quaternion, a position coordinate beyond +-1e6 m, or a timestamp not greater
/// than the previous one; "<path>: no poses" for a file without any.
[[nodiscard]] core::Trajectory readTumTrajectory(const std::string& path);

/// Writes with full precision (timestamps with 6 decimals like TUM, poses with 9 digits).
/// Throws std::runtime_error if the file cannot be written.
void writeTumTrajectory(const std::string& path, const core::Trajectory& traj,
                        const std::string& header_comment = {});

}  // namespace devslam::io
