#pragma once
/// Keyframe pose graph optimised with MRPT: mrpt::graphs::CNetworkOfPoses3DInf and
/// mrpt::graphslam::optimize_graph_spa_levmarq (the only translation unit that includes
/// the heavy header). Pure function: poses and edges in, optimised poses out.
///
/// Usage:
///   std::vector<PoseGraphEdge> edges = {...};        // i -> j: pose of j seen from i
///   auto out = devslam::slam::optimizePoseGraph(poses, edges, /*fixed=*/0, {});
#include <Eigen/Geometry>

#include <cstdint>
#include <map>
#include <vector>

namespace devslam::slam {

struct PoseGraphEdge {
    std::int64_t from = 0, to = 0;
    Eigen::Isometry3d T_from_to = Eigen::Isometry3d::Identity();  ///< pose of `to` in `from`
    /// 6x6 information in MRPT's tangent order [x y z rx ry rz] (translation first).
    Eigen::Matrix<double, 6, 6> information = Eigen::Matrix<double, 6, 6>::Identity();
};

/// Diagonal information from standard deviations [m] and [rad].
[[nodiscard]] Eigen::Matrix<double, 6, 6> diagonalInformation(double sigma_t, double sigma_r);

struct PoseGraphOptions {
    int max_iterations = 100;  ///< LM iterations
};

struct PoseGraphResult {
    std::map<std::int64_t, Eigen::Isometry3d> poses;  ///< optimised T_w_node
    std::size_t iterations = 0;
    double chi2_before = 0.0;  ///< information-weighted squared error
    double chi2_after = 0.0;
};

/// Optimises all nodes except `fixed` (the gauge). Throws std::invalid_argument when an
/// edge refers to a node not in `poses` or `fixed` is not a node.
[[nodiscard]] PoseGraphResult optimizePoseGraph(
    const std::map<std::int64_t, Eigen::Isometry3d>& poses, const std::vector<PoseGraphEdge>& edges,
    std::int64_t fixed, const PoseGraphOptions& opts);

}  // namespace devslam::slam
