#pragma once
/// The SLAM map on disk, to localize in it later (Slam::localizeIn, `devslam-run --localize`):
/// every keyframe (pose, ORB keypoints, descriptors, depths, colours) and every landmark
/// (position, descriptor, observers). An OpenCV FileStorage YAML file whose arrays are base64
/// (cv::FileStorage does the parsing and the exact float round trip; a 750-frame map of the
/// synthetic bench is some 10 MB).
///
/// Usage:
///   devslam::slam::saveMap("slam_map.yml", slam.map(), opts.orb);
///   devslam::slam::MapFile m = devslam::slam::loadMap("slam_map.yml");
///   slam.localizeIn(std::move(m.map));
///
/// Ids are renumbered on load (in the saved order), so a map that culled keyframes loads
/// with consecutive ids; everything else round-trips exactly.
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
};

/// Writes the map whole (core::writeFileWhole: a program killed on the way leaves an earlier
/// file as it was). Throws std::runtime_error naming the path if it cannot be written.
void saveMap(const std::string& path, const Map& map, const OrbExtractor::Options& orb);

/// Reads a map saveMap wrote. Throws std::runtime_error naming the file and what is wrong:
/// not there, not a DEV-SLAM map, a later format version, a field missing or of the wrong
/// size (naming the keyframe or landmark), a pose that is not a rotation, an observation of
/// a keyframe or keypoint that does not exist, a file cut short.
[[nodiscard]] MapFile loadMap(const std::string& path);

/// Throws std::invalid_argument naming both when the map's ORB pyramid is not `orb`'s (a
/// keypoint's octave sets its weight in tracking, so the two must agree).
void checkOrbMatches(const MapFile& m, const std::string& path, const OrbExtractor::Options& orb);

}  // namespace devslam::slam
