#include <devslam/slam/PoseSolver.h>

#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

namespace devslam::slam {

Eigen::Isometry3d expTwist(const Eigen::Matrix<double, 6, 1>& xi) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    const Eigen::Vector3d w = xi.tail<3>();
    const double a = w.norm();
    if (a > 1e-12) T.linear() = Eigen::AngleAxisd(a, w / a).toRotationMatrix();
    T.translation() = xi.head<3>();
    return T;
}

std::optional<PnpResult> solvePnpRansac(const std::vector<PoseObservation>& obs,
                                        const core::CameraIntrinsics& K,
                                        const PnpRansacOptions& opts,
                                        const std::optional<Eigen::Isometry3d>& guess_T_wc) {
    const int need = std::max(6, opts.min_inliers);
    if (static_cast<int>(obs.size()) < need) return std::nullopt;
    std::vector<cv::Point3f> obj;
    std::vector<cv::Point2f> img;
    obj.reserve(obs.size());
    img.reserve(obs.size());
    for (const auto& o : obs) {
        obj.emplace_back(static_cast<float>(o.p_w.x()), static_cast<float>(o.p_w.y()),
                         static_cast<float>(o.p_w.z()));
        img.emplace_back(static_cast<float>(o.uv.x()), static_cast<float>(o.uv.y()));
    }
    const cv::Matx33d Kc = K.cvMatrix();
    cv::Mat rvec, tvec;
    bool use_guess = false;
    if (guess_T_wc) {
        const Eigen::Isometry3d T_cw = guess_T_wc->inverse();
        cv::Mat R;
        Eigen::Matrix3d Re = T_cw.linear();
        cv::eigen2cv(Re, R);
        cv::Rodrigues(R, rvec);
        tvec = (cv::Mat_<double>(3, 1) << T_cw.translation().x(), T_cw.translation().y(),
                T_cw.translation().z());
        use_guess = true;
    }
    std::vector<int> inliers;
    const bool ok = cv::solvePnPRansac(obj, img, Kc, cv::noArray(), rvec, tvec, use_guess,
                                       opts.iterations, static_cast<float>(opts.reprojection_px),
                                       opts.confidence, inliers, cv::SOLVEPNP_EPNP);
    if (!ok || static_cast<int>(inliers.size()) < need) return std::nullopt;
    cv::Mat R;
    cv::Rodrigues(rvec, R);
    Eigen::Matrix3d Re;
    cv::cv2eigen(R, Re);
    Eigen::Isometry3d T_cw = Eigen::Isometry3d::Identity();
    T_cw.linear() = Re;
    T_cw.translation() =
        Eigen::Vector3d(tvec.at<double>(0), tvec.at<double>(1), tvec.at<double>(2));
    if (!T_cw.matrix().allFinite()) return std::nullopt;
    return PnpResult{T_cw.inverse(), inliers};
}

bool observationJacobians(const Eigen::Isometry3d& T_cw, const Eigen::Vector3d& p_w,
                          const Eigen::Vector2d& uv, double depth, const core::CameraIntrinsics& K,
                          double bf, Eigen::Vector3d& r, Eigen::Matrix<double, 3, 6>& J_pose,
                          Eigen::Matrix3d& J_point, int& rows) {
    const Eigen::Vector3d pc = T_cw * p_w;
    if (pc.z() <= 1e-3) return false;
    const double iz = 1.0 / pc.z(), iz2 = iz * iz;
    const double u = K.fx * pc.x() * iz + K.cx, v = K.fy * pc.y() * iz + K.cy;
    Eigen::Matrix3d Jproj = Eigen::Matrix3d::Zero();  // d(u, v, ur)/d(pc)
    Jproj(0, 0) = K.fx * iz;
    Jproj(0, 2) = -K.fx * pc.x() * iz2;
    Jproj(1, 1) = K.fy * iz;
    Jproj(1, 2) = -K.fy * pc.y() * iz2;
    rows = depth > 0 ? 3 : 2;
    r(0) = u - uv.x();
    r(1) = v - uv.y();
    r(2) = 0;
    if (rows == 3) {
        const double ur_pred = u - bf * iz;
        const double ur_meas = uv.x() - bf / depth;
        r(2) = ur_pred - ur_meas;
        Jproj.row(2) = Jproj.row(0);
        Jproj(2, 2) += bf * iz2;
    }
    // Left perturbation T_cw <- exp([v, w]) T_cw: d(pc) = v + w x pc.
    Eigen::Matrix<double, 3, 6> dpc;
    dpc.leftCols<3>().setIdentity();
    dpc.rightCols<3>() << 0, pc.z(), -pc.y(), -pc.z(), 0, pc.x(), pc.y(), -pc.x(), 0;
    J_pose = Jproj * dpc;
    J_point = Jproj * T_cw.linear();
    return true;
}

PoseObservation observationOf(const FrameFeatures& f, std::size_t i, const Eigen::Vector3d& p_w,
                              double scale_factor) {
    const auto& kp = f.keypoints[i];
    return {p_w, {kp.pt.x, kp.pt.y}, f.depth[i], f.information(i, scale_factor), f.weightOf(i)};
}

PoseRefineResult refinePose(const std::vector<PoseObservation>& obs,
                            const Eigen::Isometry3d& T_wc_init, const core::CameraIntrinsics& K,
                            const PoseRefineOptions& opts) {
    PoseRefineResult res;
    Eigen::Isometry3d T_cw = T_wc_init.inverse();
    res.inlier.assign(obs.size(), 1);
    Eigen::Vector3d r;
    Eigen::Matrix<double, 3, 6> Jp;
    Eigen::Matrix3d Jl;
    int rows = 0;
    for (int round = 0; round < opts.rounds; ++round) {
        const bool robust = round < 2;
        for (int it = 0; it < opts.iterations; ++it) {
            Eigen::Matrix<double, 6, 6> H = Eigen::Matrix<double, 6, 6>::Zero();
            Eigen::Matrix<double, 6, 1> g = Eigen::Matrix<double, 6, 1>::Zero();
            int n = 0;
            for (std::size_t i = 0; i < obs.size(); ++i) {
                if (!res.inlier[i]) continue;
                const auto& o = obs[i];
                if (!observationJacobians(T_cw, o.p_w, o.uv, o.depth, K, opts.bf, r, Jp, Jl, rows))
                    continue;
                const double e2 = r.squaredNorm() * o.inv_sigma2;
                const double delta2 = rows == 3 ? opts.chi2_stereo : opts.chi2_mono;
                double w = o.inv_sigma2 * o.weight;
                if (robust && e2 > delta2) w *= std::sqrt(delta2 / e2);  // Huber
                H += w * Jp.transpose() * Jp;
                g += w * Jp.transpose() * r;
                ++n;
            }
            if (n < 3) break;
            const Eigen::Matrix<double, 6, 1> dx = H.ldlt().solve(-g);
            if (!dx.allFinite()) break;
            T_cw = expTwist(dx) * T_cw;
            if (dx.squaredNorm() < 1e-14) break;
        }
        // Re-classify every observation (outliers may come back).
        res.n_inliers = 0;
        for (std::size_t i = 0; i < obs.size(); ++i) {
            const auto& o = obs[i];
            if (!observationJacobians(T_cw, o.p_w, o.uv, o.depth, K, opts.bf, r, Jp, Jl, rows)) {
                res.inlier[i] = 0;
                continue;
            }
            const double e2 = r.squaredNorm() * o.inv_sigma2;
            res.inlier[i] = e2 <= (rows == 3 ? opts.chi2_stereo : opts.chi2_mono) ? 1 : 0;
            res.n_inliers += res.inlier[i];
        }
        if (res.n_inliers < 10) break;
    }
    double se = 0;
    for (std::size_t i = 0; i < obs.size(); ++i) {
        if (!res.inlier[i]) continue;
        if (observationJacobians(T_cw, obs[i].p_w, obs[i].uv, 0.0, K, opts.bf, r, Jp, Jl, rows))
            se += r.head<2>().squaredNorm();
    }
    res.rms_px = res.n_inliers > 0 ? std::sqrt(se / res.n_inliers) : 0.0;
    res.T_wc = T_cw.inverse();
    return res;
}

double inlierReach(const PoseObservation& o, const core::CameraIntrinsics& K,
                   const PoseRefineOptions& opts) {
    constexpr double kInf = std::numeric_limits<double>::infinity();
    const double d = o.depth;
    if (!(d > 0) || !(o.inv_sigma2 > 0)) return kInf;
    // The gate [px], a little wider for rounding: where 1/d is barely above the gate in 1/z,
    // z_max is huge and the chi2 test's own rounding (bf/z' below 1e-13 px) takes any z'.
    const double rho = std::sqrt(opts.chi2_stereo / o.inv_sigma2) * (1 + 1e-9) + 1e-9;
    // |r_u| + |r_ur| <= sqrt(2) rho bounds |bf/z' - bf/d|, z' the moved point's depth.
    const double dinv = std::sqrt(2.0) * rho / opts.bf;
    if (1.0 / d - dinv <= 0) return kInf;
    const double z_max = 1.0 / (1.0 / d - dinv);
    const double dz = z_max - d;  // 1/z is convex: the far side is the wider one
    // x' - x = ((u' - cx) z' - (u - cx) d) / fx with |u' - u| <= rho; y alike.
    const double ex = (rho * z_max + std::abs(o.uv.x() - K.cx) * dz) / K.fx;
    const double ey = (rho * z_max + std::abs(o.uv.y() - K.cy) * dz) / K.fy;
    // A little slack for rounding (the observations come from floats).
    return std::sqrt(ex * ex + ey * ey + dz * dz) * (1 + 1e-6) + 1e-6;
}

namespace {

/// inlierBound's observations with a bounded gate: the world point, the point the keypoint
/// and its depth measure, and how far from it the moved world point of an inlier can be.
struct Measured {
    const Eigen::Vector3d* p_w;
    Eigen::Vector3d p_c;
    double e;
};

/// The observations with a bounded gate, and the count of the others.
std::vector<Measured> measured(const std::vector<PoseObservation>& obs,
                               const core::CameraIntrinsics& K, const PoseRefineOptions& opts,
                               int& unconstrained) {
    std::vector<Measured> m;
    m.reserve(obs.size());
    unconstrained = 0;
    for (const auto& o : obs) {
        const double e = inlierReach(o, K, opts);
        if (!std::isfinite(e)) {
            ++unconstrained;
            continue;
        }
        m.push_back(
            {&o.p_w,
             {(o.uv.x() - K.cx) * o.depth / K.fx, (o.uv.y() - K.cy) * o.depth / K.fy, o.depth},
             e});
    }
    return m;
}

/// Whether i and j can both be inliers of one pose (which preserves their distance).
bool consistent(const Measured& i, const Measured& j) {
    return std::abs((*i.p_w - *j.p_w).norm() - (i.p_c - j.p_c).norm()) <= i.e + j.e;
}

/// The degeneracy of m's consistency graph plus one: at least its largest clique.
int cliqueBound(const std::vector<Measured>& m) {
    const std::size_t n = m.size();
    if (n == 0) return 0;
    std::vector<std::vector<std::size_t>> adj(n);
    for (std::size_t i = 0; i < n; ++i)
        for (std::size_t j = i + 1; j < n; ++j)
            if (consistent(m[i], m[j])) {
                adj[i].push_back(j);
                adj[j].push_back(i);
            }
    // Remove a vertex of least degree until none is left; the vertices of a clique of k
    // keep degree >= k - 1 until the first of them is removed.
    std::vector<std::size_t> degree(n);
    for (std::size_t i = 0; i < n; ++i) degree[i] = adj[i].size();
    std::vector<char> removed(n, 0);
    std::size_t degeneracy = 0;
    for (std::size_t step = 0; step < n; ++step) {
        std::size_t v = n;
        for (std::size_t i = 0; i < n; ++i)
            if (!removed[i] && (v == n || degree[i] < degree[v])) v = i;
        degeneracy = std::max(degeneracy, degree[v]);
        removed[v] = 1;
        for (const std::size_t w : adj[v])
            if (!removed[w]) --degree[w];
    }
    return static_cast<int>(degeneracy) + 1;
}

}  // namespace

int inlierBound(const std::vector<PoseObservation>& obs, const core::CameraIntrinsics& K,
                const PoseRefineOptions& opts) {
    int unconstrained = 0;
    const auto m = measured(obs, K, opts, unconstrained);
    return unconstrained + cliqueBound(m);
}

bool inlierBoundReaches(const std::vector<PoseObservation>& obs, int k,
                        const core::CameraIntrinsics& K, const PoseRefineOptions& opts) {
    if (static_cast<int>(obs.size()) < k) return false;
    int unconstrained = 0;
    const auto m = measured(obs, K, opts, unconstrained);
    const int need = k - unconstrained;
    if (need <= 0) return true;
    // Correspondences of the true place are nearly all consistent: a greedy clique of `need`
    // (grown from each of the first few observations, an outlier among them) proves the
    // bound reaches k in O(n k), where the bound itself is O(n^2) (0.6 ms for 300).
    std::vector<std::size_t> clique;
    for (std::size_t s = 0; s < std::min<std::size_t>(m.size(), 4); ++s) {
        clique.assign(1, s);
        for (std::size_t i = 0; i < m.size() && static_cast<int>(clique.size()) < need; ++i)
            if (i != s && std::all_of(clique.begin(), clique.end(),
                                      [&](std::size_t c) { return consistent(m[i], m[c]); }))
                clique.push_back(i);
        if (static_cast<int>(clique.size()) >= need) return true;
    }
    return cliqueBound(m) >= need;
}
}  // namespace devslam::slam
