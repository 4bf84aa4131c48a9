#pragma once
/// Descriptor matching: by projection of map landmarks into a frame (search in a radius
/// around the predicted pixel), and brute force with Lowe's ratio test (relocalization,
/// loop closure). Pure functions.
#include <devslam/core/Camera.h>
#include <devslam/slam/Map.h>

#include <vector>

namespace devslam::slam {

/// Hamming distance of two 32-byte ORB descriptors (rows of CV_8U mats).
[[nodiscard]] int hamming32(const uchar* a, const uchar* b);

/// Keypoints bucketed in square cells for radius queries.
class KeypointGrid {
  public:
    KeypointGrid(const std::vector<cv::KeyPoint>& kps, cv::Size image, int cell_px = 16);
    /// Indices of keypoints within `radius` [px] of (u, v).
    void query(double u, double v, double radius, std::vector<int>& out) const;

  private:
    const std::vector<cv::KeyPoint>* kps_;
    int cell_, cols_, rows_;
    std::vector<std::vector<int>> cells_;
};

struct ProjectionMatchOptions {
    double radius = 12.0;     ///< [px] search radius around the projection (every octave)
    int max_hamming = 60;     ///< best distance must be <= this (0..256)
    double ratio = 0.85;      ///< best < ratio * second best (same frame), else ambiguous
    double max_depth = 10.0;  ///< [m] landmarks farther in front of the camera are not searched
};

struct Match {
    LandmarkId landmark = kNoId;
    int kp = -1;       ///< keypoint index in the frame
    int distance = 0;  ///< Hamming
};

/// Projects `candidates` with the pose T_wc and matches each to the closest descriptor
/// among the frame's keypoints near its projection. A keypoint keeps only its best
/// landmark. `n_in_view` (optional) receives how many candidates projected in the image.
[[nodiscard]] std::vector<Match> matchByProjection(
    const Map& map, const std::vector<LandmarkId>& candidates, const FrameFeatures& f,
    const KeypointGrid& grid, const Eigen::Isometry3d& T_wc, const core::CameraIntrinsics& K,
    const ProjectionMatchOptions& opts, int* n_in_view = nullptr,
    std::vector<LandmarkId>* in_view = nullptr);

/// Brute-force matching of query rows against train rows with the ratio test, one to one
/// (each train row kept for its best query row; not a mutual best check). Returns (query,
/// train) index pairs.
[[nodiscard]] std::vector<std::pair<int, int>> matchBruteForce(const cv::Mat& query,
                                                               const cv::Mat& train,
                                                               int max_hamming, double ratio);

}  // namespace devslam::slam
