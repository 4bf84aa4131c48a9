#include <devslam/core/Stats.h>

#include <algorithm>
#include <cmath>
#include <numeric>

namespace devslam::core {

double median(std::vector<double> v) {
    if (v.empty()) return 0.0;
    const std::size_t n = v.size();
    std::nth_element(v.begin(), v.begin() + n / 2, v.end());
    const double hi = v[n / 2];
    if (n % 2 == 1) return hi;
    const double lo = *std::max_element(v.begin(), v.begin() + n / 2);
    return 0.5 * (lo + hi);
}

double interquartileMean(std::vector<double> v) {
    if (v.empty()) return 0.0;
    std::sort(v.begin(), v.end());
    const std::size_t cut = v.size() / 4;
    const auto first = v.begin() + static_cast<std::ptrdiff_t>(cut);
    const auto last = v.end() - static_cast<std::ptrdiff_t>(cut);
    return std::accumulate(first, last, 0.0) / static_cast<double>(last - first);
}

Summary summarize(const std::vector<double>& v) {
    Summary s;
    s.count = v.size();
    if (v.empty()) return s;
    const auto n = static_cast<double>(v.size());
    double sum = 0, sum_sq = 0;
    for (double x : v) sum += x, sum_sq += x * x;
    s.mean = sum / n;
    s.rmse = std::sqrt(sum_sq / n);
    double var = 0;
    for (double x : v) var += (x - s.mean) * (x - s.mean);
    s.std = std::sqrt(var / n);
    s.median = median(v);
    const auto [mn, mx] = std::minmax_element(v.begin(), v.end());
    s.min = *mn;
    s.max = *mx;
    return s;
}

}  // namespace devslam::core
