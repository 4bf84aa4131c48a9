#pragma once
/// A timestamped camera trajectory (poses T_wc of the optical centre), as in TUM files.

#include <mrpt/poses/CPose3D.h>

#include <vector>

namespace devslam::core {

struct StampedPose {
    double t = 0.0;             ///< [s]
    mrpt::poses::CPose3D pose;  ///< T_wc: camera optical frame -> world
};
using Trajectory = std::vector<StampedPose>;

}  // namespace devslam::core
