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

}  // namespace devslam::core
