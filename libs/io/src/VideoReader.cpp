#include <devslam/io/VideoReader.h>

#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include <algorithm>
#include <filesystem>
#include <sstream>
#include <stdexcept>

namespace devslam::io {

VideoReader::VideoReader(std::string path, Options opts)
    : path_(std::move(path)), opts_(opts), cap_(std::make_unique<cv::VideoCapture>()) {
    if (!(opts_.plane_depth > 0))
        throw std::invalid_argument(path_ + ": plane_depth must be > 0 m");
    if (!(opts_.focal >= 0)) throw std::invalid_argument(path_ + ": focal must be >= 0 px");
    if (!std::filesystem::is_regular_file(path_))
        throw std::runtime_error(path_ + ": no such video file");
    // FFmpeg only: CAP_ANY would also try the image-sequence backend, which reports any
    // file that is not a video with a confusing exception of its own on stderr.
    if (!cap_->open(path_, cv::CAP_FFMPEG) || !cap_->isOpened())
        throw std::runtime_error(
            path_ + ": cannot open as a video (OpenCV's FFmpeg backend does not decode it)");
    // FFmpeg's tty demuxer takes any text file named .txt, .nfo, .asc, ... and its "ansi"
    // decoder draws the text as 640x400 frames: a list of images given as a video ran.
    const int ansi = cv::VideoWriter::fourcc('a', 'n', 's', 'i');
    if (static_cast<int>(cap_->get(cv::CAP_PROP_FOURCC)) == ansi)
        throw std::runtime_error(
            path_ + ": a text file, not a video (FFmpeg would draw its text as frames)");
    const double fps = cap_->get(cv::CAP_PROP_FPS);
    if (fps > 0) fps_ = fps;
    const double count = cap_->get(cv::CAP_PROP_FRAME_COUNT);
    if (count > 0) size_ = static_cast<std::size_t>(count);
    pending_ = readFrame();
    if (!pending_) throw std::runtime_error(path_ + ": no frame decodes");
}

VideoReader::~VideoReader() = default;

std::optional<core::Frame> VideoReader::next() {
    if (pending_) {
        std::optional<core::Frame> f = std::move(pending_);
        pending_.reset();
        return f;
    }
    return readFrame();
}

std::optional<core::Frame> VideoReader::readFrame() {
    cv::Mat img;
    if (!cap_->read(img) || img.empty()) {
        // The stated count is the header's for AVI and MP4, an estimate from the duration
        // for some other containers (off by a frame or two): a few frames short is not news.
        if (size_ && index_ + std::max<std::size_t>(2, *size_ / 50) < *size_)
            damage_ = path_ + ": " + std::to_string(index_) + " of the " + std::to_string(*size_) +
                      " frames the container states decoded; the file may be cut short or "
                      "damaged after frame " +
                      std::to_string(index_ == 0 ? 0 : index_ - 1);
        return std::nullopt;
    }
    if (img.type() == CV_8UC1) cv::cvtColor(img, img, cv::COLOR_GRAY2BGR);
    if (img.type() != CV_8UC3)
        throw std::runtime_error(path_ + " frame " + std::to_string(index_) +
                                 ": not an 8-bit colour image");
    if (index_ == 0) {
        K_.width = img.cols;
        K_.height = img.rows;
        K_.fx = K_.fy = opts_.focal > 0 ? opts_.focal : img.cols;
        K_.cx = (img.cols - 1) / 2.0;
        K_.cy = (img.rows - 1) / 2.0;
    } else if (img.cols != K_.width || img.rows != K_.height) {
        throw std::runtime_error(path_ + " frame " + std::to_string(index_) + ": size changed to " +
                                 std::to_string(img.cols) + "x" + std::to_string(img.rows));
    }
    core::Frame f;
    f.index = index_;
    f.timestamp = static_cast<double>(index_) / fps_;
    f.bgr = img;
    f.depth = cv::Mat(img.size(), CV_32FC1, cv::Scalar(static_cast<float>(opts_.plane_depth)));
    f.K = K_;
    f.depth_scale = 1000.0;
    f.rgb_source = path_ + " frame " + std::to_string(index_);
    f.depth_source = "constant plane";
    ++index_;
    return f;
}

std::string VideoReader::describe() const {
    std::ostringstream s;
    s << "video " << path_ << " (fixed camera, " << K_.width << "x" << K_.height << ", " << fps_
      << " Hz, depth a plane at " << opts_.plane_depth << " m)";
    return s.str();
}

}  // namespace devslam::io
