// Google Benchmark: finding a lost frame's candidate keyframes in a loaded map of N keyframes
// (each 600 keypoints with a landmark, random descriptors), with the place index against
// ranking every keyframe by brute-force matches of the frame's strongest 250 keypoints (the
// tracker's way with [tracker] place_recognition = false); and training the index at load.
// Run: build/benchmarks/bench_place   (timings only; what is found is tested in test_slam)
#include <devslam/slam/Matching.h>
#include <devslam/slam/PlaceIndex.h>

#include <benchmark/benchmark.h>

#include <random>

namespace {
using namespace devslam::slam;

constexpr int kPerKeyframe = 600;

cv::Mat randomDescriptors(int rows, std::mt19937& rng) {
    cv::Mat d(rows, 32, CV_8U);
    std::uniform_int_distribution<int> byte(0, 255);
    for (int i = 0; i < rows; ++i)
        for (int b = 0; b < 32; ++b) d.at<uchar>(i, b) = static_cast<uchar>(byte(rng));
    return d;
}

const Map& mapOf(int n) {
    static std::map<int, Map> maps;
    if (const auto it = maps.find(n); it != maps.end()) return it->second;
    std::mt19937 rng(static_cast<unsigned>(n));
    Map map;
    for (int k = 0; k < n; ++k) {
        Keyframe kf;
        kf.features.descriptors = randomDescriptors(kPerKeyframe, rng);
        kf.features.keypoints.resize(kPerKeyframe);
        kf.features.depth.assign(kPerKeyframe, 1.f);
        kf.features.points_c.assign(kPerKeyframe, Eigen::Vector3d(0, 0, 1));
        kf.features.colors.resize(kPerKeyframe);
        const cv::Mat d = kf.features.descriptors.clone();
        const KeyframeId id = map.addKeyframe(std::move(kf));
        for (int i = 0; i < kPerKeyframe; ++i)
            (void)map.addLandmark(Eigen::Vector3d(0, 0, 1), d.row(i), {}, id, i);
    }
    return maps.emplace(n, std::move(map)).first->second;
}

void BM_PlaceIndexQuery(benchmark::State& state) {
    const Map& map = mapOf(static_cast<int>(state.range(0)));
    const PlaceIndex index(map, PlaceIndexOptions{});
    std::mt19937 rng(7);
    const cv::Mat frame = randomDescriptors(1000, rng);
    for (auto _ : state) benchmark::DoNotOptimize(index.query(frame, 10));
}
BENCHMARK(BM_PlaceIndexQuery)->Arg(100)->Arg(1000)->Arg(5000)->Unit(benchmark::kMillisecond);

void BM_BruteForceRanking(benchmark::State& state) {
    const Map& map = mapOf(static_cast<int>(state.range(0)));
    std::mt19937 rng(7);
    const cv::Mat strongest = randomDescriptors(250, rng);
    for (auto _ : state) {
        std::size_t total = 0;
        for (const auto& [id, kf] : map.keyframes())
            total += matchBruteForce(strongest, kf.features.descriptors, 64, 0.8).size();
        benchmark::DoNotOptimize(total);
    }
}
BENCHMARK(BM_BruteForceRanking)->Arg(100)->Arg(1000)->Arg(5000)->Unit(benchmark::kMillisecond);

void BM_PlaceIndexBuild(benchmark::State& state) {
    const Map& map = mapOf(static_cast<int>(state.range(0)));
    for (auto _ : state) {
        const PlaceIndex index(map, PlaceIndexOptions{});
        benchmark::DoNotOptimize(index.words());
    }
}
BENCHMARK(BM_PlaceIndexBuild)->Arg(100)->Arg(1000)->Arg(5000)->Unit(benchmark::kMillisecond);
}  // namespace
BENCHMARK_MAIN();
