#pragma once
/// Headless Bullet simulation of a WorldSpec: a differential-drive robot (a dynamic
/// cylinder driven by (v, w) under acceleration limits), static obstacles, kinematic
/// pedestrians (scripted back-and-forth or seeded random walk) and a 2D laser by ray casts.
/// Fixed time step; deterministic for a given world (seed included). Bullet stays behind
/// a pimpl: this header includes no Bullet type.
///
/// Usage:
///   devslam::sim::Simulator sim(world);
///   sim.setCommand(0.4, 0.2);            // [m/s], [rad/s]
///   sim.step();                          // advances world.time_step
///   const auto& scan = sim.scan();       // latest scan (updated at laser.rate)
/// Not thread-safe.
#include <devslam/sim/World.h>

#include <memory>
#include <vector>

namespace devslam::sim {

/// Latest laser scan: ranges along angles (robot frame), max range where nothing was hit.
struct LaserScan {
    double t = -1;               ///< [s] sim time of the scan
    mrpt::math::TPose2D pose;    ///< the robot's pose then (the ranges are from it)
    std::vector<double> angles;  ///< [rad] robot frame, increasing (right to left)
    std::vector<double> ranges;  ///< [m]
    std::vector<uint8_t> hit;    ///< 1 if the ray hit something
    std::vector<uint8_t> person;  ///< 1 if what it hit is a pedestrian
};

struct CollisionCounts {
    int static_events = 0;        ///< rising edges of contact with walls/boxes
    int person_events = 0;        ///< rising edges of contact with pedestrians
    bool static_contact = false;  ///< touching a static obstacle now
    bool person_contact = false;  ///< touching a pedestrian now
};

class Simulator {
  public:
    explicit Simulator(const WorldSpec& world);
    ~Simulator();
    Simulator(const Simulator&) = delete;
    Simulator& operator=(const Simulator&) = delete;

    /// Commanded velocities; the actual ones follow under the acceleration limits. A command
    /// over the robot's max_v or max_w is scaled down, both by one factor, so that the arc
    /// keeps its curvature.
    void setCommand(double v, double w);
    /// One fixed physics step (world.time_step): people, robot, contacts, laser (at rate).
    void step();

    [[nodiscard]] double time() const;                    ///< [s]
    [[nodiscard]] mrpt::math::TPose2D robotPose() const;  ///< [m, m, rad]
    [[nodiscard]] double linearVelocity() const;          ///< [m/s] actual
    [[nodiscard]] double angularVelocity() const;         ///< [rad/s] actual
    [[nodiscard]] const LaserScan& scan() const;
    [[nodiscard]] const CollisionCounts& collisions() const;
    [[nodiscard]] std::vector<mrpt::math::TPoint2D> pedestrianPositions() const;
    [[nodiscard]] const WorldSpec& world() const;

  private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace devslam::sim
