#pragma once
/// People textures: real photographs cut out with an alpha mask (GrabCut seeded by the
/// person's box), and the mesh cells that make the rendered silhouette exact in depth
/// (MRPT 2.5.8's textured shader writes depth for transparent texels, so the silhouette
/// is built from geometry, not from alpha).
///
/// Usage:
///   cv::Mat rgba = devslam::render::cutPersonTexture(cv::imread("person.jpg"), box);
///   cv::imwrite("person.png", rgba);
///   auto tex = devslam::render::loadPersonTexture("person.png", 4);

#include <opencv2/core/mat.hpp>
#include <opencv2/core/types.hpp>

#include <string>

namespace devslam::render {

/// Cuts the person inside `box` out of `bgr` with cv::grabCut (`iterations` rounds,
/// deterministic), crops to the person's extent and returns CV_8UC4 BGRA (alpha 255 = person,
/// 0 = background). Throws std::invalid_argument if the box is empty or outside the image,
/// or the cut leaves fewer than 5% of the box.
[[nodiscard]] cv::Mat cutPersonTexture(const cv::Mat& bgr, const cv::Rect& box, int iterations = 5);

/// The largest side a texture photo may have [px]. The frames are 640x480, and every wall
/// panel keeps its own crop of half to nine tenths of its photo: a 6000x4000 wall photo took
/// 7.7 GB and 10 s a frame, a 12000x12000 one ran out of memory.
inline constexpr int kMaxTextureSide = 2048;

/// "texture '<path>' is WxH px; at most 2048 px per side ..." when `img` is larger, else "".
[[nodiscard]] std::string textureTooLarge(const cv::Mat& img, const std::string& path);

struct PersonTexture {
    cv::Mat bgr;        ///< CV_8UC3 colour, background pixels filled with the nearest person colour
    cv::Mat cell_mask;  ///< CV_8UC1, one entry per cell_px x cell_px cell: 255 = solid
    int cell_px = 4;    ///< cell size [texture px]
    [[nodiscard]] double aspect() const { return double(bgr.cols) / bgr.rows; }  ///< width / height
};

/// Loads an RGBA PNG and builds its cell mask (a cell is solid when more than half of its
/// texels are opaque). Throws std::runtime_error naming the file when it cannot be read or
/// has no alpha channel, or is larger than kMaxTextureSide.
[[nodiscard]] PersonTexture loadPersonTexture(const std::string& path, int cell_px = 4);

}  // namespace devslam::render
