#include <devslam/render/PersonMotion.h>

#include <cmath>
#include <stdexcept>

namespace devslam::render {
namespace {
constexpr double kPi = 3.14159265358979323846;
constexpr double kStepFrequency = 1.8;  ///< walking steps per second [Hz] (vertical bob)
constexpr double kGestureLift = 0.005;  ///< the hand's offset towards the viewer [m]

double gestureAngle(const PersonSpec& p, double t) {
    return p.gestures() ? p.gesture_deg * kPi / 180.0 * std::sin(2 * kPi * t / p.gesture_period)
                        : 0.0;
}
}  // namespace

PersonKind parsePersonKind(const std::string& name) {
    if (name == "walking") return PersonKind::Walking;
    if (name == "sitting") return PersonKind::Sitting;
    if (name == "standing") return PersonKind::Standing;
    throw std::invalid_argument("unknown person kind '" + name +
                                "' (known: walking, sitting, standing)");
}

std::string toString(PersonKind k) {
    switch (k) {
        case PersonKind::Walking:
            return "walking";
        case PersonKind::Sitting:
            return "sitting";
        case PersonKind::Standing:
            return "standing";
    }
    return "?";
}

mrpt::poses::CPose3D personPhotoPose(const PersonSpec& p, const PersonState& s,
                                     const Eigen::Vector3d& eye, const Eigen::Vector3d& first_eye) {
    const Eigen::Vector3d& b = s.position;
    const Eigen::Vector3d& facing = p.kind == PersonKind::Walking ? eye : first_eye;
    const double yaw = std::atan2(-(facing.x() - b.x()), facing.y() - b.y());
    // Rotating about the pivot: shift the origin by what the rotation does to the pivot.
    const mrpt::poses::CPose3D R(0, 0, 0, yaw, s.sway, 0);
    double ox = 0, oy = 0, oz = 0;
    R.composePoint(0, 0, p.sway_pivot, ox, oy, oz);
    return {b.x() - ox, b.y() - oy, b.z() + p.sway_pivot - oz, yaw, s.sway, 0};
}

mrpt::poses::CPose3D gestureLocalPose(const PersonSpec& p, const PersonState& s, double width) {
    // The photo's local frame has texture column 0 at +x and row 0 at z = height.
    const double px = width / 2 - p.gesture_pivot.x() * width;
    const double pz = p.height - p.gesture_pivot.y() * p.height;
    const mrpt::poses::CPose3D R(0, 0, 0, 0, s.gesture, 0);
    double ox = 0, oy = 0, oz = 0;
    R.composePoint(px, 0, pz, ox, oy, oz);
    return {px - ox, kGestureLift - oy, pz - oz, 0, s.gesture, 0};
}

double pathLength(const std::vector<Eigen::Vector2d>& path) {
    double L = 0;
    for (std::size_t i = 1; i < path.size(); ++i) L += (path[i] - path[i - 1]).norm();
    return L;
}

PersonState personStateAt(const PersonSpec& p, double t) {
    PersonState s;
    if (p.path.empty()) throw std::invalid_argument("person '" + p.name + "': empty path");
    if (p.kind != PersonKind::Walking || p.path.size() < 2) {
        s.position = {p.path[0].x(), p.path[0].y(), p.base_z};
        s.sway = p.sway_period > 0
                     ? p.sway_deg * kPi / 180.0 * std::sin(2 * kPi * t / p.sway_period)
                     : 0.0;
        s.gesture = gestureAngle(p, t);
        return s;
    }
    const double L = pathLength(p.path);
    // Ping-pong: arc length folded into [0, L].
    double a = std::fmod(p.start_offset + p.speed * t, 2 * L);
    if (a < 0) a += 2 * L;
    const bool back = a > L;
    const double arc = back ? 2 * L - a : a;
    double acc = 0;
    for (std::size_t i = 1; i < p.path.size(); ++i) {
        const Eigen::Vector2d seg = p.path[i] - p.path[i - 1];
        const double len = seg.norm();
        if (acc + len >= arc || i + 1 == p.path.size()) {
            const double f = len > 0 ? std::min(1.0, (arc - acc) / len) : 0.0;
            const Eigen::Vector2d xy = p.path[i - 1] + f * seg;
            const double bob = p.bob * std::abs(std::sin(kPi * kStepFrequency * t));
            s.position = {xy.x(), xy.y(), p.base_z + bob};
            s.velocity = len > 0 ? Eigen::Vector2d(seg / len * p.speed * (back ? -1 : 1))
                                 : Eigen::Vector2d::Zero();
            break;
        }
        acc += len;
    }
    s.moving = p.speed > 0;
    s.gesture = gestureAngle(p, t);
    return s;
}

}  // namespace devslam::render
