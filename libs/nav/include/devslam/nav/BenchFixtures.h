#pragma once
/// The fixed inputs the navigation timings use, shared by `devslam-nav-bench` (the medians
/// in docs/RESULTS.md) and the Google Benchmark `benchmarks/bench_nav`, so both time the
/// same work.
///
///   auto grid = devslam::nav::clutteredGrid400();   // plan (0.6, 0.6) -> (19.4, 19.4)
///   std::mt19937 g(3);
///   auto in = devslam::nav::randomVfhInput(g);
#include <devslam/nav/VfhPlus.h>

#include <mrpt/maps/COccupancyGridMap2D.h>

#include <random>

namespace devslam::nav {

/// 20 m x 20 m at 5 cm (400 x 400 cells), free, with 60 seeded 1 m boxes in [2, 18] m.
[[nodiscard]] mrpt::maps::COccupancyGridMap2D clutteredGrid400();

/// A 121-sector VFH+ input: obstacle distances uniform in [0.05, 1], target (0.6, 0.2),
/// reference distance 2.5 m.
[[nodiscard]] VfhInput randomVfhInput(std::mt19937& g);

}  // namespace devslam::nav
