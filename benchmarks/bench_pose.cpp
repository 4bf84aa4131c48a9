// Google Benchmark: verifying a candidate pose from N 2D-3D correspondences. A lost frame's
// candidate keyframe of another place gives about 30 matches that no pose explains: the
// PnP-RANSAC the tracker would run on them (300 iterations, 25 inliers needed) fails after
// all its iterations; slam::inlierBound says so without a pose. Correspondences of a true
// place (all explained by one pose): the bound's cost where it cannot skip the RANSAC, and
// the tracker's question, inlierBoundReaches, answered by a greedy clique.
// Run: build/benchmarks/bench_pose   (timings only; the bound is tested in test_slam)
#include <devslam/core/Camera.h>
#include <devslam/slam/PoseSolver.h>

#include <benchmark/benchmark.h>

#include <random>

namespace {
using namespace devslam;
using namespace devslam::slam;

core::CameraIntrinsics camera() {
    auto K = core::CameraIntrinsics::fromPreset("freiburg1");
    K.dist = {0, 0, 0, 0, 0};
    return K;
}

/// n correspondences: world points in a 5 x 5 x 2.5 m room, keypoints anywhere in the image
/// with depth 0.8-3.8 m; `explained`: the keypoints are the world points' images instead.
std::vector<PoseObservation> correspondences(int n, bool explained) {
    const auto K = camera();
    std::mt19937 rng(static_cast<unsigned>(n));
    std::uniform_real_distribution<double> U(0.0, 1.0);
    std::vector<PoseObservation> obs;
    for (int i = 0; i < n; ++i) {
        PoseObservation o;
        o.uv = {U(rng) * K.width, U(rng) * K.height};
        o.depth = 0.8 + U(rng) * 3.0;
        o.p_w = explained ? core::backproject(o.uv.x(), o.uv.y(), o.depth, K)
                          : Eigen::Vector3d(U(rng) * 5, U(rng) * 5, U(rng) * 2.5);
        obs.push_back(o);
    }
    return obs;
}

void BM_PnpRansacUnexplained(benchmark::State& state) {
    const auto obs = correspondences(static_cast<int>(state.range(0)), false);
    const auto K = camera();
    const PnpRansacOptions o{300, 4.0, 0.99, 25};
    for (auto _ : state) benchmark::DoNotOptimize(solvePnpRansac(obs, K, o));
}
BENCHMARK(BM_PnpRansacUnexplained)->Arg(30)->Arg(60)->Unit(benchmark::kMillisecond);

void BM_InlierBoundUnexplained(benchmark::State& state) {
    const auto obs = correspondences(static_cast<int>(state.range(0)), false);
    const auto K = camera();
    for (auto _ : state) benchmark::DoNotOptimize(inlierBound(obs, K, {}));
    state.counters["bound"] = inlierBound(obs, K, {});
}
BENCHMARK(BM_InlierBoundUnexplained)->Arg(30)->Arg(60)->Unit(benchmark::kMillisecond);

void BM_InlierBoundExplained(benchmark::State& state) {
    const auto obs = correspondences(static_cast<int>(state.range(0)), true);
    const auto K = camera();
    for (auto _ : state) benchmark::DoNotOptimize(inlierBound(obs, K, {}));
}
BENCHMARK(BM_InlierBoundExplained)->Arg(300)->Arg(600)->Unit(benchmark::kMillisecond);

// What the tracker asks (inlierBoundReaches with 25): a greedy clique answers yes at once.
void BM_InlierBoundReachesExplained(benchmark::State& state) {
    const auto obs = correspondences(static_cast<int>(state.range(0)), true);
    const auto K = camera();
    for (auto _ : state) benchmark::DoNotOptimize(inlierBoundReaches(obs, 25, K, {}));
}
BENCHMARK(BM_InlierBoundReachesExplained)->Arg(300)->Arg(600)->Unit(benchmark::kMillisecond);

void BM_PnpRansacExplained(benchmark::State& state) {
    const auto obs = correspondences(static_cast<int>(state.range(0)), true);
    const auto K = camera();
    const PnpRansacOptions o{300, 4.0, 0.99, 25};
    for (auto _ : state) benchmark::DoNotOptimize(solvePnpRansac(obs, K, o));
}
BENCHMARK(BM_PnpRansacExplained)->Arg(300)->Arg(600)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
