#pragma once
/// A video from a camera that does not move, read as RGB-D frames whose depth is one
/// constant plane. Real footage of walking people has no depth (OpenCV's `vtest.avi`, a
/// fixed camera over a square), yet the dynamic-object filter needs a depth per point to
/// predict the flow of the camera's own motion. With a fixed camera that motion is the
/// identity, and the predicted flow is zero whatever the depth, so a plane stands in for it.
/// For the filter's tests and overlays on real people only: depth-based tests (the
/// person's depth band, walking towards the camera) see nothing on a plane, and SLAM on
/// such frames is meaningless (no motion, no geometry).
///
/// Usage:
///   devslam::io::VideoReader video("/usr/share/doc/opencv-doc/examples/data/vtest.avi", {});
///   while (auto f = video.next()) filter.step(*f, Eigen::Isometry3d::Identity());

#include <devslam/io/RgbdReader.h>

#include <memory>
#include <string>

namespace cv {
class VideoCapture;
}

namespace devslam::io {

class VideoReader final : public RgbdReader {
  public:
    struct Options {
        double plane_depth = 5.0;  ///< [m] the constant depth of every pixel
        /// [px] focal length; 0 = the image width (a 53 deg horizontal field of view).
        /// Principal point at the image centre.
        double focal = 0.0;
    };
    /// Opens the file and reads its first frame (to learn its size). Throws
    /// std::runtime_error naming the file when it is missing or no frame decodes, and
    /// std::invalid_argument for a plane_depth or focal that is not positive (focal 0 ok).
    explicit VideoReader(std::string path, Options opts);
    ~VideoReader() override;
    VideoReader(const VideoReader&) = delete;
    VideoReader& operator=(const VideoReader&) = delete;

    /// Timestamps are index / the file's frame rate (10 Hz if it gives none).
    [[nodiscard]] std::optional<core::Frame> next() override;
    /// The container's frame count when it states one.
    [[nodiscard]] std::optional<std::size_t> size() const override { return size_; }
    [[nodiscard]] core::CameraIntrinsics intrinsics() const override { return K_; }
    [[nodiscard]] std::string describe() const override;
    /// Once next() has ended: what was not decoded when the decoder stopped well before the
    /// frame count the container states (a file cut short); "" otherwise.
    [[nodiscard]] std::string damage() const override { return damage_; }

  private:
    [[nodiscard]] std::optional<core::Frame> readFrame();

    std::string path_;
    Options opts_;
    std::unique_ptr<cv::VideoCapture> cap_;
    core::CameraIntrinsics K_;
    double fps_ = 10.0;
    std::optional<std::size_t> size_;
    std::string damage_;
    std::optional<core::Frame> pending_;  // the first frame, read by the constructor
    std::size_t index_ = 0;
};

}  // namespace devslam::io
