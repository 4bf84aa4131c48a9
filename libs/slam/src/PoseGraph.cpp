// The only TU instantiating optimize_graph_spa_levmarq (~7.5 s, 550 MB to compile).
#include <devslam/core/Pose.h>
#include <devslam/slam/PoseGraph.h>

#include <mrpt/graphs/CNetworkOfPoses.h>
#include <mrpt/graphslam/levmarq.h>
#include <mrpt/poses/CPose3DPDFGaussianInf.h>

#include <stdexcept>
#include <string>

namespace devslam::slam {

Eigen::Matrix<double, 6, 6> diagonalInformation(double sigma_t, double sigma_r) {
    Eigen::Matrix<double, 6, 6> I = Eigen::Matrix<double, 6, 6>::Zero();
    for (int k = 0; k < 3; ++k) I(k, k) = 1.0 / (sigma_t * sigma_t);
    for (int k = 3; k < 6; ++k) I(k, k) = 1.0 / (sigma_r * sigma_r);
    return I;
}

PoseGraphResult optimizePoseGraph(const std::map<std::int64_t, Eigen::Isometry3d>& poses,
                                  const std::vector<PoseGraphEdge>& edges, std::int64_t fixed,
                                  const PoseGraphOptions& opts) {
    using mrpt::graphs::TNodeID;
    if (poses.find(fixed) == poses.end())
        throw std::invalid_argument("pose graph: fixed node " + std::to_string(fixed) +
                                    " is not a node");
    mrpt::graphs::CNetworkOfPoses3DInf graph;
    for (const auto& [id, T] : poses) graph.nodes[static_cast<TNodeID>(id)] = core::toCPose3D(T);
    graph.root = static_cast<TNodeID>(fixed);
    for (const auto& e : edges) {
        if (poses.find(e.from) == poses.end() || poses.find(e.to) == poses.end())
            throw std::invalid_argument("pose graph: edge " + std::to_string(e.from) + " -> " +
                                        std::to_string(e.to) + " refers to a missing node");
        mrpt::math::CMatrixDouble66 info;
        for (int r = 0; r < 6; ++r)
            for (int c = 0; c < 6; ++c) info(r, c) = e.information(r, c);
        graph.insertEdge(static_cast<TNodeID>(e.from), static_cast<TNodeID>(e.to),
                         mrpt::poses::CPose3DPDFGaussianInf(core::toCPose3D(e.T_from_to), info));
    }
    PoseGraphResult res;
    res.chi2_before = graph.chi2();
    if (!edges.empty() && poses.size() > 1) {
        mrpt::graphslam::TResultInfoSpaLevMarq info;
        mrpt::containers::yaml params = mrpt::containers::yaml::Map();
        params["max_iterations"] = opts.max_iterations;
        mrpt::graphslam::optimize_graph_spa_levmarq(graph, info, nullptr, params);
        res.iterations = info.num_iters;
    }
    res.chi2_after = graph.chi2();
    for (const auto& [id, p] : graph.nodes)
        res.poses[static_cast<std::int64_t>(id)] = core::toIsometry(mrpt::poses::CPose3D(p));
    return res;
}

}  // namespace devslam::slam
