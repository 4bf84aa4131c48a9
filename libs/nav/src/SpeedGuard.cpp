#include <devslam/nav/SpeedGuard.h>

#include <mrpt/kinematics/CVehicleVelCmd_DiffDriven.h>
#include <mrpt/maps/CSimplePointsMap.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace devslam::nav {

namespace {
constexpr double kStep = 0.02;         ///< [s] integration step of the predicted motion
constexpr double kSensorSlack = 0.01;  ///< [m] the laser's noise, given up inside the margin
constexpr double kContactGap = 0.005;  ///< [m] never planned nearer to a point than this
constexpr double kStopped = 1e-3;      ///< [m/s], [rad/s] a speed taken as stopped
constexpr double kMaxHorizon = 30.0;   ///< [s] bound on the stopping time looked at

/// One step of each axis toward its command, by at most its acceleration limit (as
/// sim::Simulator drives the robot).
double ramp(double now, double cmd, double acc, double dt) {
    return now + std::clamp(cmd - now, -acc * dt, acc * dt);
}

constexpr double kNever = std::numeric_limits<double>::infinity();

/// A walker's points, each with the least distance it may have from the robot's centre.
struct Walker {
    std::vector<mrpt::math::TPoint2D> pts;
    std::vector<double> need;
    mrpt::math::TPoint2D vel{0, 0};
};

/// When holding (vc, wc) for `hold` s, then stopping, first brings the robot's centre nearer to
/// a still point than its need[i] (`still`) and, while it drives, to a walker's point, the
/// walker going on at its velocity, than its need (`walker`); kNever where it does not. The
/// walkers are looked at only where the still points leave the motion clear.
struct Contact {
    double still = kNever, walker = kNever;
};
Contact firstContact(double v, double w, double vc, double wc, double hold,
                     const std::vector<mrpt::math::TPoint2D>& pts, const std::vector<double>& need,
                     const std::vector<Walker>& walkers, const SpeedGuardOptions& o) {
    double x = 0, y = 0, th = 0, t = 0;
    Contact c;
    while (t < kMaxHorizon) {
        const bool holding = t < hold;
        const double tv = holding ? vc : 0.0, tw = holding ? wc : 0.0;
        if (!holding && std::abs(v) < kStopped && std::abs(w) < kStopped) break;
        // midpoint speeds over the step
        const double v1 = ramp(v, tv, o.max_acc, kStep), w1 = ramp(w, tw, o.max_ang_acc, kStep);
        const double vm = 0.5 * (v + v1), wm = 0.5 * (w + w1);
        const double thm = th + 0.5 * wm * kStep;
        x += vm * std::cos(thm) * kStep;
        y += vm * std::sin(thm) * kStep;
        th += wm * kStep;
        v = v1;
        w = w1;
        t += kStep;
        for (std::size_t i = 0; i < pts.size(); ++i)
            if (std::hypot(pts[i].x - x, pts[i].y - y) < need[i]) {
                c.still = t;
                return c;
            }
        // (still points may yet be met; a robot that only turns does not move its disc, and
        // walkers that meet it then would meet it whatever it did)
        if (c.walker < kNever || std::abs(vm) < kStopped) continue;
        for (const auto& wk : walkers) {
            const double ox = wk.vel.x * t, oy = wk.vel.y * t;
            for (std::size_t i = 0; i < wk.pts.size() && c.walker == kNever; ++i)
                if (std::hypot(wk.pts[i].x + ox - x, wk.pts[i].y + oy - y) < wk.need[i])
                    c.walker = t;
        }
    }
    return c;
}
}  // namespace

double guardScale(const GuardMotion& m, const std::vector<mrpt::math::TPoint2D>& obstacles,
                  double radius, const SpeedGuardOptions& o, int* checked) {
    return guardScale(m, obstacles, {}, radius, o, checked);
}

double guardScale(const GuardMotion& m, const std::vector<mrpt::math::TPoint2D>& obstacles,
                  const std::vector<MovingPoints>& walkers, double radius,
                  const SpeedGuardOptions& o, int* checked, double* still_only) {
    if (checked) *checked = 0;
    if (still_only) *still_only = 1.0;
    // Only points the robot could reach: the farthest it can go is at its top speed over
    // the hold and the stop after it.
    const double vmax = std::max(std::abs(m.v0), std::abs(m.vc));
    const double reach =
        vmax * m.hold + 0.5 * o.max_acc * m.hold * m.hold +
        (vmax + o.max_acc * m.hold) * (vmax + o.max_acc * m.hold) / (2 * o.max_acc) + radius +
        std::max(o.margin, kContactGap) + kStep * (vmax + o.max_acc * m.hold);
    // ... and walkers' points that can meet it before it stands: its longest motion, the hold
    // and the slower axis's stop after it (and a step).
    const double wmax = std::max(std::abs(m.w0), std::abs(m.wc));
    const double longest = m.hold +
                           std::max((vmax + o.max_acc * m.hold) / o.max_acc,
                                    (wmax + o.max_ang_acc * m.hold) / o.max_ang_acc) +
                           kStep;
    std::vector<mrpt::math::TPoint2D> pts;
    std::vector<double> need;  // each point's distance now, then the least it may have
    double nearest = 1e300, nearest_walker = 1e300;
    for (const auto& p : obstacles) {
        const double d = std::hypot(p.x, p.y);
        if (!(d <= reach)) continue;  // (NaN points too)
        pts.push_back(p);
        need.push_back(d);
        nearest = std::min(nearest, d);
    }
    std::vector<Walker> near_walkers;
    if (o.walkers)
        for (const auto& wk : walkers) {
            const double travel = wk.velocity.norm() * longest;
            if (!std::isfinite(travel)) continue;
            Walker n;
            n.vel = wk.velocity;
            for (const auto& p : wk.points) {
                const double d = std::hypot(p.x, p.y);
                if (!(d <= reach + travel)) continue;
                n.pts.push_back(p);
                n.need.push_back(d);
                nearest_walker = std::min(nearest_walker, d);
            }
            if (!n.pts.empty()) near_walkers.push_back(std::move(n));
        }
    if (pts.empty() && near_walkers.empty()) return 1.0;
    // Radius and margin. Where the robot is inside that already (a wall brushed, a person
    // come close), the margin less the laser's noise, so that it can drive along a wall it
    // brushes (every point of the wall ahead is nearer than now) - a fixed bound, not one
    // taken from the clearance now: that one sank by the noise at every step, and a robot
    // driving at a wall crept to 6-10 mm of it. And no point nearer than it is now, so that
    // a robot pushed closer still can turn in place or back away.
    // (the walkers' points on their own: they never loosen the bound of the still ones)
    const auto base = [&](double closest) {
        return closest >= radius + o.margin
                   ? radius + o.margin
                   : radius + std::max(o.margin - kSensorSlack, kContactGap);
    };
    for (double& n : need) n = std::min(base(nearest), n - 1e-6);
    for (auto& wk : near_walkers)
        for (double& n : wk.need) n = std::min(base(nearest_walker), n - 1e-6);
    double best = 0.0, latest = -1.0;  // of the scales clear of the still points
    bool clear_seen = false;
    if (still_only) *still_only = 0.0;
    for (int k = 10; k >= 0; --k) {
        const double s = 0.1 * k;
        if (checked) ++*checked;
        const Contact c =
            firstContact(m.v0, m.w0, s * m.vc, s * m.wc, m.hold, pts, need, near_walkers, o);
        if (c.still < kNever) continue;
        if (!clear_seen && still_only) *still_only = s;  // (the largest: the first)
        clear_seen = true;
        if (c.walker == kNever) return s;
        if (c.walker > latest) {
            latest = c.walker;
            best = s;
        }
    }
    return best;
}

GuardedRobot::GuardedRobot(mrpt::nav::CRobot2NavInterface& robot, double radius, double period,
                           SpeedGuardOptions o)
    : robot_(robot),
      radius_(radius),
      period_(period),
      opts_(o),
      walker_sensor_(dynamic_cast<WalkerSensor*>(&robot)) {
    setMinLoggingLevel(mrpt::system::LVL_WARN);
}

bool GuardedRobot::getCurrentPoseAndSpeeds(mrpt::math::TPose2D& pose,
                                           mrpt::math::TTwist2D& vel_global,
                                           mrpt::system::TTimeStamp& timestamp,
                                           mrpt::math::TPose2D& odometry, std::string& frame_id) {
    const bool ok = robot_.getCurrentPoseAndSpeeds(pose, vel_global, timestamp, odometry, frame_id);
    if (ok) {
        // the global twist in the robot's frame: forward speed and turn rate
        v_ = vel_global.vx * std::cos(pose.phi) + vel_global.vy * std::sin(pose.phi);
        w_ = vel_global.omega;
    }
    return ok;
}

bool GuardedRobot::changeSpeeds(const mrpt::kinematics::CVehicleVelCmd& cmd) {
    const auto* dd = dynamic_cast<const mrpt::kinematics::CVehicleVelCmd_DiffDriven*>(&cmd);
    has_last_ = dd != nullptr;
    if (dd) last_ = *dd;
    if (!opts_.enabled || !dd) return robot_.changeSpeeds(cmd);
    stats_.commands++;
    // A stop is sent as it is: nothing slower exists.
    if (dd->lin_vel == 0 && dd->ang_vel == 0) return robot_.changeSpeeds(cmd);
    GuardMotion m;
    m.v0 = v_;
    m.w0 = w_;
    m.vc = dd->lin_vel;
    m.wc = dd->ang_vel;
    m.hold = period_;
    double still_only = 1.0;
    const double s = guardScale(m, points_, walkers_, radius_, opts_, nullptr, &still_only);
    if (s >= 1.0) return robot_.changeSpeeds(cmd);
    stats_.slowed++;
    if (s <= 0) stats_.stopped++;
    if (s < still_only) stats_.by_walkers++;
    mrpt::kinematics::CVehicleVelCmd_DiffDriven scaled;
    scaled.lin_vel = s * dd->lin_vel;
    scaled.ang_vel = s * dd->ang_vel;
    return robot_.changeSpeeds(scaled);
}

// MRPT sends a NOP only through PTGs that support it (its holonomic blend PTG); its
// diff-drive ones never do. Sent again, the command counts again.
bool GuardedRobot::changeSpeedsNOP() {
    if (!opts_.enabled || !has_last_) return robot_.changeSpeedsNOP();
    const auto cmd = last_;  // (changeSpeeds sets last_)
    return changeSpeeds(cmd);
}

bool GuardedRobot::stop(bool is_emergency_stop) {
    has_last_ = false;  // (a NOP after a stop keeps the robot stopped)
    return robot_.stop(is_emergency_stop);
}
mrpt::kinematics::CVehicleVelCmd::Ptr GuardedRobot::getEmergencyStopCmd() {
    return robot_.getEmergencyStopCmd();
}
mrpt::kinematics::CVehicleVelCmd::Ptr GuardedRobot::getStopCmd() {
    return robot_.getStopCmd();
}
mrpt::kinematics::CVehicleVelCmd::Ptr GuardedRobot::getAlignCmd(double relative_heading_radians) {
    return robot_.getAlignCmd(relative_heading_radians);
}
bool GuardedRobot::startWatchdog(float T_ms) {
    return robot_.startWatchdog(T_ms);
}
bool GuardedRobot::stopWatchdog() {
    return robot_.stopWatchdog();
}

bool GuardedRobot::senseObstacles(mrpt::maps::CSimplePointsMap& obstacles,
                                  mrpt::system::TTimeStamp& timestamp) {
    const bool ok = robot_.senseObstacles(obstacles, timestamp);
    points_.clear();
    if (ok) {
        const auto& xs = obstacles.getPointsBufferRef_x();
        const auto& ys = obstacles.getPointsBufferRef_y();
        for (std::size_t i = 0; i < xs.size(); ++i) points_.emplace_back(xs[i], ys[i]);
    }
    walkers_.clear();
    if (ok && walker_sensor_ && opts_.enabled && opts_.walkers)
        walkers_ = walker_sensor_->sensedWalkers();
    return ok;
}

void GuardedRobot::sendNavigationStartEvent() {
    robot_.sendNavigationStartEvent();
}
void GuardedRobot::sendNavigationEndEvent() {
    robot_.sendNavigationEndEvent();
}
void GuardedRobot::sendWaypointReachedEvent(int waypoint_index, bool reached_nSkipped) {
    robot_.sendWaypointReachedEvent(waypoint_index, reached_nSkipped);
}
void GuardedRobot::sendNewWaypointTargetEvent(int waypoint_index) {
    robot_.sendNewWaypointTargetEvent(waypoint_index);
}
void GuardedRobot::sendNavigationEndDueToErrorEvent() {
    robot_.sendNavigationEndDueToErrorEvent();
}
void GuardedRobot::sendWaySeemsBlockedEvent() {
    robot_.sendWaySeemsBlockedEvent();
}
void GuardedRobot::sendApparentCollisionEvent() {
    robot_.sendApparentCollisionEvent();
}
void GuardedRobot::sendCannotGetCloserToBlockedTargetEvent() {
    robot_.sendCannotGetCloserToBlockedTargetEvent();
}
double GuardedRobot::getNavigationTime() {
    return robot_.getNavigationTime();
}
void GuardedRobot::resetNavigationTimer() {
    robot_.resetNavigationTimer();
}

}  // namespace devslam::nav
