#pragma once
/// SE(3) helpers over mrpt::poses::CPose3D and Eigen (no Lie-group code of our own).
///
/// A camera pose T_wc maps optical-frame points to world: p_w = T_wc * p_c. TUM trajectory
/// files store exactly this pose (translation + unit quaternion qx qy qz qw).

#include <mrpt/poses/CPose3D.h>

#include <Eigen/Geometry>

namespace devslam::core {

[[nodiscard]] Eigen::Isometry3d toIsometry(const mrpt::poses::CPose3D& p);
[[nodiscard]] mrpt::poses::CPose3D toCPose3D(const Eigen::Isometry3d& T);
/// From a TUM line's translation and quaternion (qw last, as in the file). The quaternion
/// is normalised; throws std::invalid_argument when its norm is far from 1 (|n-1| > 1e-3)
/// or zero.
[[nodiscard]] mrpt::poses::CPose3D fromTum(double tx, double ty, double tz, double qx, double qy,
                                           double qz, double qw);
/// Rotation angle of a pose [rad] in [0, pi] (the TUM tools' `compute_angle`, computed
/// without its arccos round-off).
[[nodiscard]] double rotationAngle(const mrpt::poses::CPose3D& p);
/// Wraps an angle to (-pi, pi].
[[nodiscard]] double wrapToPi(double a);

}  // namespace devslam::core
