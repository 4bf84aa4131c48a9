#pragma once
/// Scripted people: walkers follow a polyline back and forth at constant speed (with a
/// small vertical bob); sitting/standing people stay in place with a small side sway of
/// the torso, and any person may move a hand (a region of the photo that swings about a
/// pivot in the photo's plane). Pure functions of time.
///
/// Usage:
///   devslam::render::PersonSpec p; p.kind = PersonKind::Walking; p.path = {{2,1},{2,4}};
///   auto s = devslam::render::personStateAt(p, t);   // s.position, s.sway, s.moving

#include <mrpt/poses/CPose3D.h>
#include <Eigen/Core>

#include <string>
#include <vector>

namespace devslam::render {

enum class PersonKind { Walking, Sitting, Standing };
/// "walking" | "sitting" | "standing"; throws std::invalid_argument listing them.
[[nodiscard]] PersonKind parsePersonKind(const std::string& name);
[[nodiscard]] std::string toString(PersonKind k);

struct PersonSpec {
    std::string name;  ///< INI section name (person_1 ...)
    PersonKind kind = PersonKind::Walking;
    std::string texture;   ///< RGBA PNG (absolute path): the person's photo, alpha = silhouette
    double height = 1.75;  ///< height of the photo's full extent in the world [m]
    std::vector<Eigen::Vector2d>
        path;                   ///< walking: polyline on the floor; others: path[0] = place [m]
    double speed = 0.8;         ///< walking speed along the path [m/s]
    double start_offset = 0.0;  ///< walking: arc length already walked at t = 0 [m]
    double base_z = 0.0;    ///< height of the photo's bottom edge above the floor [m] (sitting: < 0
                            ///< hides legs in a desk)
    double sway_deg = 3.0;  ///< sitting/standing: side sway amplitude [deg]
    double sway_period = 3.0;  ///< [s]
    double sway_pivot = 0.0;   ///< height of the sway axis above the photo's bottom edge [m]
                               ///< (0: the whole photo sways about its bottom edge; a seated
                               ///< person's torso sways about the hips)
    double bob = 0.02;         ///< walking: vertical bob amplitude [m]
    /// Hand motion (a gesture): the photo's cells inside gesture_region (an arm, a hand)
    /// swing in the photo's plane about gesture_pivot (a shoulder, an elbow). Both are given as
    /// fractions of the photo's width (from its left edge) and height (from its top edge).
    double gesture_deg = 0.0;                    ///< swing amplitude [deg] (0: no hand motion)
    double gesture_period = 2.0;                 ///< [s]
    Eigen::Vector4d gesture_region{0, 0, 0, 0};  ///< [left top right bottom], fractions
    Eigen::Vector2d gesture_pivot{0, 0};         ///< [across down], fractions
    [[nodiscard]] bool gestures() const { return gesture_deg != 0.0; }
};

struct PersonState {
    Eigen::Vector3d position{0, 0, 0};  ///< bottom centre of the photo in the world [m]
    double sway = 0.0;                  ///< in-plane rotation about the sway axis [rad]
    double gesture = 0.0;               ///< the hand's in-plane rotation about its pivot [rad]
    bool moving = false;                ///< true while the person walks
    Eigen::Vector2d velocity{0, 0};     ///< on the floor [m/s]
};

/// State at time t [s] since the start of the sequence. Walkers go along the path and back
/// (ping-pong), so their motion is continuous and never ends.
[[nodiscard]] PersonState personStateAt(const PersonSpec& p, double t);

/// World pose of the person's photo in state s: the photo faces a camera position (yaw
/// about z only) and sways in its own plane about a horizontal axis sway_pivot above its
/// bottom edge, which stays fixed. A walker faces the camera where it is now (`eye`); a
/// sitting or standing person faces where it was in the first frame (`first_eye`) and keeps
/// that yaw, so that apart from the sway they are rigid, as the person truth says they are
/// (they turned with the camera until session 22: points at the photo's edges moved by
/// centimetres in depth). Local frame: x along the photo's width, z up its height, origin
/// at the bottom centre (where s.position is when unswayed).
[[nodiscard]] mrpt::poses::CPose3D personPhotoPose(const PersonSpec& p, const PersonState& s,
                                                   const Eigen::Vector3d& eye,
                                                   const Eigen::Vector3d& first_eye);

/// Pose of the hand (the cells in p.gesture_region) relative to the photo's pose, for a
/// photo `width` x p.height metres: rotated by s.gesture about the pivot, in the photo's
/// plane, and 5 mm in front of it so that it covers the body where it swings over it.
[[nodiscard]] mrpt::poses::CPose3D gestureLocalPose(const PersonSpec& p, const PersonState& s,
                                                    double width);

/// Length of a polyline [m].
[[nodiscard]] double pathLength(const std::vector<Eigen::Vector2d>& path);

}  // namespace devslam::render
