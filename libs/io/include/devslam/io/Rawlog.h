#pragma once
/// MRPT rawlog input and output of RGB-D frames as mrpt::obs::CObservation3DRangeScan.
///
/// Reading accepts both rawlog layouts (observation-only, and CActionCollection /
/// CSensoryFrame pairs) and observations whose images are stored externally in
/// `<name>_Images/` (MRPT 2.5.8's CRawlog::detectImagesDirectory() drops a '/', so the
/// folder is derived here). Depth not registered to colour (a Kinect/OpenNI rawlog) is
/// reprojected into the colour camera; Euclidean range images are converted to depth.
///
/// The whole file is scanned when the reader opens, so a damaged rawlog fails up front with
/// how many observations were read before the damage (DamagedInput), or, with
/// `ReaderOptions::allow_damaged`, the intact prefix is used and `damage()` says what
/// was lost.
///
/// Usage:
///   devslam::io::RawlogReader in("seq.rawlog");
///   while (auto f = in.next()) { ... }
///   devslam::io::RawlogWriter out("copy.rawlog", {});
///   out.write(frame);  // depth kept in the source's raw units, colour lossless
/// Not thread-safe.

#include <devslam/io/RgbdReader.h>

#include <memory>
#include <string>

namespace mrpt::obs {
class CObservation3DRangeScan;
}

namespace devslam::io {

class RawlogReader final : public RgbdReader {
  public:
    explicit RawlogReader(std::string path, ReaderOptions opts = {});
    ~RawlogReader() override;
    [[nodiscard]] std::optional<core::Frame> next() override;
    [[nodiscard]] std::optional<std::size_t> size() const override { return n_frames_; }
    [[nodiscard]] core::CameraIntrinsics intrinsics() const override { return K_; }
    [[nodiscard]] std::string describe() const override;

    /// Empty if the file is intact; otherwise what was wrong and how much was read.
    [[nodiscard]] std::string damage() const override { return damage_; }
    /// "observations-only" or "action/sensory-frame".
    [[nodiscard]] const std::string& format() const { return format_; }
    /// Observations of other classes (odometry, lasers...) skipped while scanning.
    [[nodiscard]] std::size_t skippedObservations() const { return n_skipped_; }

  private:
    struct Stream;
    std::string path_;
    ReaderOptions opts_;
    std::unique_ptr<Stream> stream_;
    std::size_t n_frames_ = 0, n_read_ = 0, n_skipped_ = 0;
    std::string damage_, format_;
    core::CameraIntrinsics K_;
};

/// Converts one observation into a Frame (registers depth to colour if needed). Throws
/// std::runtime_error naming `what` when the observation has no colour or no depth image,
/// or when its depth looks like the truncated metres written by MRPT's buggy
/// rgbd_dataset2rawlog sample.
[[nodiscard]] core::Frame frameFromObservation(const mrpt::obs::CObservation3DRangeScan& obs,
                                               const std::string& what);

struct RawlogWriterOptions {
    /// true: CActionCollection + CSensoryFrame pairs; false: observations only.
    bool sensory_frames = false;
    /// true: a small .rawlog plus `<name>_Images/` with PNG colour and .bin depth.
    bool external_images = false;
    int compression = 1;                ///< gzip level 0..9
    std::string sensor_label = "RGBD";  ///< CObservation::sensorLabel
    /// true: the rawlog must not be there yet ("File exists" otherwise): of two conversions
    /// into one file started at once, one is refused instead of both writing it.
    bool fresh = false;
};

class RawlogWriter {
  public:
    RawlogWriter(std::string path, RawlogWriterOptions opts);
    ~RawlogWriter();
    RawlogWriter(const RawlogWriter&) = delete;
    RawlogWriter& operator=(const RawlogWriter&) = delete;
    void write(const core::Frame& f);
    /// Flushes and closes; throws if the file could not be written completely.
    void close();
    [[nodiscard]] std::size_t count() const { return count_; }

  private:
    struct Stream;
    std::string path_, images_dir_;
    RawlogWriterOptions opts_;
    std::unique_ptr<Stream> stream_;
    std::size_t count_ = 0;
};

/// Folder that holds a rawlog's external images: `<dir>/<name>_Images`.
[[nodiscard]] std::string rawlogImagesDir(const std::string& rawlog_path);

}  // namespace devslam::io
