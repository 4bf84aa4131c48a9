#include <devslam/nav/PeopleTracker.h>

#include <algorithm>
#include <cmath>
#include <tuple>

namespace devslam::nav {

namespace {

/// Points a cluster needs for its centre to be measured (see update()).
constexpr std::size_t kMinPointsForCentre = 3;

struct Cluster {
    mrpt::math::TPoint2D centre;
    std::vector<mrpt::math::TPoint2D> points;
};

/// The person's centre behind the mean of its visible points (see the header).
mrpt::math::TPoint2D centreOf(const std::vector<mrpt::math::TPoint2D>& pts,
                              const mrpt::math::TPoint2D& sensor) {
    mrpt::math::TPoint2D mean(0, 0);
    for (const auto& p : pts) mean += p;
    mean *= 1.0 / static_cast<double>(pts.size());
    const double half_width = 0.5 * (pts.back() - pts.front()).norm();
    const mrpt::math::TPoint2D away = mean - sensor;
    const double d = away.norm();
    if (d < 1e-9) return mean;
    return mean + away * (M_PI / 4 * half_width / d);
}

}  // namespace

PeopleTracker::PeopleTracker(PeopleTrackerOptions o) : o_(o) {}

void PeopleTracker::update(double t, const mrpt::math::TPoint2D& sensor,
                           const std::vector<mrpt::math::TPoint2D>& person_points) {
    if (t <= last_t_) return;
    last_t_ = t;

    std::vector<Cluster> clusters;
    for (size_t i = 0; i < person_points.size(); i++) {
        if (i == 0 || (person_points[i] - person_points[i - 1]).norm() > o_.cluster_gap)
            clusters.emplace_back();
        clusters.back().points.push_back(person_points[i]);
    }
    // A 360-degree scan starts and ends behind the robot: a person there is the last cluster
    // and the first, and was two people with half a width each.
    if (clusters.size() >= 2 &&
        (person_points.back() - person_points.front()).norm() <= o_.cluster_gap) {
        auto& last = clusters.back().points;
        last.insert(last.end(), clusters.front().points.begin(), clusters.front().points.end());
        clusters.front().points = std::move(last);
        clusters.pop_back();
    }
    for (auto& c : clusters) c.centre = centreOf(c.points, sensor);

    // Greedy matching, nearest pair first: with a handful of people in view an optimal
    // assignment changes nothing.
    std::vector<std::tuple<double, size_t, size_t>> pairs;  // distance, track, cluster
    for (size_t k = 0; k < people_.size(); k++) {
        const auto& p = people_[k];
        const mrpt::math::TPoint2D predicted = p.centre + p.velocity * (t - p.centre_t);
        for (size_t c = 0; c < clusters.size(); c++) {
            const double d = (clusters[c].centre - predicted).norm();
            if (d <= o_.gate) pairs.emplace_back(d, k, c);
        }
    }
    std::sort(pairs.begin(), pairs.end());
    std::vector<bool> track_used(people_.size(), false), cluster_used(clusters.size(), false);
    for (const auto& [d, k, c] : pairs) {
        if (track_used[k] || cluster_used[c]) continue;
        auto& p = people_[k];
        const double dt = t - p.centre_t;  // > 0: every track's centre is from an earlier scan
        const mrpt::math::TPoint2D raw = (clusters[c].centre - p.centre) * (1.0 / dt);
        if (raw.norm() > o_.max_speed) continue;  // a jump, not a walk
        track_used[k] = cluster_used[c] = true;
        p.points = std::move(clusters[c].points);
        p.t = t;
        p.scans++;
        // One or two rays (a person far off or half hidden) give no width: their centre lies
        // up to pi/4 of a radius off, which is a walk of 1.7 m/s in one scan. The person is
        // seen, but the centre and velocity wait for a better view.
        if (p.points.size() < kMinPointsForCentre) continue;
        // The first displacement between measured centres sets the velocity; later ones are
        // low-passed.
        if (p.centre_scans > 0) {
            const double a = p.centre_scans == 1 ? 1.0 : dt / (o_.velocity_time_constant + dt);
            p.velocity = p.velocity + (raw - p.velocity) * a;
        }
        p.centre = clusters[c].centre;
        p.centre_t = t;
        p.centre_scans++;
    }
    people_.erase(std::remove_if(people_.begin(), people_.end(),
                                 [&](const TrackedPerson& p) { return t - p.t > o_.forget_after; }),
                  people_.end());
    for (size_t c = 0; c < clusters.size(); c++) {
        if (cluster_used[c]) continue;
        TrackedPerson p;
        p.id = next_id_++;
        p.centre = clusters[c].centre;
        p.points = std::move(clusters[c].points);
        p.t = p.centre_t = t;
        p.scans = 1;
        // (a centre from one or two rays is kept for matching only)
        p.centre_scans = p.points.size() >= kMinPointsForCentre ? 1 : 0;
        people_.push_back(std::move(p));
    }
}

std::vector<TrackedPerson> PeopleTracker::walkers(double min_speed) const {
    std::vector<TrackedPerson> out;
    for (const auto& p : people_)
        if (p.centre_scans >= o_.min_scans && p.velocity.norm() >= min_speed && p.t == last_t_)
            out.push_back(p);
    return out;
}

std::vector<mrpt::math::TPoint2D> PeopleTracker::predictedPoints(double horizon, double spacing,
                                                                 double min_speed) const {
    std::vector<mrpt::math::TPoint2D> out;
    if (horizon <= 0 || spacing <= 0) return out;
    for (const auto& p : walkers(min_speed)) {
        const double speed = p.velocity.norm();
        const int n = std::max(1, static_cast<int>(std::ceil(speed * horizon / spacing)));
        for (int k = 1; k <= n; k++) {
            const mrpt::math::TPoint2D shift = p.velocity * (horizon * k / n);
            for (const auto& q : p.points) out.push_back(q + shift);
        }
    }
    return out;
}

}  // namespace devslam::nav
