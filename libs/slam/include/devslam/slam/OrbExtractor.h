#pragma once
/// ORB features (OpenCV) spread over the image with a grid, keypoints inside the dynamic
/// mask dropped, depth looked up and back-projected.
///
/// Usage:
///   devslam::slam::OrbExtractor orb(opts);
///   FrameFeatures f = orb.extract(frame, filter_out.mask);   // mask may be empty
/// Not thread-safe (owns the cv::ORB object).
#include <devslam/core/Frame.h>
#include <devslam/slam/Types.h>

#include <opencv2/features2d.hpp>

#include <string>

namespace mrpt::config {
class CConfigFileBase;
}

namespace devslam::slam {

class OrbExtractor {
  public:
    struct Options {
        int n_features = 1250;       ///< features kept per frame (the paper: 1250)
        double scale_factor = 1.3;   ///< pyramid scale between levels
        int n_levels = 4;            ///< pyramid levels
        int fast_threshold = 20;     ///< FAST threshold (intensity units)
        int min_fast_threshold = 7;  ///< retried with this when a frame yields too few corners
        double oversample = 1.6;     ///< ORB asked for oversample*n_features, then spread
        int grid_cols = 8;           ///< spreading grid (cells over the image width)
        int grid_rows = 6;           ///< spreading grid (cells over the image height)
        double min_depth = 0.1;      ///< [m] nearer depth is treated as missing
        double max_depth = 6.0;      ///< [m] farther depth is treated as missing
        /// Multiplies every depth reading (sensor depth-scale calibration; 1 = as recorded).
        double depth_factor = 1.0;
        /// true: ORB detects only outside the dynamic mask, so the whole feature budget
        /// goes to the static part of the image (a walker covering half of the view halves
        /// the features otherwise). false: detect everywhere, then drop the masked keypoints
        /// (the paper's wording; n_masked counts them).
        bool detect_outside_mask = false;
        /// A keypoint whose 5x5 depth neighbourhood spreads more than this fraction of its
        /// depth (holes are left out: Kinect shadows are evidence neither way) sits on an
        /// occlusion edge - often a corner formed by a
        /// person's silhouette against the background, which moves with the person while
        /// its depth is the wall's. Its depth is discarded, so it never becomes a landmark.
        /// 0 = off.
        double depth_edge_threshold = 0.05;

        void loadFromConfig(const mrpt::config::CConfigFileBase& cfg,
                            const std::string& section = "orb");
        void saveToConfig(mrpt::config::CConfigFileBase& cfg,
                          const std::string& section = "orb") const;
    };

    explicit OrbExtractor(const Options& opts);

    /// Features of `frame`. `mask`: empty, or CV_8UC1 of the frame size with 255 = dynamic
    /// (no keypoints there; see detect_outside_mask). Throws std::invalid_argument
    /// for a mask of the wrong size/type.
    [[nodiscard]] FrameFeatures extract(const core::Frame& frame, const cv::Mat& mask) const;

    [[nodiscard]] const Options& options() const { return opts_; }

  private:
    Options opts_;
    cv::Ptr<cv::ORB> orb_, orb_low_;
};

/// Replaces keypoint positions by their undistorted pixels (K.dist, OpenCV model) and
/// re-back-projects the points with depth; no-op for an undistorted camera. Depth and
/// colour are looked up at the raw (distorted) pixel, where the registered depth lies; the
/// raw pixels are kept in `f.image_pt`.
void undistortKeypoints(FrameFeatures& f, const core::CameraIntrinsics& K);

/// Keeps at most `n` keypoints spread over a cols x rows grid: each cell first keeps its
/// strongest n/(cols*rows) responses, the rest of the budget goes to the strongest left.
/// Returns indices into `kps`, sorted ascending. Deterministic (ties by index).
[[nodiscard]] std::vector<int> spreadOverGrid(const std::vector<cv::KeyPoint>& kps, cv::Size image,
                                              int cols, int rows, int n);

}  // namespace devslam::slam
