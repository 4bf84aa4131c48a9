#pragma once
/// Camera pose from 2D-3D correspondences: PnP-RANSAC (cv::solvePnPRansac) for a robust
/// initial pose, then a motion-only Gauss-Newton refinement with a Huber kernel on the
/// reprojection error plus, where depth is measured, the error of a virtual right-camera
/// coordinate u_r = u - bf/z (the RGB-D residual of ORB-SLAM2). Pure functions.
#include <devslam/core/Camera.h>
#include <devslam/slam/Types.h>

#include <Eigen/Geometry>

#include <optional>
#include <vector>

namespace devslam::slam {

/// One correspondence: world point and its measurement in the image.
struct PoseObservation {
    Eigen::Vector3d p_w;    ///< [m]
    Eigen::Vector2d uv;     ///< [px] measured keypoint
    double depth = 0.0;     ///< [m] measured depth at the keypoint, 0 = none
    double inv_sigma2 = 1;  ///< 1/sigma^2: the chi2 test's and the Huber kernel's
    /// Multiplies inv_sigma2 in the optimisation only (and the observation's robust cost):
    /// with weight != 1 a keypoint pulls on the pose more or less than its chi2 test says
    /// (FrameFeatures::gate_exponent: a keypoint trusted less may be rejected sooner).
    double weight = 1;
};

/// Keypoint i of `f` as the measurement of the point p_w: its pixel and depth, the
/// information its outlier tests see (FrameFeatures::information) and the weight the
/// optimisation adds to it (FrameFeatures::weightOf).
[[nodiscard]] PoseObservation observationOf(const FrameFeatures& f, std::size_t i,
                                            const Eigen::Vector3d& p_w, double scale_factor);

struct PnpRansacOptions {
    int iterations = 100;             ///< RANSAC iterations
    double reprojection_px = 4.0;     ///< [px] inlier threshold
    double confidence = 0.99;         ///< RANSAC confidence
    int min_inliers = 12;             ///< fewer: no pose
};

struct PnpResult {
    Eigen::Isometry3d T_wc;
    std::vector<int> inliers;  ///< indices into the observations
};

/// RANSAC PnP (EPnP hypotheses and EPnP on the inliers). Deterministic without a seed:
/// OpenCV's RANSAC draws its samples from a generator of its own with a fixed seed (it does
/// not read cv::theRNG()). `guess_T_wc` (optional) is passed as OpenCV's extrinsic guess,
/// which EPnP does not use: the caller's refinement (refinePose) starts from the result.
/// std::nullopt with fewer than max(6, min_inliers) observations or inliers.
[[nodiscard]] std::optional<PnpResult> solvePnpRansac(
    const std::vector<PoseObservation>& obs, const core::CameraIntrinsics& K,
    const PnpRansacOptions& opts, const std::optional<Eigen::Isometry3d>& guess_T_wc = {});

struct PoseRefineOptions {
    double bf = 40.0;            ///< [px*m] virtual stereo baseline times fx (ORB-SLAM2 TUM: 40)
    int rounds = 4;              ///< outlier classification rounds
    int iterations = 10;         ///< Gauss-Newton iterations per round
    double chi2_mono = 5.991;    ///< chi-square 95% for 2 dof (pixels^2 / sigma^2)
    double chi2_stereo = 7.815;  ///< chi-square 95% for 3 dof
};

struct PoseRefineResult {
    Eigen::Isometry3d T_wc;
    std::vector<char> inlier;  ///< per observation
    int n_inliers = 0;
    double rms_px = 0.0;  ///< RMS reprojection error of the inliers [px]
};

/// Motion-only refinement from `T_wc_init` (all observations start as inliers; each
/// round re-classifies them by chi-square, the last rounds without the robust kernel).
[[nodiscard]] PoseRefineResult refinePose(const std::vector<PoseObservation>& obs,
                                          const Eigen::Isometry3d& T_wc_init,
                                          const core::CameraIntrinsics& K,
                                          const PoseRefineOptions& opts);

/// How far [m] from the point that `o`'s keypoint and depth measure (camera frame) the
/// world point, moved into the camera by a pose, can be when refinePose's last chi2 test
/// keeps `o` as an inlier; infinity without depth, with inv_sigma2 <= 0, or where the gate
/// takes any depth (1/depth <= sqrt(2 chi2_stereo / inv_sigma2) / bf). inlierBound's e.
[[nodiscard]] double inlierReach(const PoseObservation& o, const core::CameraIntrinsics& K,
                                 const PoseRefineOptions& opts);

/// An upper bound on refinePose(obs, T, K, opts).n_inliers over every pose T, computed
/// without a pose: what lets a caller skip a PnP-RANSAC whose pose could not be accepted
/// (a failing RANSAC runs all its iterations, about 10 ms on 30 correspondences).
/// Why it holds: refinePose's last classification keeps an observation i with depth only if
/// T moves its world point p_w,i to within e_i = inlierReach(i) of the point p_c,i its
/// keypoint and depth measure; T preserves distances, so two inliers i, j have
/// | |p_w,i - p_w,j| - |p_c,i - p_c,j| | <= e_i + e_j. The inliers are a clique of that
/// consistency graph, at most its degeneracy + 1; an observation of infinite reach (no
/// depth, or a gate that takes any depth) counts as an inlier of every pose.
/// Written here because OpenCV's RANSAC has no such early exit.
[[nodiscard]] int inlierBound(const std::vector<PoseObservation>& obs,
                              const core::CameraIntrinsics& K, const PoseRefineOptions& opts);

/// inlierBound(obs, K, opts) >= k, decided sooner where the answer is yes (a clique of the
/// consistency graph found greedily): what a caller asks before a PnP-RANSAC that needs k.
[[nodiscard]] bool inlierBoundReaches(const std::vector<PoseObservation>& obs, int k,
                                      const core::CameraIntrinsics& K,
                                      const PoseRefineOptions& opts);

/// Residual and Jacobian of one observation w.r.t. a left perturbation [v, w] of T_cw and
/// w.r.t. the world point: r = predicted - measured; `rows` = 2 (no depth: third row of r and
/// of both Jacobians is zero) or 3. false when behind the camera.
bool observationJacobians(const Eigen::Isometry3d& T_cw, const Eigen::Vector3d& p_w,
                          const Eigen::Vector2d& uv, double depth, const core::CameraIntrinsics& K,
                          double bf, Eigen::Vector3d& r, Eigen::Matrix<double, 3, 6>& J_pose,
                          Eigen::Matrix3d& J_point, int& rows);

/// exp of a twist [v, w] as used by the optimizers (rotation by the angle-axis w).
[[nodiscard]] Eigen::Isometry3d expTwist(const Eigen::Matrix<double, 6, 1>& xi);

}  // namespace devslam::slam
