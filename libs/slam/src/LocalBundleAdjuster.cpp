#include <devslam/core/Config.h>
#include <devslam/slam/LocalBundleAdjuster.h>
#include <devslam/slam/PoseSolver.h>

#include <mrpt/config/CConfigFileBase.h>

#include <Eigen/Cholesky>

#include <algorithm>
#include <cmath>
#include <optional>
#include <unordered_map>

namespace devslam::slam {

void LocalBaOptions::loadFromConfig(const mrpt::config::CConfigFileBase& c, const std::string& s) {
    core::requireKnownKeys(c, s,
                           {"enabled", "window", "iterations", "bf", "chi2_mono", "chi2_stereo",
                            "outlier_rounds", "max_keyframe_shift", "final_window"});
    enabled = core::readBool(c, s, "enabled", enabled);
    window = core::readInt(c, s, "window", window);
    outlier_rounds = core::readInt(c, s, "outlier_rounds", outlier_rounds);
    core::requireValue(outlier_rounds >= 0 && outlier_rounds <= 5, s, "outlier_rounds",
                       "must be in [0, 5]");
    iterations = core::readInt(c, s, "iterations", iterations);
    bf = core::readDouble(c, s, "bf", bf);
    chi2_mono = core::readDouble(c, s, "chi2_mono", chi2_mono);
    chi2_stereo = core::readDouble(c, s, "chi2_stereo", chi2_stereo);
    // One keyframe is no window: the adjustment needs two (enabled = false turns it off).
    core::requireValue(window >= 2 && window <= 30, s, "window",
                       "must be in [2, 30] (a window of 1 adjusts nothing: enabled = false)");
    core::requireValue(iterations >= 0 && iterations <= 1000, s, "iterations",
                       "must be in [0, 1000]");
    core::requireValue(bf > 0, s, "bf", "must be > 0");
    core::requireValue(chi2_mono > 0, s, "chi2_mono", "must be > 0");
    core::requireValue(chi2_stereo > 0, s, "chi2_stereo", "must be > 0");
    max_keyframe_shift = core::readDouble(c, s, "max_keyframe_shift", max_keyframe_shift);
    core::requireValue(max_keyframe_shift >= 0, s, "max_keyframe_shift", "must be >= 0 (0 = off)");
    final_window = core::readInt(c, s, "final_window", final_window);
    core::requireValue(final_window == 0 || (final_window >= 2 && final_window <= 1000), s,
                       "final_window", "must be 0 (the window) or in [2, 1000]");
}

void LocalBaOptions::saveToConfig(mrpt::config::CConfigFileBase& c, const std::string& s) const {
    core::writeKey(c, s, "enabled", enabled);
    core::writeKey(c, s, "window", window);
    core::writeKey(c, s, "outlier_rounds", outlier_rounds);
    core::writeKey(c, s, "iterations", iterations);
    core::writeKey(c, s, "bf", bf);
    core::writeKey(c, s, "chi2_mono", chi2_mono);
    core::writeKey(c, s, "chi2_stereo", chi2_stereo);
    core::writeKey(c, s, "max_keyframe_shift", max_keyframe_shift);
    core::writeKey(c, s, "final_window", final_window);
}

namespace {
struct Obs {
    int pose;      ///< index into poses (optimised or fixed)
    int landmark;  ///< index into lms
    Eigen::Vector2d uv;
    double depth;
    double inv_sigma2;  ///< the chi2 test's and the Huber kernel's 1/sigma^2
    double weight;      ///< multiplies inv_sigma2 in the normal equations (PoseObservation)
    KeyframeId kf;
    int kp;
};
}  // namespace

LocalBaResult localBundleAdjust(Map& map, KeyframeId newest, const core::CameraIntrinsics& K,
                                const LocalBaOptions& opts) {
    LocalBaResult res;
    std::vector<KeyframeId> window;
    for (KeyframeId id : map.lastKeyframes(map.keyframes().size()))
        if (id <= newest) window.push_back(id);
    if (static_cast<int>(window.size()) > opts.window)
        window.erase(window.begin(), window.end() - opts.window);
    if (window.size() < 2) return res;

    // Poses: optimised first (P of them), then fixed ones.
    std::vector<KeyframeId> pose_ids;
    std::unordered_map<KeyframeId, int> pose_index;
    for (KeyframeId id : window)
        if (id != 0) {
            pose_index[id] = static_cast<int>(pose_ids.size());
            pose_ids.push_back(id);
        }
    const int P = static_cast<int>(pose_ids.size());
    if (P == 0) return res;
    const auto lm_ids = map.landmarksOf(window);
    std::unordered_map<LandmarkId, int> lm_index;
    for (std::size_t i = 0; i < lm_ids.size(); ++i) lm_index[lm_ids[i]] = static_cast<int>(i);
    std::vector<Obs> obs;
    for (std::size_t li = 0; li < lm_ids.size(); ++li) {
        for (const auto& [kf, kp] : map.landmark(lm_ids[li])->observations) {
            auto it = pose_index.find(kf);
            if (it == pose_index.end()) {
                pose_index[kf] = static_cast<int>(pose_ids.size());
                pose_ids.push_back(kf);
                it = pose_index.find(kf);
            }
            const Keyframe& k = map.keyframe(kf);
            const auto& key = k.features.keypoints[kp];
            obs.push_back({it->second,
                           static_cast<int>(li),
                           {key.pt.x, key.pt.y},
                           static_cast<double>(k.features.depth[kp]),
                           k.features.information(kp, opts.scale_factor),
                           k.features.weightOf(kp),
                           kf,
                           kp});
        }
    }
    res.n_keyframes = P;
    res.n_fixed_keyframes = static_cast<int>(pose_ids.size()) - P;
    res.n_landmarks = static_cast<int>(lm_ids.size());
    res.n_observations = static_cast<int>(obs.size());

    std::vector<Eigen::Isometry3d> T_cw(pose_ids.size());
    for (std::size_t i = 0; i < pose_ids.size(); ++i)
        T_cw[i] = map.keyframe(pose_ids[i]).T_wc.inverse();
    std::vector<Eigen::Vector3d> X(lm_ids.size());
    for (std::size_t i = 0; i < lm_ids.size(); ++i) X[i] = map.landmark(lm_ids[i])->p_w;

    // Observations taken out after the first round (ORB-SLAM2's two-round local BA: the
    // Huber kernel bounds an outlier's pull but does not remove it; people at the mask
    // borders give many such outliers that pull together).
    std::vector<char> active(obs.size(), 1);
    // An observation's scaled squared error e2 and its chi2 bound d2 (stereo or mono) at a
    // pose and point; nullopt when the point is behind the camera.
    struct Chi2 {
        double e2, d2;
    };
    auto chi2 = [&](const Obs& o, const Eigen::Isometry3d& T,
                    const Eigen::Vector3d& Xl) -> std::optional<Chi2> {
        Eigen::Vector3d r;
        Eigen::Matrix<double, 3, 6> Jp;
        Eigen::Matrix3d Jl;
        int rows;
        if (!observationJacobians(T, Xl, o.uv, o.depth, K, opts.bf, r, Jp, Jl, rows))
            return std::nullopt;
        return Chi2{r.squaredNorm() * o.inv_sigma2, rows == 3 ? opts.chi2_stereo : opts.chi2_mono};
    };
    auto robustCost = [&](const std::vector<Eigen::Isometry3d>& T,
                          const std::vector<Eigen::Vector3d>& Xs) {
        double cost = 0;
        for (std::size_t k = 0; k < obs.size(); ++k) {
            if (!active[k]) continue;
            const auto& o = obs[k];
            const auto c = chi2(o, T[o.pose], Xs[o.landmark]);
            if (!c)
                cost += 100.0;
            else
                // weight x Huber(e2): its gradient is what the normal equations below use
                cost += o.weight *
                        (c->e2 <= c->d2 ? c->e2 : 2 * std::sqrt(c->e2 * c->d2) - c->d2);
        }
        return cost;
    };

    // Outside chi2 (or behind the camera) at the current estimate.
    auto isOutlier = [&](const Obs& o) {
        const auto c = chi2(o, T_cw[o.pose], X[o.landmark]);
        return !c || c->e2 > c->d2;
    };

    const int L = static_cast<int>(lm_ids.size());
    double cost = robustCost(T_cw, X);
    res.initial_cost = cost;
    double lambda = 1e-3;
    using Mat63 = Eigen::Matrix<double, 6, 3>;
    const int rounds = opts.outlier_rounds + 1;
    for (int round = 0; round < rounds; ++round) {
        if (round > 0) {
            int dropped = 0;
            for (std::size_t k = 0; k < obs.size(); ++k) {
                if (active[k] && isOutlier(obs[k])) {
                    active[k] = 0;
                    ++dropped;
                }
            }
            if (dropped == 0) break;
            cost = robustCost(T_cw, X);
            lambda = 1e-3;
        }
        for (int it = 0; it < opts.iterations; ++it) {
            Eigen::MatrixXd Hpp = Eigen::MatrixXd::Zero(Eigen::Index{6} * P, Eigen::Index{6} * P);
            Eigen::VectorXd gp = Eigen::VectorXd::Zero(Eigen::Index{6} * P);
            std::vector<Eigen::Matrix3d> Hll(L, Eigen::Matrix3d::Zero());
            std::vector<Eigen::Vector3d> gl(L, Eigen::Vector3d::Zero());
            std::vector<Mat63> Hpl(obs.size(), Mat63::Zero());
            Eigen::Vector3d r;
            Eigen::Matrix<double, 3, 6> Jp;
            Eigen::Matrix3d Jl;
            int rows;
            for (std::size_t k = 0; k < obs.size(); ++k) {
                if (!active[k]) continue;
                const auto& o = obs[k];
                if (!observationJacobians(T_cw[o.pose], X[o.landmark], o.uv, o.depth, K, opts.bf, r,
                                          Jp, Jl, rows))
                    continue;
                const double e2 = r.squaredNorm() * o.inv_sigma2;
                const double d2 = rows == 3 ? opts.chi2_stereo : opts.chi2_mono;
                const double w =
                    o.inv_sigma2 * o.weight * (e2 <= d2 ? 1.0 : std::sqrt(d2 / e2));
                const auto Jpr = Jp;
                const auto Jlr = Jl;
                Hll[o.landmark] += w * Jlr.transpose() * Jlr;
                gl[o.landmark] += w * Jlr.transpose() * r;
                if (o.pose < P) {
                    Hpp.block<6, 6>(Eigen::Index{6} * o.pose, Eigen::Index{6} * o.pose) +=
                        w * Jpr.transpose() * Jpr;
                    gp.segment<6>(Eigen::Index{6} * o.pose) += w * Jpr.transpose() * r;
                    Hpl[k] = w * Jpr.transpose() * Jlr;
                }
            }
            // Schur complement over landmarks, with LM damping on all diagonal blocks.
            bool accepted = false;
            for (int attempt = 0; attempt < 5 && !accepted; ++attempt) {
                Eigen::MatrixXd S = Hpp;
                S.diagonal() +=
                    lambda * Hpp.diagonal() + Eigen::VectorXd::Constant(Eigen::Index{6} * P, 1e-9);
                Eigen::VectorXd rhs = -gp;
                std::vector<Eigen::Matrix3d> Hll_inv(L);
                for (int l = 0; l < L; ++l) {
                    Eigen::Matrix3d H = Hll[l];
                    H.diagonal() += lambda * Hll[l].diagonal() + Eigen::Vector3d::Constant(1e-9);
                    Hll_inv[l] = H.inverse();
                }
                // Group observations of each landmark to form S -= Hpl Hll^-1 Hlp.
                std::vector<std::vector<int>> obs_of_lm(L);
                for (std::size_t k = 0; k < obs.size(); ++k)
                    if (active[k] && obs[k].pose < P)
                        obs_of_lm[obs[k].landmark].push_back(static_cast<int>(k));
                for (int l = 0; l < L; ++l) {
                    const auto& ks = obs_of_lm[l];
                    for (int a : ks) {
                        const Mat63 A = Hpl[a] * Hll_inv[l];
                        rhs.segment<6>(Eigen::Index{6} * obs[a].pose) += A * gl[l];
                        for (int b : ks)
                            S.block<6, 6>(Eigen::Index{6} * obs[a].pose,
                                          Eigen::Index{6} * obs[b].pose) -= A * Hpl[b].transpose();
                    }
                }
                const Eigen::VectorXd dp = S.ldlt().solve(rhs);
                if (!dp.allFinite()) {
                    lambda *= 10;
                    continue;
                }
                std::vector<Eigen::Vector3d> gl_red = gl;
                for (int l = 0; l < L; ++l)
                    for (int a : obs_of_lm[l])
                        gl_red[l] +=
                            Hpl[a].transpose() * dp.segment<6>(Eigen::Index{6} * obs[a].pose);
                auto T_new = T_cw;
                auto X_new = X;
                for (int p = 0; p < P; ++p)
                    T_new[p] = expTwist(dp.segment<6>(Eigen::Index{6} * p)) * T_cw[p];
                for (int l = 0; l < L; ++l) X_new[l] = X[l] - Hll_inv[l] * gl_red[l];
                const double new_cost = robustCost(T_new, X_new);
                if (new_cost < cost) {
                    T_cw = std::move(T_new);
                    X = std::move(X_new);
                    const double rel = (cost - new_cost) / std::max(cost, 1e-12);
                    cost = new_cost;
                    lambda = std::max(lambda / 10, 1e-7);
                    accepted = true;
                    if (rel < 1e-6) it = opts.iterations;
                } else {
                    lambda *= 10;
                }
            }
            ++res.iterations;
            if (!accepted) break;
        }
    }
    res.final_cost = cost;
    for (int p = 0; p < P; ++p)
        res.max_shift =
            std::max(res.max_shift, (T_cw[p].inverse().translation() -
                                     map.keyframe(pose_ids[p]).T_wc.translation())
                                        .norm());
    res.rejected = opts.max_keyframe_shift > 0 && res.max_shift > opts.max_keyframe_shift;
    if (res.rejected) return res;  // the map stays as it was, observations included
    for (int p = 0; p < P; ++p) map.keyframe(pose_ids[p]).T_wc = T_cw[p].inverse();
    for (int l = 0; l < L; ++l) map.landmark(lm_ids[l])->p_w = X[l];

    // Drop observations that are still outliers; landmarks left without any go too.
    for (const auto& o : obs) {
        if (!isOutlier(o)) continue;
        map.removeObservation(lm_ids[o.landmark], o.kf, o.kp);
        ++res.n_outliers_removed;
    }
    for (LandmarkId id : lm_ids) {
        const Landmark* l = map.landmark(id);
        if (l && l->observations.empty()) map.removeLandmark(id);
    }
    return res;
}

}  // namespace devslam::slam
