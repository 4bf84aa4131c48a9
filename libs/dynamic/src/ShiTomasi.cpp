#include <devslam/dynamic/ShiTomasi.h>

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <set>
#include <stdexcept>
#include <string>
#include <tuple>

namespace devslam::dynamic {

ShiTomasiMap ShiTomasiMap::compute(const cv::Mat& gray) {
    ShiTomasiMap m;
    m.update(gray);
    return m;
}

void ShiTomasiMap::update(const cv::Mat& gray) {
    if (gray.type() != CV_8UC1 || gray.empty())
        throw std::invalid_argument("Shi-Tomasi map: needs a non-empty CV_8UC1 image");
    // cv::cornerMinEigenVal(gray, eig, 3, 3), composed from OpenCV's own primitives, which
    // Debian's OpenCV 4.6 runs in 0.6-0.7x its time at 320x240 (devslam-filter-bench, the
    // `detect` section of docs/RESULTS.md): its 3x3 sums, a boxFilter on a 3-channel float
    // image, are the slow part, and a separable filter of ones computes the same sums. The
    // steps write into buffers kept from call to call. Same scale, border and formula: the
    // values agree to float rounding, and the corners selected are goodFeaturesToTrack's
    // (tests ShiTomasi.MapIsCornerMinEigenVal, WholeImageSelectionIsGoodFeaturesToTrack).
    const double scale = 1.0 / (4 * 3 * 255.0);  // 1 / ((1 << (aperture - 1)) * block * 255)
    const auto border = cv::BORDER_REFLECT_101;
    cv::Sobel(gray, a_, CV_32F, 1, 0, 3, scale, 0, border);  // a_ = gx
    cv::Sobel(gray, b_, CV_32F, 0, 1, 3, scale, 0, border);  // b_ = gy
    cv::multiply(a_, a_, c_);                                // gx^2
    cv::multiply(a_, b_, d_);                                // gx gy
    cv::multiply(b_, b_, e_);                                // gy^2
    const cv::Mat ones = cv::Mat::ones(1, 3, CV_32F);        // unnormalised 3x3 block sums
    cv::sepFilter2D(c_, a_, CV_32F, ones, ones, cv::Point(-1, -1), 0, border);  // a_ = Sxx
    cv::sepFilter2D(e_, b_, CV_32F, ones, ones, cv::Point(-1, -1), 0, border);  // b_ = Syy
    cv::sepFilter2D(d_, c_, CV_32F, ones, ones, cv::Point(-1, -1), 0, border);  // c_ = Sxy
    // Smaller eigenvalue of [[Sxx, Sxy], [Sxy, Syy]], as cornerMinEigenVal computes it:
    // (p + q) - sqrt((p - q)^2 + Sxy^2) with p = Sxx / 2, q = Syy / 2.
    a_ *= 0.5;
    b_ *= 0.5;
    cv::subtract(a_, b_, d_);
    cv::magnitude(d_, c_, e_);
    cv::add(a_, b_, eig);
    cv::subtract(eig, e_, eig);
    // A pixel above the quality threshold is a local maximum of the thresholded map (what
    // goodFeaturesToTrack dilates) exactly when it is one of the raw map: its 3x3 maximum is
    // at least its own value, so above the threshold too. One dilation serves every region.
    cv::dilate(eig, eig_max, cv::Mat());
}

std::vector<cv::Point2f> selectShiTomasi(const ShiTomasiMap& map, const cv::Rect& roi,
                                         int max_corners, double quality, double min_distance,
                                         const cv::Mat& mask,
                                         const std::vector<cv::Point2f>& taken) {
    if (map.empty()) throw std::invalid_argument("Shi-Tomasi selection: empty map");
    const cv::Rect whole(0, 0, map.eig.cols, map.eig.rows);
    if (roi.width < 0 || roi.height < 0 || (!roi.empty() && (roi & whole) != roi))
        throw std::invalid_argument("Shi-Tomasi selection: region (" + std::to_string(roi.x) +
                                    ", " + std::to_string(roi.y) + ", " +
                                    std::to_string(roi.width) + " x " + std::to_string(roi.height) +
                                    ") outside the " + std::to_string(whole.width) + " x " +
                                    std::to_string(whole.height) + " map");
    if (!mask.empty() && (mask.type() != CV_8UC1 || mask.size() != roi.size()))
        throw std::invalid_argument(
            "Shi-Tomasi selection: mask must be CV_8U of the region's size");
    std::vector<cv::Point2f> corners;
    if (roi.empty()) return corners;
    const cv::Mat eig = map.eig(roi), eig_max = map.eig_max(roi);
    double max_val = 0;
    cv::minMaxLoc(eig, nullptr, &max_val, nullptr, nullptr, mask);
    const auto thr = static_cast<float>(max_val * quality);

    struct Candidate {
        float v;
        int y, x;  // region coordinates
    };
    std::vector<Candidate> cand;
    for (int y = 1; y < roi.height - 1; ++y) {
        const float* e = eig.ptr<float>(y);
        const float* d = eig_max.ptr<float>(y);
        const uchar* mk = mask.empty() ? nullptr : mask.ptr<uchar>(y);
        for (int x = 1; x < roi.width - 1; ++x)
            if (e[x] > thr && e[x] == d[x] && (!mk || mk[x])) cand.push_back({e[x], y, x});
    }
    // Strongest first; ties go to the later pixel, as goodFeaturesToTrack orders them.
    std::sort(cand.begin(), cand.end(), [](const Candidate& a, const Candidate& b) {
        return a.v != b.v ? a.v > b.v : std::tie(a.y, a.x) > std::tie(b.y, b.x);
    });

    const auto full = [&] {
        return max_corners > 0 && static_cast<int>(corners.size()) >= max_corners;
    };
    const cv::Point2f offset(static_cast<float>(roi.x), static_cast<float>(roi.y));
    if (min_distance < 1) {
        std::set<std::pair<int, int>> used;  // the taken corners' pixels in the region
        for (const auto& q : taken) used.insert({cvRound(q.y) - roi.y, cvRound(q.x) - roi.x});
        for (const auto& c : cand) {
            if (full()) break;
            if (used.count({c.y, c.x})) continue;
            corners.emplace_back(cv::Point2f(static_cast<float>(c.x), static_cast<float>(c.y)) +
                                 offset);
        }
        return corners;
    }
    // Grid of min_distance cells: a new corner is checked against the 3x3 cells around it.
    const int cell = cvRound(min_distance);
    const int gw = (roi.width + cell - 1) / cell, gh = (roi.height + cell - 1) / cell;
    std::vector<std::vector<cv::Point2f>> grid(static_cast<std::size_t>(gw) * gh);
    const auto d2 = static_cast<float>(min_distance * min_distance);
    // The taken corners within min_distance of the region hold their place: one just outside
    // goes into the nearest border cell, whose 3x3 neighbourhood holds every candidate closer
    // to it than min_distance.
    for (const auto& q : taken) {
        // Whole pixels, as the candidates: then one in a cell two cells away from another is
        // at least cell + 1 > min_distance from it (a fractional one could be closer).
        const int x = cvRound(q.x) - roi.x, y = cvRound(q.y) - roi.y;
        if (x <= -min_distance || y <= -min_distance || x >= roi.width + min_distance ||
            y >= roi.height + min_distance)
            continue;
        // (x / cell rounds a negative x towards 0: the clamp puts it in the border cell anyway)
        const int cx = std::clamp(x / cell, 0, gw - 1), cy = std::clamp(y / cell, 0, gh - 1);
        grid[static_cast<std::size_t>(cy) * gw + cx].push_back(
            cv::Point2f(static_cast<float>(x), static_cast<float>(y)));
    }
    for (const auto& c : cand) {
        const int cx = c.x / cell, cy = c.y / cell;
        bool good = true;
        for (int yy = std::max(0, cy - 1); good && yy <= std::min(gh - 1, cy + 1); ++yy)
            for (int xx = std::max(0, cx - 1); good && xx <= std::min(gw - 1, cx + 1); ++xx)
                for (const auto& q : grid[static_cast<std::size_t>(yy) * gw + xx]) {
                    const float dx = static_cast<float>(c.x) - q.x,
                                dy = static_cast<float>(c.y) - q.y;
                    if (dx * dx + dy * dy < d2) {
                        good = false;
                        break;
                    }
                }
        if (!good) continue;
        const cv::Point2f p(static_cast<float>(c.x), static_cast<float>(c.y));
        grid[static_cast<std::size_t>(cy) * gw + cx].push_back(p);
        corners.push_back(p + offset);
        if (full()) break;
    }
    return corners;
}

}  // namespace devslam::dynamic
