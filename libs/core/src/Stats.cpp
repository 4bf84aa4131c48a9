#include <devslam/core/Stats.h>

#include <boost/math/distributions/students_t.hpp>

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

MeanInterval meanInterval95(const std::vector<double>& v) {
    MeanInterval m;
    m.count = v.size();
    if (v.empty()) return m;
    const auto n = static_cast<double>(v.size());
    m.mean = std::accumulate(v.begin(), v.end(), 0.0) / n;
    if (v.size() < 2) return m;
    double ss = 0;
    for (double x : v) ss += (x - m.mean) * (x - m.mean);
    const double half =
        boost::math::quantile(boost::math::students_t(n - 1), 0.975) * std::sqrt(ss / (n - 1) / n);
    m.lo = m.mean - half;
    m.hi = m.mean + half;
    return m;
}

}  // namespace devslam::core
