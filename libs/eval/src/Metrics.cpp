#include <devslam/eval/Metrics.h>

#include <devslam/core/Association.h>
#include <devslam/core/Parse.h>
#include <devslam/core/Pose.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace devslam::eval {

Eigen::Isometry3d hornAlign(const std::vector<Eigen::Vector3d>& model,
                            const std::vector<Eigen::Vector3d>& data) {
    if (model.size() != data.size())
        throw std::invalid_argument("hornAlign: " + std::to_string(model.size()) + " model vs " +
                                    std::to_string(data.size()) + " data points");
    if (model.size() < 3)
        throw std::invalid_argument("hornAlign: need at least 3 point pairs, got " +
                                    std::to_string(model.size()));
    Eigen::Matrix3Xd src(3, data.size()), dst(3, model.size());
    for (std::size_t i = 0; i < data.size(); ++i) src.col(i) = data[i], dst.col(i) = model[i];
    // Eigen's Umeyama without scale is the same least-squares optimum as Horn's closed form
    // used by evaluate_ate.py (SVD of the cross-covariance with the reflection fix).
    Eigen::Isometry3d T;
    T.matrix() = Eigen::umeyama(src, dst, false);
    return T;
}

AteResult computeAte(const core::Trajectory& gt, const core::Trajectory& est,
                     const AteOptions& opts) {
    // 1e308 overflowed the alignment: an rmse of -nan.
    if (!(opts.scale >= kMinScale && opts.scale <= kMaxScale))
        throw std::invalid_argument("ATE: scale " + std::to_string(opts.scale) +
                                    " is outside [1e-6, 1e6]");
    std::vector<double> tg, te;
    for (const auto& p : gt) tg.push_back(p.t);
    for (const auto& p : est) te.push_back(p.t);
    // evaluate_ate.py: associate(gt, est, offset, max_difference) with the offset on est.
    const auto pairs = core::associate(tg, te, opts.max_dt, opts.offset);
    // The alignment needs three points; with fewer poses than that the files are fine.
    if (pairs.size() < 3 && pairs.size() == std::min(est.size(), gt.size()))
        throw std::invalid_argument("ATE: " + std::to_string(pairs.size()) +
                                    " associated poses, the alignment needs at least 3 (" +
                                    std::to_string(est.size()) + " estimated, " +
                                    std::to_string(gt.size()) + " in the ground truth)");
    if (pairs.size() < 3)
        throw std::invalid_argument(
            "ATE: only " + std::to_string(pairs.size()) + " of " + std::to_string(est.size()) +
            " estimated poses associate with the ground truth within " +
            core::shortestReal(opts.max_dt) +  // (to_string wrote 1e-300 as 0.000000)
            " s (wrong files, or timestamps in other units?)");
    AteResult r;
    r.n_gt = gt.size();
    r.n_est = est.size();
    std::vector<Eigen::Vector3d> model, data;
    for (const auto& [i, j] : pairs) {
        const auto& g = gt[i].pose;
        const auto& e = est[j].pose;
        model.emplace_back(g.x(), g.y(), g.z());
        data.emplace_back(opts.scale * e.x(), opts.scale * e.y(), opts.scale * e.z());
        r.stamps.push_back(est[j].t);
    }
    r.T_gt_est = hornAlign(model, data);
    for (std::size_t k = 0; k < model.size(); ++k) {
        const Eigen::Vector3d aligned = r.T_gt_est * data[k];
        r.errors.push_back((aligned - model[k]).norm());
        r.est_xyz.push_back(aligned);
    }
    r.gt_xyz = std::move(model);
    r.trans = core::summarize(r.errors);
    if (!std::isfinite(r.trans.rmse) || !std::isfinite(r.trans.max))
        throw std::invalid_argument("ATE: the alignment overflowed (positions or scale too "
                                    "large): the figures are not finite");
    return r;
}

namespace {

// evaluate_rpe.py's find_closest_index, reproduced step by step (a bisection that keeps the
// best |L[m] - t| seen on the way; ties keep the earlier-visited index).
std::size_t findClosestIndex(const std::vector<double>& L, double t) {
    std::size_t begin = 0, end = L.size(), best = 0;
    double diff = std::abs(L[0] - t);
    while (begin < end) {
        const std::size_t mid = (begin + end) / 2;
        if (std::abs(L[mid] - t) < diff) {
            diff = std::abs(L[mid] - t);
            best = mid;
        }
        if (t == L[mid]) return mid;
        if (L[mid] > t)
            end = mid;
        else
            begin = mid + 1;
    }
    return best;
}

}  // namespace

RpeResult computeRpe(const core::Trajectory& gt, const core::Trajectory& est,
                     const RpeOptions& opts) {
    if (gt.size() < 2 || est.size() < 2)
        throw std::invalid_argument("RPE: need at least 2 poses in each trajectory");
    if (!(opts.delta > 0)) throw std::invalid_argument("RPE: delta must be > 0");
    // evaluate_rpe.py takes whole frames; half a frame pairs each pose with itself (error 0).
    if (opts.delta_in_frames && opts.delta != std::floor(opts.delta))
        throw std::invalid_argument("RPE: a delta in frames must be a whole number, got " +
                                    (std::ostringstream() << opts.delta).str());
    std::vector<double> sg, se;
    for (const auto& p : gt) sg.push_back(p.t);
    for (const auto& p : est) se.push_back(p.t);
    // Trajectories are sorted by construction (readers reject unsorted files).
    std::vector<double> index(se.size());
    for (std::size_t i = 0; i < se.size(); ++i)
        index[i] = opts.delta_in_frames ? static_cast<double>(i) : se[i];

    // evaluate_rpe.py's overlap check: from each estimate stamp to its nearest ground truth
    // and back to the nearest estimate stamp; fewer than two of those come back when the two
    // trajectories hardly overlap in time, and their pairs would all meet the same
    // ground-truth pose (the figures then the estimate's own motion).
    const auto back = [&](std::size_t i) {
        return findClosestIndex(se, sg[findClosestIndex(sg, se[i] + opts.offset)] - opts.offset);
    };
    const std::size_t first = back(0);
    bool two_back = false;
    for (std::size_t i = 1; i < se.size() && !two_back; ++i) two_back = back(i) != first;
    if (!two_back)
        throw std::invalid_argument(
            "RPE: the trajectories overlap in time at one estimate pose only (evaluate_rpe.py: "
            "'Number of overlap in the timestamps is too small'): the right files, the right "
            "offset?");

    std::vector<double> intervals;
    for (std::size_t i = 1; i < sg.size(); ++i) intervals.push_back(sg[i] - sg[i - 1]);
    const double gt_max_dt = 2.0 * core::median(intervals);

    std::vector<double> trans, rot;
    // A delta past the estimate's whole span pairs each pose with the last one, and such
    // pairs are dropped: none is left. Searched for, a delta of 1e16 s swamps the stamps in
    // double precision (every |stamp - target| rounds to the same number) and paired each pose
    // with the first one.
    const bool any_pair = opts.delta <= index.back() - index.front();
    for (std::size_t i = 0; any_pair && i < se.size(); ++i) {
        const std::size_t j = findClosestIndex(index, index[i] + opts.delta);
        if (j == se.size() - 1) continue;  // evaluate_rpe.py drops pairs ending at the last pose
        // A delta under half the frame interval finds the pose itself: evaluate_rpe.py counts
        // that pair (no motion, error 0) and gives a perfect RPE; it is no relative pose.
        if (j == i) continue;
        const std::size_t g0 = findClosestIndex(sg, se[i] + opts.offset);
        const std::size_t g1 = findClosestIndex(sg, se[j] + opts.offset);
        if (std::abs(sg[g0] - (se[i] + opts.offset)) > gt_max_dt ||
            std::abs(sg[g1] - (se[j] + opts.offset)) > gt_max_dt)
            continue;
        const mrpt::poses::CPose3D rel_est = est[j].pose - est[i].pose;  // A = P_i^-1 P_j
        mrpt::poses::CPose3D inv_rel_gt = gt[g1].pose - gt[g0].pose;     // B = Q_i^-1 Q_j
        inv_rel_gt.inverse();
        // evaluate_rpe.py's ominus(ominus(P_j, P_i), ominus(Q_j, Q_i)) = A B^-1. Its
        // translation, t_A - R_A R_B^T t_B, is not that of A^-1 B (|t_B - t_A|) when the
        // rotations differ: a rotation error adds to the translational figure there.
        const mrpt::poses::CPose3D err = rel_est + inv_rel_gt;
        trans.push_back(err.norm());
        rot.push_back(core::rotationAngle(err) * 180.0 / M_PI);
    }
    // evaluate_rpe.py gives no figures for fewer than two pairs either.
    if (trans.size() < 2)
        throw std::invalid_argument(
            "RPE: " + std::string(trans.empty() ? "no pose pair" : "one pose pair") + " " +
            (std::ostringstream() << opts.delta).str() + (opts.delta_in_frames ? " frames" : " s") +
            " apart that ends before the estimate's last pose (evaluate_rpe.py drops those) and "
            "has ground truth at both ends; two are needed (sequence too short?)");
    RpeResult r;
    r.trans = core::summarize(trans);
    r.rot = core::summarize(rot);
    r.n_pairs = trans.size();
    return r;
}

std::optional<RelativePoseError> relativePoseError(const core::Trajectory& gt, double t_a,
                                                   double t_b, const Eigen::Isometry3d& T_a_b,
                                                   double max_dt) {
    const auto nearest = [&](double t) -> std::optional<Eigen::Isometry3d> {
        const core::StampedPose* best = nullptr;
        for (const auto& p : gt)  // gt need not be sorted
            if (!best || std::abs(p.t - t) < std::abs(best->t - t)) best = &p;
        if (!best || std::abs(best->t - t) > max_dt) return std::nullopt;
        return core::toIsometry(best->pose);
    };
    const auto Qa = nearest(t_a), Qb = nearest(t_b);
    if (!Qa || !Qb) return std::nullopt;
    const Eigen::Isometry3d E = (Qa->inverse() * *Qb).inverse() * T_a_b;
    return RelativePoseError{E.translation().norm(),
                             Eigen::AngleAxisd(E.linear()).angle() * 180.0 / M_PI};
}

}  // namespace devslam::eval
