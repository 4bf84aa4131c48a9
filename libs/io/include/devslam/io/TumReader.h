#pragma once
/// TUM RGB-D benchmark folder reader: rgb.txt, depth.txt, optional groundtruth.txt.
/// Colour and depth are associated like TUM's associate.py (nearest within max_dt, each
/// image used once); depth PNGs are 16-bit with 5000 units per metre, 0 = missing.
///
/// Intrinsics, in order of precedence: ReaderOptions::intrinsics, a named preset
/// (ReaderOptions::camera), the folder's own `camera.ini` (section [camera], written by
/// TumWriter and the renderer), the preset the folder name implies ("freiburg1", "fr3"...),
/// else the ROS default (describe() says which was used).
///
/// Every list is parsed and every referenced file checked for existence when the reader
/// is constructed, so a damaged folder fails before any work starts, with file and line
/// (DamagedInput when images are missing; with ReaderOptions::allow_damaged the pairs
/// without them are left out and damage() lists them).
///
/// Usage:
///   devslam::io::TumReader reader("data/tum/fr1_xyz_first37", opts);
///   while (auto f = reader.next()) { ... }

#include <devslam/io/RgbdReader.h>

#include <string>
#include <vector>

namespace devslam::io {

/// One `timestamp filename` entry of rgb.txt / depth.txt.
struct TumListEntry {
    double t = 0;
    std::string file;  ///< relative to the folder
    int line = 0;      ///< 1-based line in the list file
};

/// Parses rgb.txt/depth.txt. Throws std::runtime_error "<path> line N: ..." for a
/// malformed line, and for unsorted or duplicate timestamps; "<path>: no entries" if empty.
[[nodiscard]] std::vector<TumListEntry> readTumList(const std::string& path);

/// Picks the camera preset from a TUM folder name; std::nullopt if it names none.
[[nodiscard]] std::optional<std::string> tumPresetFromName(const std::string& folder);

class TumReader final : public RgbdReader {
  public:
    explicit TumReader(std::string folder, ReaderOptions opts = {});
    [[nodiscard]] std::optional<core::Frame> next() override;
    [[nodiscard]] std::optional<std::size_t> size() const override { return pairs_.size(); }
    [[nodiscard]] std::optional<core::Trajectory> groundTruth() const override { return gt_; }
    [[nodiscard]] core::CameraIntrinsics intrinsics() const override { return K_; }
    [[nodiscard]] std::string describe() const override;
    [[nodiscard]] std::string damage() const override { return damage_; }

    /// Random access to frame i (0-based) of the associated list.
    [[nodiscard]] core::Frame read(std::size_t i) const;

  private:
    /// A listed image's file: as listed where that is absolute, else in the folder.
    [[nodiscard]] std::string imagePath(const std::string& listed) const;
    std::string folder_;
    ReaderOptions opts_;
    core::CameraIntrinsics K_;
    std::vector<std::pair<TumListEntry, TumListEntry>> pairs_;  // (rgb, depth)
    std::optional<core::Trajectory> gt_;
    std::string camera_source_, damage_;
    std::size_t cursor_ = 0;
};

/// Loads a colour PNG/JPG (any 8-bit image, converted to BGR) and a 16-bit depth PNG into
/// a Frame's images; throws std::runtime_error naming the file when it is missing, does not
/// decode, or has the wrong type or size.
void loadTumImages(const std::string& rgb_path, const std::string& depth_path, double depth_scale,
                   core::Frame& f);

}  // namespace devslam::io
