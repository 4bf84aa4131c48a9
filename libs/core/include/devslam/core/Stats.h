#pragma once
/// Summary statistics as the TUM benchmark tools print them (numpy semantics:
/// median of an even count = mean of the two middle values, std = population std).

#include <cstddef>
#include <limits>
#include <vector>

namespace devslam::core {

struct Summary {
    std::size_t count = 0;
    double rmse = 0, mean = 0, median = 0, std = 0, min = 0, max = 0;
};

/// Summary of `v`; all zero for an empty vector.
[[nodiscard]] Summary summarize(const std::vector<double>& v);
/// Median (numpy.median); 0 for an empty vector.
[[nodiscard]] double median(std::vector<double> v);
/// Interquartile mean: the mean of the values left after dropping the lowest and the highest
/// quarter (floor(n / 4) each); 0 for an empty vector. As robust to a minority of outliers
/// as the median, but it keeps the size of a change shown by part of the values (quantized
/// samples, a mixture) where the median jumps between them.
[[nodiscard]] double interquartileMean(std::vector<double> v);

/// The mean of `v` and its two-sided 95 % confidence interval, mean +- t * s / sqrt(n), with s
/// the sample standard deviation (n - 1) and t Student's 97.5 % quantile for n - 1 degrees of
/// freedom (Boost.Math): for a few paired samples, such as one figure on a handful of renders.
/// Fewer than two values: no interval (NaN bounds; the mean of one value is that value).
struct MeanInterval {
    std::size_t count = 0;
    double mean = std::numeric_limits<double>::quiet_NaN();
    double lo = std::numeric_limits<double>::quiet_NaN();
    double hi = std::numeric_limits<double>::quiet_NaN();
};
[[nodiscard]] MeanInterval meanInterval95(const std::vector<double>& v);

}  // namespace devslam::core
