// The people tracker (PeopleTracker.h): laser points on discs that walk or stand, cast from a
// sensor the test moves, and the tracks, velocities and predicted points it makes of them.
#include <devslam/nav/PeopleTracker.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

using devslam::nav::PeopleTracker;
using devslam::nav::PeopleTrackerOptions;
using mrpt::math::TPoint2D;

namespace {

struct Disc {
    TPoint2D centre;
    double radius = 0.25;
};

/// The points a 1-degree laser at `sensor` puts on the discs, in ray order (nearest hit per
/// ray; rays that hit none give nothing).
std::vector<TPoint2D> scan(const TPoint2D& sensor, const std::vector<Disc>& discs) {
    std::vector<TPoint2D> pts;
    for (int k = 0; k < 360; k++) {
        const double a = (-180 + k) * M_PI / 180;
        const TPoint2D d(std::cos(a), std::sin(a));
        double best = 1e9;
        for (const auto& c : discs) {
            // |sensor + t d - centre| = r, the smaller positive t
            const TPoint2D m = sensor - c.centre;
            const double b = m.x * d.x + m.y * d.y;
            const double disc = b * b - (m.x * m.x + m.y * m.y - c.radius * c.radius);
            if (disc < 0) continue;
            const double t = -b - std::sqrt(disc);
            if (t > 0) best = std::min(best, t);
        }
        if (best < 1e9) pts.push_back(sensor + d * best);
    }
    return pts;
}

}  // namespace

// A walker at 0.8 m/s across the view, seen at 10 Hz: its velocity and centre come out.
TEST(PeopleTracker, AWalkersVelocityAndCentreAreFound) {
    PeopleTracker tracker;
    const TPoint2D sensor(0, 0), v(0.8, 0.3);
    TPoint2D c(-1.5, 2.0);
    for (int i = 0; i <= 20; i++) {
        const double t = 0.1 * i;
        tracker.update(t, sensor, scan(sensor, {{c + v * t}}));
    }
    ASSERT_EQ(tracker.people().size(), 1u);
    const auto& p = tracker.people()[0];
    EXPECT_EQ(p.scans, 21);
    EXPECT_NEAR(p.velocity.x, v.x, 0.05);
    EXPECT_NEAR(p.velocity.y, v.y, 0.05);
    const TPoint2D truth = c + v * 2.0;
    const auto pts = scan(sensor, {{truth}});
    TPoint2D mean(0, 0);
    for (const auto& q : pts) mean += q;
    mean *= 1.0 / static_cast<double>(pts.size());
    EXPECT_GT((mean - truth).norm(), 0.15) << "[m] the near side's mean";
    EXPECT_LT((p.centre - truth).norm(), 0.04) << "[m] the centre";
}

// A robot driving past a person who stands still sees the person's other sides in turn. The
// mean of the points swings with them (about 0.16 m/s here); the centre, pushed back from the
// sensor, stays put.
TEST(PeopleTracker, AStillPersonSeemsStillFromAPassingRobot) {
    const Disc person{{0, 0.8}, 0.25};
    const auto run = [&](double* worst_speed, double* worst_mean_speed) {
        PeopleTracker tracker;
        TPoint2D last_mean(0, 0);
        for (int i = 0; i <= 40; i++) {  // 4 s at 0.6 m/s from x = -1.2 to 1.2
            const double t = 0.1 * i;
            const TPoint2D sensor(-1.2 + 0.6 * t, 0);
            const auto pts = scan(sensor, {person});
            ASSERT_FALSE(pts.empty());
            tracker.update(t, sensor, pts);
            ASSERT_EQ(tracker.people().size(), 1u) << "t = " << t;
            TPoint2D mean(0, 0);
            for (const auto& p : pts) mean += p;
            mean *= 1.0 / static_cast<double>(pts.size());
            if (i > 0)
                *worst_mean_speed = std::max(*worst_mean_speed, (mean - last_mean).norm() / 0.1);
            last_mean = mean;
            if (tracker.people()[0].scans >= 3)
                *worst_speed = std::max(*worst_speed, tracker.people()[0].velocity.norm());
        }
        EXPECT_TRUE(tracker.predictedPoints(1.0).empty());
    };
    double worst = 0, worst_mean = 0;
    run(&worst, &worst_mean);
    EXPECT_GT(worst_mean, 0.15) << "[m/s] what the plain mean of the points would give";
    // (below predictedPoints' min_speed, 0.15 m/s, with room to spare)
    EXPECT_LT(worst, 0.08) << "[m/s] the tracker's speed of a person who stands";
}

// Two walkers, a metre apart, passing each other: each keeps its track and its own velocity.
TEST(PeopleTracker, TwoWalkersPassingKeepTheirTracks) {
    PeopleTracker tracker;
    const TPoint2D sensor(0, 0);
    std::vector<int> ids;
    for (int i = 0; i <= 30; i++) {
        const double t = 0.1 * i;
        const Disc a{{-1.5 + 1.0 * t, 2.5}, 0.25}, b{{1.5 - 1.0 * t, 3.5}, 0.25};
        tracker.update(t, sensor, scan(sensor, {a, b}));
        if (i == 3) {
            ASSERT_EQ(tracker.people().size(), 2u);
            for (const auto& p : tracker.people()) ids.push_back(p.id);
        }
    }
    // a is nearer and hides b for a few scans as they pass: b's track outlives that
    // (forget_after), so both tracks are the ones of the start
    ASSERT_EQ(tracker.people().size(), 2u);
    for (const auto& p : tracker.people()) {
        EXPECT_NE(std::find(ids.begin(), ids.end(), p.id), ids.end()) << "a new track " << p.id;
        const bool is_a = p.centre.y < 3.0;
        EXPECT_NEAR(p.velocity.x, is_a ? 1.0 : -1.0, 0.1) << "track " << p.id;
        EXPECT_NEAR(p.velocity.y, 0.0, 0.1) << "track " << p.id;
    }
}

// Two people side by side in one run of rays, one a metre behind the other: two tracks.
TEST(PeopleTracker, PeopleFartherApartThanTheGapAreTwo) {
    PeopleTracker tracker;
    const TPoint2D sensor(0, 0);
    // Discs that touch in the view: the rays go from the near one's edge to the far one.
    const auto pts = scan(sensor, {{{2.0, 0.0}, 0.25}, {{3.0, 0.5}, 0.25}});
    tracker.update(0, sensor, pts);
    EXPECT_EQ(tracker.people().size(), 2u);
    PeopleTrackerOptions wide;
    wide.cluster_gap = 1.0;
    PeopleTracker merged(wide);
    merged.update(0, sensor, pts);
    EXPECT_EQ(merged.people().size(), 1u) << "the gap is what splits them";
}

// The predicted points: the person's points moved along its velocity, every `spacing` of the
// way to `horizon`; none before min_scans scans, and none for a person gone from view.
TEST(PeopleTracker, PredictedPointsLieAlongTheWalkersPath) {
    PeopleTracker tracker;
    const TPoint2D sensor(0, 0), v(0, -1.0);  // coming at the sensor
    const TPoint2D c0(0, 4);
    std::vector<TPoint2D> last;
    for (int i = 0; i <= 10; i++) {
        const double t = 0.1 * i;
        last = scan(sensor, {{c0 + v * t}});
        tracker.update(t, sensor, last);
        if (i < 2) {
            EXPECT_TRUE(tracker.predictedPoints(1.0).empty()) << "scan " << i;
        }
    }
    const auto& p = tracker.people().at(0);
    ASSERT_NEAR(p.velocity.y, -1.0, 0.05);
    const auto ahead = tracker.predictedPoints(1.0, 0.1);
    // about 1 m/s for 1 s, every 0.1 m or less: 10 or 11 copies of the scan's points
    const int n = static_cast<int>(std::ceil(p.velocity.norm() * 1.0 / 0.1));
    ASSERT_GE(n, 10);
    ASSERT_LE(n, 11);
    ASSERT_EQ(ahead.size(), n * last.size());
    for (int k = 1; k <= n; k++)
        for (size_t j = 0; j < last.size(); j++) {
            const TPoint2D want = last[j] + p.velocity * (1.0 * k / n);
            EXPECT_LT((ahead[(k - 1) * last.size() + j] - want).norm(), 1e-9);
        }
    // the farthest copy lies a metre nearer the sensor than the walker's near side
    double nearest = 1e9;
    for (const auto& q : ahead) nearest = std::min(nearest, q.norm());
    EXPECT_NEAR(nearest, 3.0 - 0.25 - 1.0, 0.06);
    EXPECT_TRUE(tracker.predictedPoints(0.0).empty());
    // out of view: not predicted, and forgotten after forget_after
    tracker.update(1.1, sensor, {});
    EXPECT_EQ(tracker.people().size(), 1u);
    EXPECT_TRUE(tracker.predictedPoints(1.0).empty());
    tracker.update(1.7, sensor, {});
    EXPECT_TRUE(tracker.people().empty());
}

// A cluster that jumps farther than max_speed allows in one scan is a new person, and a scan
// at the time of the last one is ignored.
TEST(PeopleTracker, AJumpIsANewPersonAndARepeatedScanIsIgnored) {
    PeopleTrackerOptions o;
    o.gate = 2.0;  // so only max_speed tells them apart
    PeopleTracker tracker(o);
    const TPoint2D sensor(0, 0);
    tracker.update(0.0, sensor, scan(sensor, {{{2, 0}, 0.25}}));
    tracker.update(0.0, sensor, scan(sensor, {{{2, 1}, 0.25}}));
    ASSERT_EQ(tracker.people().size(), 1u);
    EXPECT_EQ(tracker.people()[0].scans, 1);
    tracker.update(0.1, sensor, scan(sensor, {{{2, 0.5}, 0.25}}));  // 5 m/s
    ASSERT_EQ(tracker.people().size(), 2u);
    EXPECT_NE(tracker.people()[0].id, tracker.people()[1].id);
    for (const auto& p : tracker.people()) EXPECT_EQ(p.scans, 1);
}

// A 360-degree scan starts and ends behind the sensor: a person there is one person, not the
// scan's first cluster and its last.
TEST(PeopleTracker, APersonAtTheScansSeamIsOne) {
    PeopleTracker tracker;
    const TPoint2D sensor(0, 0);
    const auto pts = scan(sensor, {{{-2, 0}, 0.25}});
    ASSERT_GT(pts.size(), 4u);
    ASSERT_LT(pts.front().y, 0);  // the scan's first rays, at -180 deg and on
    ASSERT_GT(pts.back().y, 0);   // its last, up to +179 deg
    tracker.update(0, sensor, pts);
    ASSERT_EQ(tracker.people().size(), 1u);
    EXPECT_LT((tracker.people()[0].centre - TPoint2D(-2, 0)).norm(), 0.04);
    EXPECT_EQ(tracker.people()[0].points.size(), pts.size());
}

// Seen by one or two rays only, a person has no width, and the mean of those points lies up to
// 0.2 m in front of the centre: a still person seen so every other scan seemed to walk at 2 m/s.
// Such scans keep the track alive but measure no centre, and none starts the velocity.
TEST(PeopleTracker, OneOrTwoRaysMeasureNoCentre) {
    PeopleTracker tracker;
    const TPoint2D sensor(0, 0);
    const auto full = scan(sensor, {{{6, 0}, 0.25}});
    ASSERT_GE(full.size(), 3u);
    const std::vector<TPoint2D> one{full[full.size() / 2]}, two{full[0], full[1]};
    const std::vector<std::vector<TPoint2D>> seen{one, full, two, full, one, full, full};
    for (size_t i = 0; i < seen.size(); i++) tracker.update(0.1 * i, sensor, seen[i]);
    ASSERT_EQ(tracker.people().size(), 1u);
    const auto& p = tracker.people()[0];
    EXPECT_EQ(p.scans, 7);
    EXPECT_EQ(p.centre_scans, 4);
    EXPECT_LT(p.velocity.norm(), 0.05) << "[m/s] a person who stands";
    EXPECT_TRUE(tracker.predictedPoints(1.0).empty());
}
