#pragma once
/// Trajectory metrics exactly as the TUM RGB-D benchmark tools (evaluate_ate.py,
/// evaluate_rpe.py) define them.
///
/// Usage:
///   auto ate = devslam::eval::computeAte(gt, est);           // Horn alignment, no scale
///   auto rpe = devslam::eval::computeRpe(gt, est, {});       // delta 1 s
///   std::cout << devslam::eval::formatTable(ate, rpe);

#include <devslam/core/Stats.h>
#include <devslam/core/Trajectory.h>

#include <Eigen/Geometry>

#include <optional>
#include <string>
#include <vector>

namespace devslam::eval {

/// The range of AteOptions::scale (computeAte refuses others).
inline constexpr double kMinScale = 1e-6, kMaxScale = 1e6;

struct AteOptions {
    double max_dt = 0.02;  ///< [s] association window (associate.py --max_difference)
    double offset = 0.0;   ///< [s] added to the estimate's stamps (--offset)
    double scale = 1.0;    ///< multiplies the estimate's translations (--scale)
};

struct AteResult {
    core::Summary trans;                   ///< translational error after alignment [m]
    Eigen::Isometry3d T_gt_est;            ///< alignment: p_gt ~= T_gt_est * p_est
    std::vector<double> stamps;            ///< associated estimate stamps
    std::vector<Eigen::Vector3d> gt_xyz;   ///< associated ground truth positions
    std::vector<Eigen::Vector3d> est_xyz;  ///< aligned estimate positions
    std::vector<double> errors;            ///< per pair [m]
    std::size_t n_gt = 0, n_est = 0;       ///< poses in each input
};

/// Associates est to gt, aligns with Horn's closed-form rigid transform (no scale) and
/// summarises the translational residuals. Throws std::invalid_argument when fewer than 3
/// pairs associate, for a scale outside [kMinScale, kMaxScale], and when the figures are not
/// finite.
[[nodiscard]] AteResult computeAte(const core::Trajectory& gt, const core::Trajectory& est,
                                   const AteOptions& opts = {});

/// Horn (1987) closed-form rigid alignment of column-matched point sets: returns T with
/// model ~= T * data minimising the sum of squared distances (no scale). Throws
/// std::invalid_argument for fewer than 3 points or mismatched sizes.
[[nodiscard]] Eigen::Isometry3d hornAlign(const std::vector<Eigen::Vector3d>& model,
                                          const std::vector<Eigen::Vector3d>& data);

struct RpeOptions {
    double delta = 1.0;            ///< fixed interval
    bool delta_in_frames = false;  ///< false: delta in seconds ("s"); true: in frames ("f")
    double offset = 0.0;           ///< [s] added to the estimate's stamps
};

struct RpeResult {
    core::Summary trans;  ///< [m]
    core::Summary rot;    ///< [deg]
    std::size_t n_pairs = 0;
};

/// E_i = (P_i^-1 P_j) (Q_i^-1 Q_j)^-1, j = the estimate index closest to "i + delta"
/// (evaluate_rpe.py --fixed_delta, which also skips j = last index): the translational norm
/// and rotation angle of E_i. The TUM paper's (Q_i^-1 Q_j)^-1 (P_i^-1 P_j) has the same angle
/// but another translation; the script's is the one published (docs/eval.md). Q (ground
/// truth) is the gt pose closest to each estimate stamp, and a pair is skipped when that is
/// more than twice the median gt interval away, as evaluate_rpe.py does. Throws
/// std::invalid_argument when fewer than two pairs exist (evaluate_rpe.py raises too).
[[nodiscard]] RpeResult computeRpe(const core::Trajectory& gt, const core::Trajectory& est,
                                   const RpeOptions& opts = {});

struct RelativePoseError {
    double trans = 0;  ///< [m]
    double rot = 0;    ///< [deg]
};

/// Error of a measured relative pose `T_a_b` (pose at time t_b in the frame of the pose at
/// t_a, e.g. a SLAM loop constraint) against the ground truth: E = (Q_a^-1 Q_b)^-1 T_a_b,
/// Q the gt poses nearest in time to t_a and t_b. nullopt when either is more than
/// `max_dt` [s] away. Unlike the ATE it does not depend on the trajectory's drift.
[[nodiscard]] std::optional<RelativePoseError> relativePoseError(const core::Trajectory& gt,
                                                                 double t_a, double t_b,
                                                                 const Eigen::Isometry3d& T_a_b,
                                                                 double max_dt = 0.02);

}  // namespace devslam::eval
