#include <devslam/core/Pose.h>

#include <mrpt/math/CMatrixFixed.h>

#include <cmath>
#include <stdexcept>

namespace devslam::core {

Eigen::Isometry3d toIsometry(const mrpt::poses::CPose3D& p) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.matrix() = p.getHomogeneousMatrixVal<mrpt::math::CMatrixDouble44>().asEigen();
    return T;
}

mrpt::poses::CPose3D toCPose3D(const Eigen::Isometry3d& T) {
    mrpt::math::CMatrixDouble44 M;
    M.asEigen() = T.matrix();
    return mrpt::poses::CPose3D(M);
}

mrpt::poses::CPose3D fromTum(double tx, double ty, double tz, double qx, double qy, double qz,
                             double qw) {
    const double n = std::sqrt(qx * qx + qy * qy + qz * qz + qw * qw);
    constexpr double kNormTolerance = 1e-3;
    if (!(std::abs(n - 1.0) <= kNormTolerance))
        throw std::invalid_argument("quaternion norm " + std::to_string(n) + " is not 1");
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = Eigen::Quaterniond(qw / n, qx / n, qy / n, qz / n).toRotationMatrix();
    T.translation() = Eigen::Vector3d(tx, ty, tz);
    return toCPose3D(T);
}

double rotationAngle(const mrpt::poses::CPose3D& p) {
    // The same angle as TUM's compute_angle, arccos((trace(R) - 1) / 2), but evaluated as
    // 2 atan2(|q_vec|, |q_w|): arccos loses half the digits near 0 (1e-8 rad noise).
    const Eigen::Quaterniond q(p.getRotationMatrix().asEigen());
    return 2.0 * std::atan2(q.vec().norm(), std::abs(q.w()));
}

double wrapToPi(double a) {
    a = std::fmod(a + M_PI, 2.0 * M_PI);
    if (a <= 0) a += 2.0 * M_PI;
    return a - M_PI;
}

}  // namespace devslam::core
