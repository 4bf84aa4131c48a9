#pragma once
/// A synthetic RGB-D scenario: a textured room, people, a camera trajectory, sensor noise,
/// all read from a commented INI file in sim_worlds/synth/ (see docs/render.md).
///
/// Usage:
///   auto sc = devslam::render::loadScenario("sim_worlds/synth/walking_xyz.ini");
///   devslam::render::SequenceRenderer r(sc);       // SequenceRenderer.h
///   auto f = r.render(0);

#include <devslam/core/Camera.h>
#include <devslam/render/CameraTrajectory.h>
#include <devslam/render/DepthNoise.h>
#include <devslam/render/PersonMotion.h>

#include <Eigen/Core>

#include <cstdint>
#include <string>
#include <vector>

namespace devslam::render {

/// An axis-aligned (up to yaw) box standing on the floor: desk, shelf, crate.
struct BoxSpec {
    std::string name;                   ///< INI section name, for messages
    Eigen::Vector3d base{0, 0, 0};      ///< centre of the bottom face in the world [m]
    Eigen::Vector3d size{1, 1, 1};      ///< extent along its own x, y, z [m]
    double yaw = 0.0;                   ///< rotation about world z [rad]
    std::vector<std::string> textures;  ///< images (absolute paths), used round-robin per face
    double blur = 0.0;  ///< Gaussian sigma [px of the photo] applied to its photos (0 = sharp)
};

/// A closed room with textured walls, floor and ceiling made of photo panels.
struct RoomSpec {
    Eigen::Vector3d size{6, 5, 2.8};  ///< room extent; the room spans [0,sx] x [0,sy] x [0,sz] [m]
    double panel_width = 1.2;         ///< wall/floor panel width [m] (one photo crop each)
    double panel_height = 0.9;        ///< wall/floor panel height [m]
    std::vector<std::string> wall_textures;   ///< photo files (absolute paths)
    std::vector<std::string> floor_textures;  ///< photo files (absolute paths)
    /// Gaussian blur of the wall/ceiling and floor photos before they are cropped [px of the
    /// photo, sigma], 0 = sharp: painted walls and a carpet with a few soft shapes, whose
    /// corners do not outnumber those of the people and the furniture (docs/render.md).
    double wall_blur = 0.0;
    double floor_blur = 0.0;
    std::string source;  ///< the room INI file it was read from
    /// the scenario's `room_set` items applied over that file, in order
    std::vector<std::string> overrides;
    std::vector<BoxSpec> boxes;
};

/// The most frames a scenario may have (loadScenario): 55 min at 30 Hz.
inline constexpr int kMaxFrames = 100000;

struct Scenario {
    std::string name;          ///< [scenario] name
    std::string source;        ///< the INI file it was read from (the room's: room.source)
    /// "section.key=value" items applied over the scenario file (loadScenario), in order
    std::vector<std::string> overrides;
    core::CameraIntrinsics K;  ///< exact intrinsics of the rendered images (TUM fr3 by default)
    double rate_hz = 30.0;     ///< frame rate [Hz]
    std::size_t n_frames = 60;
    double t0 = 1700000000.0;      ///< timestamp of frame 0 [s]
    std::uint64_t seed = 1;        ///< seeds the depth/colour noise and panel crops
    double rgb_noise_sigma = 1.5;  ///< Gaussian colour noise [8-bit grey levels], 0 = none
    double near_clip = 0.05, far_clip = 30.0;  ///< GL clip planes [m]
    /// Texture sampling: bilinear (true, `texture_filter = linear`) or nearest texel
    /// (`nearest`, MRPT's default and the renderer's before version 3). Nearest sampling
    /// magnifies a photo into blocks whose corners ORB finds and tracks (a walker 0.55 m
    /// from the camera shows 7x7-pixel texels) and makes edges jump a whole pixel as the
    /// camera moves; a camera sees neither (docs/render.md, "Texture sampling").
    bool texture_linear = true;
    RoomSpec room;
    std::vector<PersonSpec> people;
    TrajectoryOptions trajectory;
    DepthNoiseOptions depth_noise;

    /// Timestamp of frame i [s].
    [[nodiscard]] double timeOf(std::size_t i) const { return t0 + double(i) / rate_hz; }
    /// Seconds since frame 0 of frame i.
    [[nodiscard]] double elapsed(std::size_t i) const { return double(i) / rate_hz; }
};

/// Reads a scenario INI (sections [scenario], [camera], [trajectory], [depth_noise],
/// [person_*]) and the room file it names (`room = office_room.ini`, relative to the
/// scenario file; sections [room], [box_*]). Relative texture paths are resolved against
/// the directory of the file that names them; a directory stands for all its *.png/*.jpg
/// files in name order. Throws std::invalid_argument / std::runtime_error naming the file,
/// section and key on any unknown key, missing file, or out-of-range value.
/// `overrides`: "section.key=value" items written over the scenario file's settings before
/// it is read (devslam-synth --set; sections of the scenario file, not of the room), checked
/// like the file's own keys. The scenario's own `room_set` (whitespace-separated
/// "section.key=value" items) is written over the room file's settings the same way, on
/// its [room] and existing [box_*] sections: one room file serves variants such as
/// sitting_bare's blurred furniture.
[[nodiscard]] Scenario loadScenario(const std::string& path,
                                    const std::vector<std::string>& overrides = {});

}  // namespace devslam::render
