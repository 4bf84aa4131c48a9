#pragma once
/// Camera trajectory generators shaped like the TUM fr3 hand-held sequences:
/// `xyz` (translation along the three axes), `static` (a few mm of jitter), `halfsphere`
/// (orbit on a half sphere around a point), `rpy` (rotation about the three axes).
/// Amplitudes and periods default to values whose mean speeds are TUM fr3's: xyz 0.21 m/s
/// and 5.5 deg/s (walking_xyz), static 0.01 m/s and 1.6 deg/s (walking_static: 1.4),
/// halfsphere 18 deg/s, rpy 53 deg/s: docs/render.md, "Camera speeds" (`devslam-synth
/// --list` prints each scenario's). Pure functions of time.
///
/// Usage:
///   devslam::render::TrajectoryOptions o; o.type = TrajectoryType::Xyz;
///   mrpt::poses::CPose3D T_wc = devslam::render::cameraPoseAt(o, 1.5);

#include <mrpt/poses/CPose3D.h>

#include <Eigen/Core>

#include <string>

namespace mrpt::config {
class CConfigFileBase;
}

namespace devslam::render {

enum class TrajectoryType { Static, Xyz, Halfsphere, Rpy };
/// "static" | "xyz" | "halfsphere" | "rpy"; throws std::invalid_argument listing them.
[[nodiscard]] TrajectoryType parseTrajectoryType(const std::string& name);
[[nodiscard]] std::string toString(TrajectoryType t);

struct TrajectoryOptions {
    TrajectoryType type = TrajectoryType::Xyz;
    Eigen::Vector3d position{0.6, 2.5, 1.3};  ///< mean optical centre in the world [m]
    Eigen::Vector3d look_at{4.0, 2.5, 1.0};   ///< point the mean view direction aims at [m]
    /// xyz/static: translation amplitude along camera right, down, forward [m].
    Eigen::Vector3d amplitude{0.35, 0.15, 0.25};
    /// xyz/static: periods of the three translation sines [s].
    Eigen::Vector3d period{8.0, 10.5, 13.0};
    /// rpy/all: rotation amplitude about camera forward (roll), right (pitch), down (yaw) [deg].
    Eigen::Vector3d rot_amplitude_deg{2.0, 3.0, 4.0};
    /// periods of the three rotation sines [s].
    Eigen::Vector3d rot_period{3.0, 4.0, 5.0};
    /// halfsphere: azimuth and elevation swing around the mean direction [deg], their periods [s].
    double azimuth_amplitude_deg = 30.0, elevation_amplitude_deg = 10.0;
    double azimuth_period = 8.0, elevation_period = 5.5;

    /// Reads `[section]` (all keys optional, defaults for the chosen type; unknown keys rejected).
    void loadFromConfig(const mrpt::config::CConfigFileBase& cfg, const std::string& section);
    /// Defaults that give TUM fr3-like speeds for `t` (keeps position/look_at).
    void setDefaultsFor(TrajectoryType t);
};

/// Pose T_wc of the optical centre (x right, y down, z forward) at time t [s] since start.
[[nodiscard]] mrpt::poses::CPose3D cameraPoseAt(const TrajectoryOptions& o, double t);

/// The camera's mean speeds over `n_frames` frames at `rate_hz` from time 0, as TUM's
/// dataset tables give theirs: the path's length and its frame-to-frame rotation angles
/// summed, over the duration.
struct TrajectorySpeeds {
    double m_per_s = 0;
    double deg_per_s = 0;
};
[[nodiscard]] TrajectorySpeeds meanSpeeds(const TrajectoryOptions& o, std::size_t n_frames,
                                          double rate_hz);

/// Optical-frame orientation looking from `eye` towards `target` with world z up
/// (the image's "down" is world -z). Throws std::invalid_argument if they coincide or
/// the view is vertical.
[[nodiscard]] mrpt::poses::CPose3D lookAtPose(const Eigen::Vector3d& eye,
                                              const Eigen::Vector3d& target);

}  // namespace devslam::render
