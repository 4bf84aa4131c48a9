#pragma once
/// PNG pictures written whole or not at all (plots, maps, robot runs).
///
/// Usage:
///   devslam::core::writePngWhole(out + "/ate.png", canvas);
#include <opencv2/core/mat.hpp>

#include <string>

namespace devslam::core {

/// Encodes `image` as PNG, then writes it with writeFileWhole: a program killed on the way, a
/// disk that fills, or two programs writing one picture at once never leave a cut or spliced
/// PNG at `path` (cv::imwrite wrote into the file itself, and said only "false"). Throws
/// std::runtime_error "cannot write 'PATH': <why>" ("File too large", "a folder", "the PNG
/// did not encode" for an empty image or a channel count PNG does not hold; a depth other than
/// 8 or 16 bits is converted to 8, as cv::imwrite does).
void writePngWhole(const std::string& path, const cv::Mat& image);

/// cv::imread(path, flags), except that an image OpenCV refuses with an exception (a PNG whose
/// header claims 100000 x 100000 px: "OpenCV(4.6.0) .../loadsave.cpp:77: error: (-215:Assertion
/// failed) pixels <= CV_IO_MAX_IMAGE_PIXELS ...", naming no file, ended a run) comes back empty
/// as one that does not decode, with `why` set to " (OpenCV: <its reason>)"; else `why` is "".
[[nodiscard]] cv::Mat readImage(const std::string& path, int flags, std::string& why);

}  // namespace devslam::core
