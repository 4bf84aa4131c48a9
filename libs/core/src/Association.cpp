#include <devslam/core/Association.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <tuple>

namespace devslam::core {

std::vector<std::pair<std::size_t, std::size_t>> associate(const std::vector<double>& a,
                                                           const std::vector<double>& b,
                                                           double max_dt, double offset) {
    // associate.py builds all |a-b| pairs; a sorted window per `a` gives the same candidate
    // set in O(n log n + candidates).
    std::vector<std::size_t> order_b(b.size());
    std::iota(order_b.begin(), order_b.end(), 0);
    std::sort(order_b.begin(), order_b.end(), [&](auto x, auto y) { return b[x] < b[y]; });
    std::vector<double> sorted_b(b.size());
    for (std::size_t k = 0; k < b.size(); ++k) sorted_b[k] = b[order_b[k]] + offset;

    std::vector<std::tuple<double, std::size_t, std::size_t>> cand;  // (|diff|, i, j)
    for (std::size_t i = 0; i < a.size(); ++i) {
        auto lo = std::lower_bound(sorted_b.begin(), sorted_b.end(), a[i] - max_dt);
        for (auto it = lo; it != sorted_b.end() && *it <= a[i] + max_dt; ++it) {
            const double d = std::abs(a[i] - *it);
            if (d < max_dt) cand.emplace_back(d, i, order_b[it - sorted_b.begin()]);
        }
    }
    std::sort(cand.begin(), cand.end());  // ties: by i then j, deterministic
    std::vector<char> used_a(a.size(), 0), used_b(b.size(), 0);
    std::vector<std::pair<std::size_t, std::size_t>> out;
    for (const auto& [d, i, j] : cand) {
        if (used_a[i] || used_b[j]) continue;
        used_a[i] = used_b[j] = 1;
        out.emplace_back(i, j);
    }
    std::sort(out.begin(), out.end(), [&](auto x, auto y) { return a[x.first] < a[y.first]; });
    return out;
}

}  // namespace devslam::core
