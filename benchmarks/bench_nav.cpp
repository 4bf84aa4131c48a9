// Google Benchmark: grid A* on a 400x400 grid and one VFH+ step (121 sectors).
// Run: build/benchmarks/bench_nav   (the nav bench app prints the same medians into RESULTS.md)
#include <devslam/nav/BenchFixtures.h>
#include <devslam/nav/GridPlanner.h>
#include <devslam/nav/VfhPlus.h>

#include <benchmark/benchmark.h>

#include <random>

namespace {
using devslam::nav::clutteredGrid400;

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
    const devslam::nav::VfhInput in = devslam::nav::randomVfhInput(g);
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
