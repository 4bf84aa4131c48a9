#pragma once
/// The SLAM map on disk, to localize in it later (Slam::localizeIn, `devslam-run --localize`):
/// every keyframe (pose, ORB keypoints, descriptors, depths, colours) and every landmark
/// (position, descriptor, observers), and the camera and ORB pyramid it was made with. An
/// OpenCV FileStorage YAML file whose arrays are base64 matrices (cv::FileStorage does the
/// parsing and the exact round trip; each matrix is checked for its type and columns).
///
/// Usage:
///   devslam::slam::saveMap("slam_map.yml", slam.map(), opts.orb, reader->intrinsics());
///   devslam::slam::MapFile m = devslam::slam::loadMap("slam_map.yml");
///   slam.localizeIn(std::move(m.map));
///
/// Ids are renumbered on load (in the saved order), so a map that culled keyframes loads
/// with consecutive ids; everything else round-trips exactly.
#include <devslam/core/Camera.h>
#include <devslam/slam/Map.h>
#include <devslam/slam/OrbExtractor.h>

#include <string>

namespace devslam::slam {

struct MapFile {
    Map map;
    /// The ORB pyramid the map's keypoints come from ([orb] scale_factor, n_levels): a run
    /// localizing in it must extract with the same one (checkOrbMatches).
    double orb_scale_factor = 0;
    int orb_n_levels = 0;
    /// The camera of the run that made it: its keyframes' pixels are that camera's, so a run
    /// that adjusts them (extending the map) must use the same one (checkCameraMatches).
    core::CameraIntrinsics camera;
};

/// Writes the map whole (core::writeFileWhole: a program killed on the way leaves an earlier
/// file as it was). Throws std::runtime_error naming the path if it cannot be written.
void saveMap(const std::string& path, const Map& map, const OrbExtractor::Options& orb,
             const core::CameraIntrinsics& camera);

/// Reads a map saveMap wrote. Throws std::runtime_error naming the file and what is wrong:
/// not there, not a DEV-SLAM map, a later format version, a field missing or of the wrong
/// size (naming the keyframe or landmark), a pose that is not a rotation, an observation of
/// a keyframe or keypoint that does not exist, a file cut short.
[[nodiscard]] MapFile loadMap(const std::string& path);

/// Throws std::invalid_argument naming both when the map's ORB pyramid is not `orb`'s (a
/// keypoint's octave sets its weight in tracking, so the two must agree).
void checkOrbMatches(const MapFile& m, const std::string& path, const OrbExtractor::Options& orb);

/// Throws std::invalid_argument naming both cameras when `camera` is not the map's (within
/// 1e-6 px and 1e-9 in the distortion): a bundle adjustment over the map's keyframes with
/// another camera moves them by decimetres (a half-size copy of the shipped frames: 9-25 cm).
void checkCameraMatches(const MapFile& m, const std::string& path,
                        const core::CameraIntrinsics& camera);

}  // namespace devslam::slam
