#include <devslam/io/TrajectoryIO.h>

#include "TextFile.h"

#include <devslam/core/Pose.h>

#include <mrpt/math/CQuaternion.h>
#include <mrpt/poses/CPose3DQuat.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <stdexcept>

namespace devslam::io {

core::Trajectory readTumTrajectory(const std::string& path) {
    core::Trajectory traj;
    int previous = 0;  // the line of traj.back()
    detail::forEachDataLine(path, [&](int line, const std::vector<std::string>& tok) {
        if (tok.size() != 8)
            throw std::runtime_error(
                detail::lineError(path, line,
                                  "expected 'timestamp tx ty tz qx qy qz qw' (8 values), got " +
                                      std::to_string(tok.size())));
        double v[8];
        static const char* kNames[8] = {"timestamp", "tx", "ty", "tz", "qx", "qy", "qz", "qw"};
        for (int k = 0; k < 8; ++k) v[k] = detail::parseNumber(tok[k], path, line, kNames[k]);
        // Beyond it the ATE's sums of squares overflowed: rmse -nan under exit status 0.
        for (int k = 1; k <= 3; ++k)
            if (std::abs(v[k]) > kMaxTrajectoryCoordinate)
                throw std::runtime_error(detail::lineError(
                    path, line,
                    std::string(kNames[k]) + " " + tok[k] + " is beyond +-1e6 m (not metres?)"));
        // As rgb.txt's: a last pose at 1e300 s was read, and the RPE paired the poses before
        // it across the gap (30 pairs instead of 5 on the shipped frames).
        if (v[0] < 0 || v[0] > 1e11)
            throw std::runtime_error(
                detail::lineError(path, line, "timestamp " + tok[0] + " is not in [0, 1e11] s"));
        if (!traj.empty() && v[0] <= traj.back().t)
            throw std::runtime_error(
                detail::lineError(path, line,
                                  detail::stampNotAfter(v[0], traj.back().t, tok[0]) +
                                      " (previous pose at line " + std::to_string(previous) + ")"));
        previous = line;
        try {
            traj.push_back({v[0], core::fromTum(v[1], v[2], v[3], v[4], v[5], v[6], v[7])});
        } catch (const std::invalid_argument& e) {
            throw std::runtime_error(detail::lineError(path, line, e.what()));
        }
    });
    if (traj.empty()) throw std::runtime_error(path + ": no poses");
    return traj;
}

void writeTumTrajectory(const std::string& path, const core::Trajectory& traj,
                        const std::string& header_comment) {
    auto f = detail::openForWriting(path);
    if (!header_comment.empty()) std::fprintf(f.get(), "# %s\n", header_comment.c_str());
    std::fprintf(f.get(), "# timestamp tx ty tz qx qy qz qw\n");
    for (const auto& sp : traj) {
        const mrpt::poses::CPose3DQuat q(sp.pose);
        std::fprintf(f.get(), "%.6f %.9f %.9f %.9f %.9f %.9f %.9f %.9f\n", sp.t, q.x(), q.y(),
                     q.z(), q.quat().x(), q.quat().y(), q.quat().z(), q.quat().r());
    }
    detail::closeWritten(f, "error writing '" + path + "'");
}

}  // namespace devslam::io
