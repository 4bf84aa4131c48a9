// Google Benchmark: grid A* on a 400x400 grid and one VFH+ step (121 sectors).
// Run: build/benchmarks/bench_nav   (the nav bench app prints the same medians into RESULTS.md)
#include <devslam/nav/GridPlanner.h>
#include <devslam/nav/VfhPlus.h>

#include <benchmark/benchmark.h>

#include <random>

namespace {
mrpt::maps::COccupancyGridMap2D clutteredGrid400() {
    mrpt::maps::COccupancyGridMap2D grid;
    grid.setSize(0, 20, 0, 20, 0.05f, 1.0f);  // 400 x 400 cells
    std::mt19937 g(5);
    std::uniform_real_distribution<double> u(2.0, 18.0);
    for (int k = 0; k < 60; k++) {
        const double cx = u(g), cy = u(g);
        for (double y = cy - 0.5; y <= cy + 0.5; y += 0.05)
            for (double x = cx - 0.5; x <= cx + 0.5; x += 0.05) grid.setPos(x, y, 0.0f);
    }
    return grid;
}

void BM_AStar400(benchmark::State& state) {
    devslam::nav::GridPlanner planner;
    planner.setMap(clutteredGrid400());
    for (auto _ : state) {
        auto p = planner.plan({0.6, 0.6}, {19.4, 19.4});
        benchmark::DoNotOptimize(p);
    }
}
BENCHMARK(BM_AStar400)->Unit(benchmark::kMillisecond);

void BM_AStar400SetMap(benchmark::State& state) {
    devslam::nav::GridPlanner planner;
    const auto grid = clutteredGrid400();
    for (auto _ : state) planner.setMap(grid);  // distance transform
}
BENCHMARK(BM_AStar400SetMap)->Unit(benchmark::kMillisecond);

void BM_VfhPlusStep(benchmark::State& state) {
    std::mt19937 g(3);
    std::uniform_real_distribution<double> u(0.05, 1.0);
    devslam::nav::VfhInput in;
    in.obstacles.resize(121);
    for (auto& d : in.obstacles) d = u(g);
    in.target_x = 0.6;
    in.target_y = 0.2;
    in.ref_distance = 2.5;
    devslam::nav::VfhPlusOptions o;
    devslam::nav::VfhState st;
    for (auto _ : state) {
        auto out = devslam::nav::vfhPlusStep(in, st, o);
        benchmark::DoNotOptimize(out);
    }
}
BENCHMARK(BM_VfhPlusStep)->Unit(benchmark::kMicrosecond);
}  // namespace

BENCHMARK_MAIN();
