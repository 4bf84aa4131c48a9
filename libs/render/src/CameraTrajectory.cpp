#include <devslam/core/Config.h>
#include <devslam/core/Parse.h>
#include <devslam/core/Pose.h>
#include <devslam/render/CameraTrajectory.h>

#include <mrpt/config/CConfigFileBase.h>
#include <mrpt/math/CMatrixFixed.h>
#include <mrpt/math/CVectorFixed.h>

#include <Eigen/Geometry>

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace devslam::render {
namespace {
constexpr double kPi = 3.14159265358979323846;
constexpr double kDeg = kPi / 180.0;

double sine(double amp, double period, double t, double phase = 0.0) {
    return period > 0 ? amp * std::sin(2.0 * kPi * t / period + phase) : 0.0;
}

Eigen::Vector3d readVec3(const mrpt::config::CConfigFileBase& cfg, const std::string& s,
                         const std::string& key, const Eigen::Vector3d& def) {
    const auto txt = core::readTextIfPresent(cfg, s, key);
    if (!txt) return def;
    const auto v = core::parseNumberList(*txt, "[" + s + "] " + key, 3);
    return {v[0], v[1], v[2]};
}

/// Rotation about the optical axes (x right, y down, z forward): R = Rz(roll) Rx(pitch) Ry(yaw).
mrpt::poses::CPose3D opticalRotation(double roll, double pitch, double yaw) {
    const Eigen::Matrix3d R = (Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitZ()) *
                               Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitX()) *
                               Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitY()))
                                  .toRotationMatrix();
    mrpt::math::CMatrixDouble33 M;
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) M(r, c) = R(r, c);
    return mrpt::poses::CPose3D(M, mrpt::math::CVectorFixedDouble<3>());
}
}  // namespace

TrajectoryType parseTrajectoryType(const std::string& name) {
    if (name == "static") return TrajectoryType::Static;
    if (name == "xyz") return TrajectoryType::Xyz;
    if (name == "halfsphere") return TrajectoryType::Halfsphere;
    if (name == "rpy") return TrajectoryType::Rpy;
    throw std::invalid_argument("unknown trajectory type '" + name +
                                "' (known: static, xyz, halfsphere, rpy)");
}

std::string toString(TrajectoryType t) {
    switch (t) {
        case TrajectoryType::Static:
            return "static";
        case TrajectoryType::Xyz:
            return "xyz";
        case TrajectoryType::Halfsphere:
            return "halfsphere";
        case TrajectoryType::Rpy:
            return "rpy";
    }
    return "?";
}

void TrajectoryOptions::setDefaultsFor(TrajectoryType t) {
    type = t;
    switch (t) {
        case TrajectoryType::Xyz:  // 0.21 m/s, 5.5 deg/s (TUM fr3 walking_xyz: 0.21, 5.5)
            // The view direction is held, as in TUM's *_xyz: the rotation is a hand's
            // few-degree wobble, faster than the translation.
            amplitude = {0.35, 0.15, 0.25};
            period = {8.0, 10.5, 13.0};
            rot_amplitude_deg = {2.0, 3.0, 4.0};
            rot_period = {3.0, 4.0, 5.0};
            break;
        case TrajectoryType::Static:  // 0.01 m/s, 1.6 deg/s (fr3 walking_static: 0.012, 1.4)
            amplitude = {0.006, 0.004, 0.005};
            period = {2.5, 3.1, 3.7};
            rot_amplitude_deg = {0.3, 0.4, 0.5};
            rot_period = {1.5, 1.9, 2.3};
            break;
        case TrajectoryType::Halfsphere:  // 18 deg/s (fr3 walking_halfsphere: 0.22 m/s, 18)
            // The view turns at the orbit's angular rate whatever its radius; the radius
            // sets the speed (0.21 m/s at TUM's 0.7 m: walking_halfsphere.ini).
            amplitude = {0.0, 0.0, 0.0};
            rot_amplitude_deg = {2.0, 1.0, 1.0};
            rot_period = {4.0, 5.0, 6.0};
            azimuth_amplitude_deg = 30.0;
            elevation_amplitude_deg = 10.0;
            azimuth_period = 8.0;
            elevation_period = 5.5;
            break;
        case TrajectoryType::Rpy:  // 53 deg/s (fr3 walking_rpy: 53)
            amplitude = {0.02, 0.02, 0.02};
            period = {6.0, 7.0, 8.0};
            rot_amplitude_deg = {24.0, 19.0, 32.0};
            rot_period = {2.9, 3.6, 4.3};
            break;
    }
}

void TrajectoryOptions::loadFromConfig(const mrpt::config::CConfigFileBase& cfg,
                                       const std::string& s) {
    core::requireKnownKeys(
        cfg, s,
        {"type", "position", "look_at", "amplitude", "period", "rot_amplitude_deg", "rot_period",
         "azimuth_amplitude_deg", "elevation_amplitude_deg", "azimuth_period", "elevation_period"});
    try {
        setDefaultsFor(parseTrajectoryType(cfg.read_string(s, "type", toString(type))));
    } catch (const std::invalid_argument& e) {
        throw std::invalid_argument("[" + s + "] type: " + e.what());
    }
    position = readVec3(cfg, s, "position", position);
    look_at = readVec3(cfg, s, "look_at", look_at);
    amplitude = readVec3(cfg, s, "amplitude", amplitude);
    period = readVec3(cfg, s, "period", period);
    rot_amplitude_deg = readVec3(cfg, s, "rot_amplitude_deg", rot_amplitude_deg);
    rot_period = readVec3(cfg, s, "rot_period", rot_period);
    azimuth_amplitude_deg =
        core::readDouble(cfg, s, "azimuth_amplitude_deg", azimuth_amplitude_deg);
    elevation_amplitude_deg =
        core::readDouble(cfg, s, "elevation_amplitude_deg", elevation_amplitude_deg);
    azimuth_period = core::readDouble(cfg, s, "azimuth_period", azimuth_period);
    elevation_period = core::readDouble(cfg, s, "elevation_period", elevation_period);
    // Bounds no camera comes near (the shipped scenes: at most 32 deg, 2.9-16 s), so that a typo
    // fails here: a period of 1e-300 s sampled its sine at random, a rotation of 1e6 deg spun the
    // view from frame to frame, both without a word. (An amplitude that takes the camera
    // out of the room is refused by loadScenario, which checks every frame's position.)
    const auto period_ok = [](double p) { return p >= 0.1 && p <= 1e5; };
    const std::string period_msg = "must be in [0.1, 1e5] [s]";
    for (int i = 0; i < 3; ++i) {
        core::requireValue(period_ok(period[i]), s, "period", period_msg);
        core::requireValue(period_ok(rot_period[i]), s, "rot_period", period_msg);
        core::requireValue(std::abs(rot_amplitude_deg[i]) <= 90.0, s, "rot_amplitude_deg",
                           "must be in [-90, 90] [deg]");
    }
    core::requireValue(period_ok(azimuth_period), s, "azimuth_period", period_msg);
    core::requireValue(period_ok(elevation_period), s, "elevation_period", period_msg);
    core::requireValue(std::abs(azimuth_amplitude_deg) <= 180.0, s, "azimuth_amplitude_deg",
                       "must be in [-180, 180] [deg]");
    core::requireValue((look_at - position).norm() > 1e-3, s, "look_at",
                       "must differ from position");
    // lookAtPose levels the camera's roll on the horizontal: a vertical view has none.
    core::requireValue(
        (look_at - position).normalized().cross(Eigen::Vector3d::UnitZ()).norm() >= 1e-6, s,
        "look_at",
        "straight above or below position: the view needs a "
        "horizontal part to level the camera");
    if (type == TrajectoryType::Halfsphere) {
        // Over the top of the sphere the levelled view turns upside down between two frames.
        const Eigen::Vector3d d0 = position - look_at;
        const double el0 = std::asin(d0.z() / d0.norm()) / kDeg;
        const double reach = std::abs(el0) + std::abs(elevation_amplitude_deg);
        std::ostringstream m;
        m << "the orbit reaches " << reach << " deg of elevation (the mean view's " << el0
          << " deg and this amplitude); it must stay below 89 deg, where the view would turn "
             "over";
        core::requireValue(reach < 89.0, s, "elevation_amplitude_deg", m.str());
    }
}

TrajectorySpeeds meanSpeeds(const TrajectoryOptions& o, std::size_t n_frames, double rate_hz) {
    TrajectorySpeeds v;
    if (n_frames < 2 || !(rate_hz > 0)) return v;
    double length = 0, angle = 0;
    mrpt::poses::CPose3D prev = cameraPoseAt(o, 0.0);
    for (std::size_t i = 1; i < n_frames; ++i) {
        const mrpt::poses::CPose3D p = cameraPoseAt(o, double(i) / rate_hz);
        const mrpt::poses::CPose3D d = p - prev;
        length += d.norm();
        angle += core::rotationAngle(d);
        prev = p;
    }
    const double duration = double(n_frames - 1) / rate_hz;
    v.m_per_s = length / duration;
    v.deg_per_s = angle * 180.0 / M_PI / duration;
    return v;
}

mrpt::poses::CPose3D lookAtPose(const Eigen::Vector3d& eye, const Eigen::Vector3d& target) {
    const Eigen::Vector3d z = target - eye;
    if (z.norm() < 1e-9) throw std::invalid_argument("lookAtPose: eye and target coincide");
    const Eigen::Vector3d zf = z.normalized();
    Eigen::Vector3d x = zf.cross(Eigen::Vector3d::UnitZ());  // right = forward x up
    if (x.norm() < 1e-6) throw std::invalid_argument("lookAtPose: vertical view direction");
    x.normalize();
    const Eigen::Vector3d y = zf.cross(x);  // down
    mrpt::math::CMatrixDouble33 R;
    for (int r = 0; r < 3; ++r) {
        R(r, 0) = x[r];
        R(r, 1) = y[r];
        R(r, 2) = zf[r];
    }
    mrpt::math::CVectorFixedDouble<3> t;
    for (int r = 0; r < 3; ++r) t[r] = eye[r];
    return mrpt::poses::CPose3D(R, t);
}

mrpt::poses::CPose3D cameraPoseAt(const TrajectoryOptions& o, double t) {
    const auto& ra = o.rot_amplitude_deg;
    const auto& rp = o.rot_period;
    const auto wobble =
        opticalRotation(sine(ra[0] * kDeg, rp[0], t, 0.3), sine(ra[1] * kDeg, rp[1], t, 1.1),
                        sine(ra[2] * kDeg, rp[2], t, 2.0));
    if (o.type == TrajectoryType::Halfsphere) {
        // Orbit at constant radius around look_at, starting at the mean position.
        const Eigen::Vector3d d0 = o.position - o.look_at;
        const double r = d0.norm();
        const double az0 = std::atan2(d0.y(), d0.x());
        const double el0 = std::asin(d0.z() / r);
        const double az = az0 + sine(o.azimuth_amplitude_deg * kDeg, o.azimuth_period, t);
        const double el = el0 + sine(o.elevation_amplitude_deg * kDeg, o.elevation_period, t);
        const Eigen::Vector3d eye =
            o.look_at + r * Eigen::Vector3d(std::cos(el) * std::cos(az),
                                            std::cos(el) * std::sin(az), std::sin(el));
        return lookAtPose(eye, o.look_at) + wobble;
    }
    const auto base = lookAtPose(o.position, o.look_at);
    // Translation in the mean camera's own axes (right, down, forward).
    const mrpt::poses::CPose3D shift(sine(o.amplitude[0], o.period[0], t),
                                     sine(o.amplitude[1], o.period[1], t, 0.7),
                                     sine(o.amplitude[2], o.period[2], t, 1.9), 0, 0, 0);
    return base + shift + wobble;
}

}  // namespace devslam::render
