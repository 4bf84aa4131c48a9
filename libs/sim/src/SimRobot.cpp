#include <devslam/sim/SimRobot.h>

#include <mrpt/core/Clock.h>
#include <mrpt/kinematics/CVehicleVelCmd_DiffDriven.h>
#include <mrpt/maps/CSimplePointsMap.h>
#include <mrpt/poses/CPose2D.h>

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
    // Ring points closer to the robot's centre than its edge (a person already inside the
    // margin) are left out: they would put an obstacle inside the robot's own shape, which
    // blocks every motion; the person's real points still stop it touching them.
    constexpr int kRing = 12;  // chord 0.5 x margin: no gap the robot fits through
    const double keep_out = sim_.world().robot.radius + 0.02;
    // At the laser's height, which MRPT's [CReactiveNavigationSystem] min/max_obstacles_height
    // band must hold (runEpisode checks it).
    const auto z = static_cast<float>(sim_.world().laser.height);
    // The points in the robot's frame now, which MRPT and the navigator take them in: a scan
    // older than this step (a laser slower than the navigator) was taken from another pose,
    // and its points were placed as if from this one (0.5 m off turning at 1.2 rad/s with a
    // 5 Hz laser).
    const bool moved = s.t != sim_.time();
    // (a - b: a seen from b)
    const mrpt::poses::CPose2D now_from_scan =
        mrpt::poses::CPose2D(s.pose) - mrpt::poses::CPose2D(sim_.robotPose());
    const auto insert = [&](double x, double y, bool ring) {
        if (moved) now_from_scan.composePoint(x, y, x, y);
        if (ring && std::hypot(x, y) < keep_out) return;
        obstacles.insertPoint(static_cast<float>(x), static_cast<float>(y), z);
    };
    std::vector<mrpt::math::TPoint2D> person_world;  // this scan's person points, for the tracker
    const mrpt::poses::CPose2D scan_pose(s.pose);
    for (size_t i = 0; i < s.ranges.size(); i++) {
        if (!s.hit[i]) continue;
        const double x = s.ranges[i] * std::cos(s.angles[i]);
        const double y = s.ranges[i] * std::sin(s.angles[i]);
        insert(x, y, false);
        if (predict_horizon_ > 0 && s.person[i]) {
            mrpt::math::TPoint2D w;
            scan_pose.composePoint(x, y, w.x, w.y);
            person_world.push_back(w);
        }
        if (person_margin_ <= 0 || !s.person[i]) continue;
        for (int k = 0; k < kRing; k++) {
            const double a = 2 * M_PI * k / kRing;
            insert(x + person_margin_ * std::cos(a), y + person_margin_ * std::sin(a), true);
        }
    }
    if (predict_horizon_ > 0) {
        // Once per scan (the tracker ignores a scan it has had); the predicted points, in the
        // world frame, are put in the robot's frame now. Those inside the robot's own shape are
        // left out as ring points are: a walker's path through where the robot stands would
        // block every motion, and the walker's own points still keep the robot off them.
        tracker_.update(s.t, {s.pose.x, s.pose.y}, person_world);
        const mrpt::poses::CPose2D now(sim_.robotPose());
        for (const auto& w : tracker_.predictedPoints(predict_horizon_)) {
            double x = 0, y = 0;
            now.inverseComposePoint(w.x, w.y, x, y);
            if (std::hypot(x, y) < keep_out) continue;
            obstacles.insertPoint(static_cast<float>(x), static_cast<float>(y), z);
        }
    }
    timestamp = mrpt::Clock::now();
    return true;
}

std::vector<nav::MovingPoints> SimRobot::sensedWalkers() {
    std::vector<nav::MovingPoints> out;
    if (predict_horizon_ <= 0) return out;  // (the tracker is fed only then)
    const mrpt::poses::CPose2D now(sim_.robotPose());
    const double c = std::cos(now.phi()), s = std::sin(now.phi());
    for (const auto& p : tracker_.walkers()) {
        const double age = sim_.time() - p.t;  // (a laser slower than the navigator)
        nav::MovingPoints m;
        m.velocity = {c * p.velocity.x + s * p.velocity.y, -s * p.velocity.x + c * p.velocity.y};
        for (const auto& q : p.points) {
            mrpt::math::TPoint2D r;
            now.inverseComposePoint(q.x + p.velocity.x * age, q.y + p.velocity.y * age, r.x, r.y);
            m.points.push_back(r);
        }
        out.push_back(std::move(m));
    }
    return out;
}

}  // namespace devslam::sim
