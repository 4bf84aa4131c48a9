#include <devslam/slam/Matching.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

namespace devslam::slam {

// Debian builds for baseline x86-64, where __builtin_popcountll is a libgcc call
// (__popcountdi2: 1.2 % of devslam-run's profile on walking_xyz). GCC's target_clones adds
// a POPCNT version chosen at load time on CPUs that have it; the result is the same.
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && !defined(__POPCNT__)
__attribute__((target_clones("popcnt", "default")))
#endif
int hamming32(const uchar* a, const uchar* b) {
    int d = 0;
    for (std::ptrdiff_t i = 0; i < 4; ++i) {
        std::uint64_t x, y;
        std::memcpy(&x, a + 8 * i, 8);
        std::memcpy(&y, b + 8 * i, 8);
        d += __builtin_popcountll(x ^ y);
    }
    return d;
}

KeypointGrid::KeypointGrid(const std::vector<cv::KeyPoint>& kps, cv::Size image, int cell_px)
    : kps_(&kps),
      cell_(cell_px),
      cols_(std::max(1, (image.width + cell_px - 1) / cell_px)),
      rows_(std::max(1, (image.height + cell_px - 1) / cell_px)),
      cells_(static_cast<std::size_t>(cols_ * rows_)) {
    for (int i = 0; i < static_cast<int>(kps.size()); ++i) {
        const int cx = std::clamp(static_cast<int>(kps[i].pt.x) / cell_, 0, cols_ - 1);
        const int cy = std::clamp(static_cast<int>(kps[i].pt.y) / cell_, 0, rows_ - 1);
        cells_[cy * cols_ + cx].push_back(i);
    }
}

void KeypointGrid::query(double u, double v, double radius, std::vector<int>& out) const {
    out.clear();
    const int x0 = std::max(0, static_cast<int>(std::floor((u - radius) / cell_)));
    const int x1 = std::min(cols_ - 1, static_cast<int>(std::floor((u + radius) / cell_)));
    const int y0 = std::max(0, static_cast<int>(std::floor((v - radius) / cell_)));
    const int y1 = std::min(rows_ - 1, static_cast<int>(std::floor((v + radius) / cell_)));
    const double r2 = radius * radius;
    for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x)
            for (int i : cells_[y * cols_ + x]) {
                const double du = (*kps_)[i].pt.x - u, dv = (*kps_)[i].pt.y - v;
                if (du * du + dv * dv <= r2) out.push_back(i);
            }
}

std::vector<Match> matchByProjection(const Map& map, const std::vector<LandmarkId>& candidates,
                                     const FrameFeatures& f, const KeypointGrid& grid,
                                     const Eigen::Isometry3d& T_wc, const core::CameraIntrinsics& K,
                                     const ProjectionMatchOptions& opts, int* n_in_view,
                                     std::vector<LandmarkId>* in_view) {
    const Eigen::Isometry3d T_cw = T_wc.inverse();
    std::vector<int> best_dist(f.size(), std::numeric_limits<int>::max());
    std::vector<Match> best_of_kp(f.size());
    std::vector<int> near;
    int seen = 0;
    for (LandmarkId id : candidates) {
        const Landmark* lm = map.landmark(id);
        if (!lm) continue;
        const Eigen::Vector3d pc = T_cw * lm->p_w;
        if (pc.z() <= 0.05 || pc.z() > opts.max_depth) continue;
        const auto uv = core::project(pc, K);
        if (!uv || uv->x() < 0 || uv->y() < 0 || uv->x() >= K.width || uv->y() >= K.height)
            continue;
        ++seen;
        if (in_view) in_view->push_back(id);
        grid.query(uv->x(), uv->y(), opts.radius, near);
        int d1 = 256, d2 = 256, i1 = -1;
        for (int i : near) {
            const int d = hamming32(lm->descriptor.ptr<uchar>(0), f.descriptors.ptr<uchar>(i));
            if (d < d1) {
                d2 = d1;
                d1 = d;
                i1 = i;
            } else if (d < d2) {
                d2 = d;
            }
        }
        if (i1 < 0 || d1 > opts.max_hamming) continue;
        if (d2 < 256 && d1 > opts.ratio * d2) continue;
        if (d1 < best_dist[i1]) {
            best_dist[i1] = d1;
            best_of_kp[i1] = Match{id, i1, d1};
        }
    }
    if (n_in_view) *n_in_view = seen;
    std::vector<Match> out;
    for (std::size_t i = 0; i < f.size(); ++i)
        if (best_of_kp[i].landmark != kNoId) out.push_back(best_of_kp[i]);
    return out;
}

std::vector<std::pair<int, int>> matchBruteForce(const cv::Mat& query, const cv::Mat& train,
                                                 int max_hamming, double ratio) {
    std::vector<int> best_q_of_t(train.rows, -1), best_d_of_t(train.rows, 257);
    std::vector<std::pair<int, int>> candidates;
    for (int q = 0; q < query.rows; ++q) {
        int d1 = 256, d2 = 256, i1 = -1;
        const uchar* a = query.ptr<uchar>(q);
        for (int t = 0; t < train.rows; ++t) {
            const int d = hamming32(a, train.ptr<uchar>(t));
            if (d < d1) {
                d2 = d1;
                d1 = d;
                i1 = t;
            } else if (d < d2) {
                d2 = d;
            }
        }
        if (i1 < 0 || d1 > max_hamming || d1 > ratio * d2) continue;
        if (d1 < best_d_of_t[i1]) {
            best_d_of_t[i1] = d1;
            best_q_of_t[i1] = q;
        }
    }
    std::vector<std::pair<int, int>> out;
    for (int t = 0; t < train.rows; ++t)
        if (best_q_of_t[t] >= 0) out.emplace_back(best_q_of_t[t], t);
    std::sort(out.begin(), out.end());
    return out;
}

}  // namespace devslam::slam
