#pragma once
/// Where the people around the robot are going: a tracker of the laser points known to lie on
/// people, and their predicted positions over the next second or so.
///
/// Why: the navigator (MRPT's PTGs, the holonomic methods, the speed guard) takes every sensed
/// point as still. A walker coming at the robot, or crossing in front of it, is then avoided
/// only where they are, not where they will be: the robot steers into their path and meets
/// them at whatever distance `person_margin` allows (docs/nav.md "People"). Adding each walker's
/// points along its predicted path for `horizon` seconds makes that path an obstacle too, so
/// the robot gives way early, as a person would, and keeps more room at no larger margin.
///
/// Each scan's person points (world frame, ray order) are cut into people where neighbours lie
/// more than `cluster_gap` apart. A person's centre is the mean of its points pushed away from
/// the sensor by pi/4 of its half width: rays at even spacing across a disc see its near half,
/// whose mean lies that far in front of the centre, so a still person does not seem to move as
/// the robot passes and sees another side. A person seen by one or two rays only (far off,
/// half hidden) has no width: it keeps its track alive but measures no centre. People are
/// matched to tracks greedily by distance to the track's predicted centre (within `gate`); the
/// velocity is the centre's displacement, low-passed with time constant
/// `velocity_time_constant`. A person at the seam of a 360-degree scan (behind the robot) is
/// one person. Nothing here is in MRPT (its
/// obstacle filters are static), and a Kalman filter per person adds nothing at this accuracy.
///
/// Usage:
///   devslam::nav::PeopleTracker tracker;
///   tracker.update(t, sensor_xy, person_points_world);     // once per new scan
///   auto ahead = tracker.predictedPoints(1.0);            // world frame
/// Not thread-safe.
#include <mrpt/math/TPoint2D.h>

#include <vector>

namespace devslam::nav {

struct PeopleTrackerOptions {
    double cluster_gap = 0.30;  ///< [m] neighbouring person points farther apart: two people
    double gate = 0.50;         ///< [m] farthest a person may be from a track's prediction
    double velocity_time_constant = 0.30;  ///< [s] low-pass of the velocity
    double forget_after = 0.50;            ///< [s] a track not seen this long is dropped
    int min_scans = 3;       ///< scans measuring its centre a track needs before it is predicted
    double max_speed = 3.0;  ///< [m/s] a faster apparent motion is a new person, not a walk
};

struct TrackedPerson {
    int id = 0;
    mrpt::math::TPoint2D centre;               ///< [m] world frame, at `centre_t`
    mrpt::math::TPoint2D velocity;             ///< [m/s] world frame
    std::vector<mrpt::math::TPoint2D> points;  ///< the latest scan's points on the person
    double t = 0;                              ///< [s] when last seen
    double centre_t = 0;                       ///< [s] when its centre was last measured
    int scans = 0;                             ///< scans it was seen in
    int centre_scans = 0;  ///< of them, those with 3 points or more, which measure the centre
};

class PeopleTracker {
  public:
    explicit PeopleTracker(PeopleTrackerOptions o = {});

    /// One scan taken at `t` [s] from `sensor` (world frame): the points its rays put on
    /// people, world frame, in ray order (points of one person adjacent). Scans come in time
    /// order; one at the time of the last is ignored.
    void update(double t, const mrpt::math::TPoint2D& sensor,
                const std::vector<mrpt::math::TPoint2D>& person_points);

    /// The tracks, seen within `forget_after` of the last scan.
    [[nodiscard]] const std::vector<TrackedPerson>& people() const { return people_; }

    /// The tracks predictedPoints() moves: seen in the last scan, with `min_scans` centres
    /// measured and at least `min_speed` [m/s].
    [[nodiscard]] std::vector<TrackedPerson> walkers(double min_speed = 0.15) const;

    /// Copies of each tracked person's latest points moved along its velocity, every
    /// `spacing` [m] of its path up to `horizon` [s] after the last scan (the points
    /// themselves not included); people slower than `min_speed` [m/s], with fewer than
    /// `min_scans` centres measured, or not in the last scan, add none.
    [[nodiscard]] std::vector<mrpt::math::TPoint2D> predictedPoints(double horizon,
                                                                    double spacing = 0.10,
                                                                    double min_speed = 0.15) const;

  private:
    PeopleTrackerOptions o_;
    std::vector<TrackedPerson> people_;
    double last_t_ = -1e300;
    int next_id_ = 1;
};

}  // namespace devslam::nav
