#pragma once
/// A speed guard between MRPT's reactive navigator and the robot: each (v, w) command is
/// scaled down (both by one factor, so its arc stays the one MRPT checked) until the robot,
/// with its real acceleration limits, can follow it for one navigation period and then stop
/// without coming closer to a sensed point than `margin` beyond its radius.
///
/// Why: MRPT's PTGs assume the robot takes a commanded speed at once. A robot with
/// acceleration limits lags them: on a turn it drives wider than the arc MRPT checked, and
/// near a wall it cannot brake in the free distance MRPT saw. At 0.6 m/s this hardly matters;
/// at 1.4 m/s the robot of paper_fig6 (1 m/s^2, 180 deg/s^2) overshot its first turn into the
/// wall (docs/nav.md "The speed guard"). The test is the "admissible velocity" of the dynamic
/// window approach (a velocity from which the robot can still stop), made on the robot's own
/// motion model: each axis moves toward its command at most by its acceleration limit, as
/// sim::Simulator drives it. MRPT has no such check for differential robots (its blended
/// holonomic PTG models a ramp, its diff-drive PTGs do not), so it is written here.
///
///   MRPT navigationStep() ── changeSpeeds(v, w) ──► GuardedRobot ── s·(v, w) ──► robot
///                                                    ▲ latest speeds and sensed points
///
/// Inside radius + margin already (a wall brushed, a person come close), the bound is the
/// margin less 1 cm of laser noise (at least 5 mm), so a robot can drive along a wall it
/// brushes, and no point may come nearer than it is now, so a robot pushed closer still can
/// back away or turn in place. Sensed points are taken as still (people too;
/// walkers' predicted paths come as points, PeopleTracker.h).
///
/// Walkers in time: a robot interface that tracks people (WalkerSensor, below; sim::SimRobot
/// does) also gives each walker's points and velocity, and the guard then checks the robot's
/// stop against each walker's position at each instant of it (the walker going on at its
/// speed), not only against where the walker is and its path as still points. This is what
/// a fast robot needs: at 1.8 m/s and 1 m/s^2 its stop takes 1.9 s, in which a walker coming at
/// it covers 1.7 m, more than the predicted path MRPT is given (1 s) reaches. Where every
/// scale that keeps clear of the still points meets a walker, the one that meets it latest is
/// sent: stopping is not always best against someone who walks on (a walker catching up from
/// behind reaches a braking robot sooner).
#include <mrpt/kinematics/CVehicleVelCmd_DiffDriven.h>
#include <mrpt/math/TPoint2D.h>
#include <mrpt/nav/reactive/CRobot2NavInterface.h>

#include <cstddef>
#include <vector>

namespace devslam::nav {

/// The most a robot is taken to do, by the world files' [robot] and the navigator's INI alike:
/// top speed [m/s], acceleration [m/s^2], angular acceleration [deg/s^2].
inline constexpr double kMaxRobotSpeed = 5.0, kMaxRobotAcc = 20.0, kMaxRobotAngAccDeg = 3600.0;

/// [navigator] speed_guard, max_acc, max_ang_acc_deg, guard_margin.
struct SpeedGuardOptions {
    bool enabled = true;
    double max_acc = 1.0;          ///< [m/s^2] the robot's linear acceleration (and braking) limit
    double max_ang_acc = 3.14159;  ///< [rad/s^2] its angular one
    double margin = 0.02;          ///< [m] kept beyond the robot's radius on the predicted path
    bool walkers = true;  ///< [navigator] guard_walkers: the walkers' positions in time (above)
};

/// A walking person as the guard sees it: the points last sensed on them, moved along their
/// velocity to now, and that velocity, both in the robot's frame now (x forward) [m], [m/s].
struct MovingPoints {
    std::vector<mrpt::math::TPoint2D> points;
    mrpt::math::TPoint2D velocity{0, 0};
};

/// What a robot interface that tracks people can also give the guard (GuardedRobot finds it on
/// the robot it wraps by dynamic_cast).
class WalkerSensor {
  public:
    virtual ~WalkerSensor() = default;
    /// The people walking now; asked right after each senseObstacles().
    [[nodiscard]] virtual std::vector<MovingPoints> sensedWalkers() = 0;
};

/// The robot's motion for the guard: speeds now, the command, the period it is held.
struct GuardMotion {
    double v0 = 0, w0 = 0;  ///< [m/s], [rad/s] the robot's speeds now (its own frame)
    double vc = 0, wc = 0;  ///< the command
    double hold = 0.1;      ///< [s] until the next command (the navigation period)
};

/// The largest s of 1, 0.9, ..., 0.1, 0 for which holding (s vc, s wc) for `hold` and then
/// stopping keeps the robot (a circle of `radius` [m]) clear of every point of `obstacles`
/// (robot frame, x forward) as the header says; 0 when none is (stopping is then the least
/// bad). `checked` (optional) gets the number of candidate scales tried.
[[nodiscard]] double guardScale(const GuardMotion& m,
                                const std::vector<mrpt::math::TPoint2D>& obstacles, double radius,
                                const SpeedGuardOptions& o, int* checked = nullptr);

/// The same with `walkers` checked in time (the header): the largest scale that keeps clear of
/// the still points and of every walker's points as they move (each walker point kept the
/// distance a still point would be); of the scales clear of the still points only, the one
/// whose first contact with a walker comes latest (ties: the larger); 0 when none is clear of
/// the still points. Walkers are met only while the robot drives: one that reaches it after it
/// stands, or while it only turns, would reach it whatever it did. `o.walkers` false ignores
/// `walkers`. `still_only` (optional) gets the scale the still points alone allow.
[[nodiscard]] double guardScale(const GuardMotion& m,
                                const std::vector<mrpt::math::TPoint2D>& obstacles,
                                const std::vector<MovingPoints>& walkers, double radius,
                                const SpeedGuardOptions& o, int* checked = nullptr,
                                double* still_only = nullptr);

/// What the guard did over a run.
struct SpeedGuardStats {
    std::size_t commands = 0;  ///< (v, w) commands MRPT sent
    std::size_t slowed = 0;    ///< of them scaled below 1
    std::size_t stopped = 0;   ///< of them scaled to 0 (a moving command)
    std::size_t by_walkers = 0;  ///< of the slowed, those scaled otherwise than the still points
                                 ///< alone ask (the walkers in time)
};

/// The CRobot2NavInterface MRPT's navigator drives when the guard is on: forwards every call
/// to `robot`, keeps the speeds and points it reports, and scales differential-drive
/// commands by guardScale(). Other command classes pass as they are.
class GuardedRobot : public mrpt::nav::CRobot2NavInterface {
  public:
    GuardedRobot(mrpt::nav::CRobot2NavInterface& robot, double radius, double period,
                 SpeedGuardOptions o);

    bool getCurrentPoseAndSpeeds(mrpt::math::TPose2D& pose, mrpt::math::TTwist2D& vel_global,
                                 mrpt::system::TTimeStamp& timestamp, mrpt::math::TPose2D& odometry,
                                 std::string& frame_id) override;
    bool changeSpeeds(const mrpt::kinematics::CVehicleVelCmd& cmd) override;
    /// Sends the last command again through the guard (the robot has moved since).
    bool changeSpeedsNOP() override;
    bool stop(bool is_emergency_stop = true) override;
    mrpt::kinematics::CVehicleVelCmd::Ptr getEmergencyStopCmd() override;
    mrpt::kinematics::CVehicleVelCmd::Ptr getStopCmd() override;
    mrpt::kinematics::CVehicleVelCmd::Ptr getAlignCmd(
        const double relative_heading_radians) override;
    bool startWatchdog(float T_ms) override;
    bool stopWatchdog() override;
    bool senseObstacles(mrpt::maps::CSimplePointsMap& obstacles,
                        mrpt::system::TTimeStamp& timestamp) override;
    void sendNavigationStartEvent() override;
    void sendNavigationEndEvent() override;
    void sendWaypointReachedEvent(int waypoint_index, bool reached_nSkipped) override;
    void sendNewWaypointTargetEvent(int waypoint_index) override;
    void sendNavigationEndDueToErrorEvent() override;
    void sendWaySeemsBlockedEvent() override;
    void sendApparentCollisionEvent() override;
    void sendCannotGetCloserToBlockedTargetEvent() override;
    double getNavigationTime() override;
    void resetNavigationTimer() override;

    [[nodiscard]] const SpeedGuardStats& stats() const { return stats_; }

  private:
    mrpt::nav::CRobot2NavInterface& robot_;
    double radius_, period_;
    SpeedGuardOptions opts_;
    double v_ = 0, w_ = 0;  ///< the robot's speeds as last reported (its frame)
    std::vector<mrpt::math::TPoint2D> points_;
    WalkerSensor* walker_sensor_ = nullptr;  ///< robot_ as a WalkerSensor, if it is one
    std::vector<MovingPoints> walkers_;      ///< what it gave with the last points
    bool has_last_ = false;  ///< the last command MRPT sent was a differential-drive one
    mrpt::kinematics::CVehicleVelCmd_DiffDriven last_;  ///< that command, unscaled
    SpeedGuardStats stats_;
};

}  // namespace devslam::nav
