#include <devslam/core/Association.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <optional>
#include <queue>
#include <tuple>

namespace devslam::core {

namespace {

/// Indices 0..n-1 of which some are removed: the nearest left in a direction, by path
/// halving (near-constant time each).
class Remaining {
  public:
    explicit Remaining(std::size_t n) : next_(n + 1), prev_(n + 1) {
        std::iota(next_.begin(), next_.end(), 0);  // next_[k]: first left at or after k (n: none)
        std::iota(prev_.begin(), prev_.end(), 0);  // prev_[k]: k - 1 of the first at or before
    }
    void remove(std::size_t k) {
        next_[k] = k + 1;
        prev_[k + 1] = k;
    }
    /// The first index >= k still in (n when none).
    std::size_t atOrAfter(std::size_t k) { return find(next_, k); }
    /// The last index < k still in, plus one (0 when none).
    std::size_t before(std::size_t k) { return find(prev_, k); }

  private:
    static std::size_t find(std::vector<std::size_t>& p, std::size_t k) {
        while (p[k] != k) {
            p[k] = p[p[k]];
            k = p[k];
        }
        return k;
    }
    std::vector<std::size_t> next_, prev_;
};

}  // namespace

std::vector<std::pair<std::size_t, std::size_t>> associate(const std::vector<double>& a,
                                                           const std::vector<double>& b,
                                                           double max_dt, double offset) {
    // associate.py takes every pair within max_dt in order of (|diff|, a, b), skipping stamps
    // already used: with stamps denser than max_dt that is n * m candidates (20 000 stamps 1 us
    // apart took 6 GB, then std::bad_alloc). The same pairs, in the same order, from one
    // candidate per stamp of `a`: its best pair among the unused stamps of `b` (nearest on
    // either side of it in sorted order, ties in |diff| by index), kept in a heap and found
    // again when its `b` is taken; a stale candidate is never better than the one found again,
    // so the heap's best is the best of all remaining pairs. Ties are by index (i, j).
    std::vector<std::size_t> order_b(b.size());
    std::iota(order_b.begin(), order_b.end(), 0);
    std::sort(order_b.begin(), order_b.end(),
              [&](auto x, auto y) { return b[x] < b[y] || (b[x] == b[y] && x < y); });
    std::vector<double> sorted_b(b.size());
    for (std::size_t k = 0; k < b.size(); ++k) sorted_b[k] = b[order_b[k]] + offset;
    Remaining left(b.size());

    using Cand = std::tuple<double, std::size_t, std::size_t>;  // (|diff|, i, j)
    // a[i]'s best pair among the remaining b: walking away from a[i] on each side, |diff|
    // only grows, so each walk stops at the first stamp farther than the best so far (every
    // next one at the same |diff|, equal stamps or rounding, is weighed by its index).
    const auto best = [&](std::size_t i) -> std::optional<Cand> {
        std::optional<Cand> c;
        const auto consider = [&](std::size_t k) {  // false: no stamp past k can be better
            const double d = std::abs(a[i] - sorted_b[k]);
            if (!(d < max_dt) || (c && std::get<0>(*c) < d)) return false;
            if (const Cand x{d, i, order_b[k]}; !c || x < *c) c = x;
            return true;
        };
        const std::size_t split = static_cast<std::size_t>(
            std::lower_bound(sorted_b.begin(), sorted_b.end(), a[i]) - sorted_b.begin());
        for (std::size_t k = left.atOrAfter(split); k < b.size(); k = left.atOrAfter(k + 1))
            if (!consider(k)) break;
        for (std::size_t k = left.before(split); k > 0; k = left.before(k - 1))
            if (!consider(k - 1)) break;
        return c;
    };
    std::priority_queue<Cand, std::vector<Cand>, std::greater<>> heap;
    for (std::size_t i = 0; i < a.size(); ++i)
        if (const auto c = best(i)) heap.push(*c);
    std::vector<char> used_b(b.size(), 0);
    std::vector<std::size_t> pos_b(b.size());  // where b[j] is in sorted_b
    for (std::size_t k = 0; k < b.size(); ++k) pos_b[order_b[k]] = k;
    std::vector<std::pair<std::size_t, std::size_t>> out;
    while (!heap.empty()) {
        const auto [d, i, j] = heap.top();
        heap.pop();
        if (used_b[j]) {  // taken since: a[i]'s next best
            if (const auto c = best(i)) heap.push(*c);
            continue;
        }
        used_b[j] = 1;
        left.remove(pos_b[j]);
        out.emplace_back(i, j);
    }
    std::sort(out.begin(), out.end(), [&](auto x, auto y) { return a[x.first] < a[y.first]; });
    return out;
}

}  // namespace devslam::core
