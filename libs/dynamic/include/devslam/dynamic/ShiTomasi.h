#pragma once

#include <opencv2/core.hpp>

#include <vector>

namespace devslam::dynamic {

/// Shi-Tomasi corners ("Good features to track", Shi & Tomasi 1994) selected from a
/// precomputed minimum-eigenvalue map, so that one map serves the whole image and every
/// person box of a frame.
///
/// OpenCV's cv::goodFeaturesToTrack recomputes cv::cornerMinEigenVal on every call, and
/// the filter calls it once for the image and once per box: the map cost 0.7 ms of the
/// filter's 4.5 ms at 320x240. This is the selection half of goodFeaturesToTrack, written
/// by hand because OpenCV has no entry point that takes the map: corners are the 3x3
/// local maxima above quality * (the region's maximum), strongest first, at least
/// min_distance apart, at most max_corners. On the whole image with no mask it returns
/// exactly what cv::goodFeaturesToTrack returns (tests/dynamic checks this); inside a
/// region, a corner must also be a local maximum over the region's outside neighbours.
/// The map itself is cv::cornerMinEigenVal's, computed from faster OpenCV primitives
/// (ShiTomasi.cpp says why).
///
///   const auto map = ShiTomasiMap::compute(gray);  // once per frame (or map.update(gray))
///   auto all = selectShiTomasi(map, cv::Rect(0, 0, gray.cols, gray.rows), 200, 0.01, 5);
///   auto box = selectShiTomasi(map, roi, 40, 0.01, 2.5, fg_mask);  // per box, same map
struct ShiTomasiMap {
    cv::Mat eig;      ///< CV_32F minimum eigenvalue of the gradient covariance per pixel
    cv::Mat eig_max;  ///< CV_32F 3x3 dilation of eig (local-maximum test)

    /// Computes the map of a CV_8U image (blockSize 3, Sobel aperture 3, as the filter's
    /// former goodFeaturesToTrack calls).
    [[nodiscard]] static ShiTomasiMap compute(const cv::Mat& gray);
    /// The same, in place: a map kept from frame to frame reuses its images and scratch
    /// buffers (no allocation once the image size is fixed). eig and eig_max are
    /// overwritten, so headers copied from them earlier see the new map.
    void update(const cv::Mat& gray);
    [[nodiscard]] bool empty() const { return eig.empty(); }

  private:
    cv::Mat a_, b_, c_, d_, e_;  // scratch (gradients, their products and sums)
};

/// Corners in `roi` of the map (coordinates of the whole image). mask: empty, or CV_8U of
/// roi's size (non-zero = allowed), like goodFeaturesToTrack's mask. max_corners <= 0: no
/// limit. The outermost row and column of the roi are skipped, as goodFeaturesToTrack does.
/// taken: corners chosen before (whole-image coordinates, say the image-wide selection's,
/// rounded to whole pixels): none is returned again, and the new ones keep min_distance from
/// them as from each other, so that max_corners new corners are found where the region has
/// them.
[[nodiscard]] std::vector<cv::Point2f> selectShiTomasi(const ShiTomasiMap& map, const cv::Rect& roi,
                                                       int max_corners, double quality,
                                                       double min_distance,
                                                       const cv::Mat& mask = cv::Mat(),
                                                       const std::vector<cv::Point2f>& taken = {});

}  // namespace devslam::dynamic
