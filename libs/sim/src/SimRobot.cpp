#include <devslam/sim/SimRobot.h>

#include <mrpt/core/Clock.h>
#include <mrpt/kinematics/CVehicleVelCmd_DiffDriven.h>
#include <mrpt/maps/CSimplePointsMap.h>

#include <cmath>

namespace devslam::sim {

bool SimRobot::getCurrentPoseAndSpeeds(mrpt::math::TPose2D& pose, mrpt::math::TTwist2D& vel_global,
                                       mrpt::system::TTimeStamp& timestamp,
                                       mrpt::math::TPose2D& odometry, std::string& frame_id) {
    pose = sim_.robotPose();
    const double v = sim_.linearVelocity();
    vel_global = mrpt::math::TTwist2D(v * std::cos(pose.phi), v * std::sin(pose.phi),
                                      sim_.angularVelocity());
    timestamp = mrpt::Clock::now();
    odometry = pose;
    frame_id = "map";
    return true;
}

bool SimRobot::changeSpeeds(const mrpt::kinematics::CVehicleVelCmd& cmd) {
    const auto* dd = dynamic_cast<const mrpt::kinematics::CVehicleVelCmd_DiffDriven*>(&cmd);
    if (!dd) return false;  // only differential-drive commands make sense here
    sim_.setCommand(dd->lin_vel, dd->ang_vel);
    return true;
}

bool SimRobot::stop(bool /*is_emergency_stop*/) {
    sim_.setCommand(0, 0);
    return true;
}

mrpt::kinematics::CVehicleVelCmd::Ptr SimRobot::getEmergencyStopCmd() {
    return getStopCmd();
}

mrpt::kinematics::CVehicleVelCmd::Ptr SimRobot::getStopCmd() {
    auto cmd = std::make_shared<mrpt::kinematics::CVehicleVelCmd_DiffDriven>();
    cmd->setToStop();
    return cmd;
}

bool SimRobot::senseObstacles(mrpt::maps::CSimplePointsMap& obstacles,
                              mrpt::system::TTimeStamp& timestamp) {
    const auto& s = sim_.scan();
    obstacles.clear();
    for (size_t i = 0; i < s.ranges.size(); i++)
        if (s.hit[i])
            obstacles.insertPoint(static_cast<float>(s.ranges[i] * std::cos(s.angles[i])),
                                  static_cast<float>(s.ranges[i] * std::sin(s.angles[i])), 0.2f);
    timestamp = mrpt::Clock::now();
    return true;
}

}  // namespace devslam::sim
