#pragma once
/// MRPT's CRobot2NavInterface on top of the Bullet Simulator, so MRPT's reactive navigator
/// drives the simulated robot exactly as it would drive a real one: pose and speeds from
/// the rigid body, (v, w) commands through CVehicleVelCmd_DiffDriven, obstacles from the
/// latest laser scan in the robot frame, time from the simulation clock.
///
/// People get extra room: with `person_margin` > 0 every laser point on a pedestrian is
/// surrounded by a ring of points that far out, so every holonomic method and the replanner
/// keep that much more distance from people than from walls. (The simulator knows which
/// body a ray hit; on the robot that knowledge would come from the person detector.)
///
/// Walkers' paths too: with `person_predict_horizon` > 0 the person points of each new scan
/// feed a nav::PeopleTracker, and every moving person's points are also reported where its
/// velocity takes them over that many seconds (nav/PeopleTracker.h), so the navigator gives
/// way to where people are going, not only to where they are. The same tracks go to the speed
/// guard as walkers (nav::WalkerSensor), which it checks at each instant of a stop.
///
/// Usage:
///   devslam::sim::SimRobot robot(sim);
///   mrpt::nav::CReactiveNavigationSystem nav(robot);
/// Not thread-safe.
#include <devslam/nav/PeopleTracker.h>
#include <devslam/nav/SpeedGuard.h>
#include <devslam/sim/Simulator.h>

#include <mrpt/nav/reactive/CRobot2NavInterface.h>

namespace devslam::sim {

class SimRobot : public mrpt::nav::CRobot2NavInterface, public nav::WalkerSensor {
  public:
    /// `person_margin` [m], `person_predict_horizon` [s]: see above; 0 and 0 report the scan
    /// as it is.
    explicit SimRobot(Simulator& sim, double person_margin = 0.0,
                      double person_predict_horizon = 0.0)
        : sim_(sim), person_margin_(person_margin), predict_horizon_(person_predict_horizon) {
        setMinLoggingLevel(mrpt::system::LVL_WARN);
    }

    bool getCurrentPoseAndSpeeds(mrpt::math::TPose2D& pose, mrpt::math::TTwist2D& vel_global,
                                 mrpt::system::TTimeStamp& timestamp, mrpt::math::TPose2D& odometry,
                                 std::string& frame_id) override;
    bool changeSpeeds(const mrpt::kinematics::CVehicleVelCmd& cmd) override;
    bool changeSpeedsNOP() override { return true; }
    bool stop(bool is_emergency_stop = true) override;
    mrpt::kinematics::CVehicleVelCmd::Ptr getEmergencyStopCmd() override;
    mrpt::kinematics::CVehicleVelCmd::Ptr getStopCmd() override;
    bool senseObstacles(mrpt::maps::CSimplePointsMap& obstacles,
                        mrpt::system::TTimeStamp& timestamp) override;
    /// The tracker's walkers (with `person_predict_horizon` > 0, else none): their last
    /// scan's points moved along their velocity to now, in the robot's frame now.
    [[nodiscard]] std::vector<nav::MovingPoints> sensedWalkers() override;
    double getNavigationTime() override { return sim_.time() - nav_t0_; }
    void resetNavigationTimer() override { nav_t0_ = sim_.time(); }

    void sendNavigationEndEvent() override { end_events_++; }
    void sendNavigationEndDueToErrorEvent() override { error_events_++; }
    void sendWaySeemsBlockedEvent() override { blocked_events_++; }
    void sendApparentCollisionEvent() override {}
    void sendNavigationStartEvent() override {}
    void sendWaypointReachedEvent(int, bool) override {}
    void sendNewWaypointTargetEvent(int) override {}
    void sendCannotGetCloserToBlockedTargetEvent() override {}

    [[nodiscard]] int endEvents() const { return end_events_; }
    [[nodiscard]] int errorEvents() const { return error_events_; }
    [[nodiscard]] int blockedEvents() const { return blocked_events_; }

  private:
    Simulator& sim_;
    double person_margin_ = 0;    ///< [m]
    double predict_horizon_ = 0;  ///< [s]
    nav::PeopleTracker tracker_;
    double nav_t0_ = 0;
    int end_events_ = 0, error_events_ = 0, blocked_events_ = 0;
};

}  // namespace devslam::sim
