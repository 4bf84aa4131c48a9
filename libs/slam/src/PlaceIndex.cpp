#include <devslam/slam/Matching.h>
#include <devslam/slam/PlaceIndex.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

namespace devslam::slam {

namespace {
/// A uniform double in [0, 1) from the generator's bits (std::uniform_real_distribution's
/// output is the library's choice; the vocabulary must be the same wherever it is built).
double uniform01(std::mt19937_64& rng) {
    return static_cast<double>(rng() >> 11) * 0x1.0p-53;
}

/// kSpread[v]: byte j is bit 7 - j of v (the descriptor's bits, most significant first).
constexpr std::array<std::uint64_t, 256> makeSpread() {
    std::array<std::uint64_t, 256> t{};
    for (int v = 0; v < 256; ++v)
        for (int j = 0; j < 8; ++j)
            t[static_cast<std::size_t>(v)] |= static_cast<std::uint64_t>((v >> (7 - j)) & 1)
                                              << (8 * j);
    return t;
}
constexpr auto kSpread = makeSpread();
}  // namespace

BinaryVocabulary::BinaryVocabulary(const cv::Mat& descriptors, const PlaceIndexOptions& opts) {
    if (opts.branching < 2 || opts.levels < 1 || opts.iterations < 1 || opts.max_train < 1)
        throw std::invalid_argument(
            "BinaryVocabulary: branching >= 2, levels, iterations and "
            "max_train >= 1 needed");
    if (!descriptors.empty() && (descriptors.type() != CV_8U || descriptors.cols != 32))
        throw std::invalid_argument("BinaryVocabulary: descriptors must be CV_8U, 32 columns");
    nodes_.emplace_back();  // the root
    if (descriptors.empty()) return;
    // Evenly spaced rows, at most max_train of them.
    const int n = descriptors.rows;
    const int take = std::min(n, opts.max_train);
    std::vector<const uchar*> rows;
    rows.reserve(static_cast<std::size_t>(take));
    for (int i = 0; i < take; ++i)
        rows.push_back(
            descriptors.ptr<uchar>(static_cast<int>(static_cast<long long>(i) * n / take)));
    split(rows, 0, 0, opts);
}

void BinaryVocabulary::split(std::vector<const uchar*>& rows, int node, int level,
                             const PlaceIndexOptions& o) {
    if (level == o.levels || rows.size() <= 1) {
        nodes_[static_cast<std::size_t>(node)].word = n_words_++;
        return;
    }
    const std::size_t n = rows.size();
    // k-means++ seeding: each next centre drawn with probability proportional to its squared
    // distance to the nearest centre so far; rows all equal to a centre end it early.
    std::mt19937_64 rng(0x5eedULL + static_cast<std::uint64_t>(node));
    std::vector<const uchar*> seeds = {rows[rng() % n]};
    std::vector<double> d2(n);
    for (std::size_t i = 0; i < n; ++i) {
        const double d = hamming32(rows[i], seeds[0]);
        d2[i] = d * d;
    }
    while (seeds.size() < static_cast<std::size_t>(o.branching)) {
        double sum = 0;
        for (double v : d2) sum += v;
        if (sum <= 0) break;
        double pick = uniform01(rng) * sum;
        std::size_t chosen = n - 1;
        for (std::size_t i = 0; i < n; ++i) {
            pick -= d2[i];
            if (pick < 0 && d2[i] > 0) {
                chosen = i;
                break;
            }
        }
        if (d2[chosen] <= 0) break;  // rounding at the end: no row left apart from the seeds
        seeds.push_back(rows[chosen]);
        for (std::size_t i = 0; i < n; ++i) {
            const double d = hamming32(rows[i], rows[chosen]);
            d2[i] = std::min(d2[i], d * d);
        }
    }
    const std::size_t k = seeds.size();
    std::vector<std::array<uchar, 32>> centres(k);
    for (std::size_t c = 0; c < k; ++c) std::copy(seeds[c], seeds[c] + 32, centres[c].begin());
    // k-medians: each row to its nearest centre, each centre the bitwise majority of its rows.
    std::vector<int> of(n, -1);
    // At most `iterations` centre updates, each followed by an assignment: the children are
    // split by the assignment to the centres they get.
    for (int it = 0;; ++it) {
        bool changed = false;
        for (std::size_t i = 0; i < n; ++i) {
            int best = 0, best_d = 257;
            for (std::size_t c = 0; c < k; ++c)
                if (const int d = hamming32(rows[i], centres[c].data()); d < best_d) {
                    best_d = d;
                    best = static_cast<int>(c);
                }
            changed |= of[i] != best;
            of[i] = best;
        }
        if (!changed || it == o.iterations) break;
        // Bit counts per cluster, 8 at a time: byte j of lanes[c][B] counts bit 7 - j of byte
        // B, so a row adds 32 words, not 256 bits (the counting was most of the training);
        // flushed before a byte lane can overflow.
        std::vector<std::array<int, 256>> ones(k);
        std::vector<std::array<std::uint64_t, 32>> lanes(k);
        std::vector<int> size(k, 0), pending(k, 0);
        for (auto& o1 : ones) o1.fill(0);
        for (auto& l : lanes) l.fill(0);
        const auto flush = [&](std::size_t c) {
            for (int B = 0; B < 32; ++B)
                for (int j = 0; j < 8; ++j)
                    ones[c][8 * B + j] += static_cast<int>((lanes[c][B] >> (8 * j)) & 0xff);
            lanes[c].fill(0);
            pending[c] = 0;
        };
        for (std::size_t i = 0; i < n; ++i) {
            const auto c = static_cast<std::size_t>(of[i]);
            ++size[c];
            for (int B = 0; B < 32; ++B) lanes[c][B] += kSpread[rows[i][B]];
            if (++pending[c] == 255) flush(c);
        }
        for (std::size_t c = 0; c < k; ++c) flush(c);
        for (std::size_t c = 0; c < k; ++c) {
            if (size[c] == 0) continue;  // kept; dropped below if still empty
            centres[c].fill(0);
            for (int b = 0; b < 256; ++b)
                if (2 * ones[c][b] > size[c]) centres[c][b / 8] |= uchar(1u << (7 - b % 8));
        }
    }
    std::vector<std::vector<const uchar*>> members(k);
    for (std::size_t i = 0; i < n; ++i) members[static_cast<std::size_t>(of[i])].push_back(rows[i]);
    rows.clear();
    rows.shrink_to_fit();
    const int first = static_cast<int>(nodes_.size());
    int made = 0;
    for (std::size_t c = 0; c < k; ++c)
        if (!members[c].empty()) {
            nodes_.emplace_back();
            nodes_.back().centre = centres[c];
            ++made;
        }
    nodes_[static_cast<std::size_t>(node)].first_child = first;
    nodes_[static_cast<std::size_t>(node)].n_children = made;
    int child = first;
    for (std::size_t c = 0; c < k; ++c)
        if (!members[c].empty()) split(members[c], child++, level + 1, o);
}

int BinaryVocabulary::word(const uchar* descriptor) const {
    if (n_words_ == 0) return -1;
    std::size_t node = 0;
    while (nodes_[node].n_children > 0) {
        const int first = nodes_[node].first_child;
        int best = first, best_d = 257;
        for (int c = first; c < first + nodes_[node].n_children; ++c)
            if (const int d =
                    hamming32(descriptor, nodes_[static_cast<std::size_t>(c)].centre.data());
                d < best_d) {
                best_d = d;
                best = c;
            }
        node = static_cast<std::size_t>(best);
    }
    return nodes_[node].word;
}

PlaceIndex::PlaceIndex(const Map& map, const PlaceIndexOptions& opts) {
    // Each keyframe's keypoints with a landmark: what the vocabulary learns, and what a
    // candidate is verified with.
    std::vector<std::vector<int>> rows_of;
    int total = 0;
    for (const auto& [id, kf] : map.keyframes()) {
        std::vector<int> rows;
        for (int i = 0; i < static_cast<int>(kf.landmark_of_kp.size()); ++i)
            if (kf.landmark_of_kp[static_cast<std::size_t>(i)] != kNoId) rows.push_back(i);
        total += static_cast<int>(rows.size());
        kf_ids_.push_back(id);
        rows_of.push_back(std::move(rows));
    }
    cv::Mat all(total, 32, CV_8U);
    int r = 0;
    std::size_t k = 0;
    for (const auto& [id, kf] : map.keyframes()) {
        for (int i : rows_of[k]) kf.features.descriptors.row(i).copyTo(all.row(r++));
        ++k;
    }
    voc_ = BinaryVocabulary(all, opts);
    all.release();
    // idf = log(keyframes / keyframes with the word): a word every keyframe has tells none
    // apart (weight 0).
    std::vector<std::vector<int>> words_of(kf_ids_.size());
    std::vector<int> df(static_cast<std::size_t>(voc_.words()), 0);
    k = 0;
    for (const auto& [id, kf] : map.keyframes()) {
        auto& w = words_of[k];
        for (int i : rows_of[k]) w.push_back(voc_.word(kf.features.descriptors.ptr<uchar>(i)));
        std::sort(w.begin(), w.end());
        for (std::size_t j = 0; j < w.size(); ++j)
            if (j == 0 || w[j] != w[j - 1]) ++df[static_cast<std::size_t>(w[j])];
        ++k;
    }
    idf_.assign(df.size(), 0.0f);
    for (std::size_t w = 0; w < df.size(); ++w)
        if (df[w] > 0)
            idf_[w] = static_cast<float>(std::log(static_cast<double>(kf_ids_.size()) / df[w]));
    inverted_.resize(df.size());
    k = 0;
    for (const auto& [id, kf] : map.keyframes()) {
        for (const auto& [w, v] : histogram(kf.features.descriptors, rows_of[k]))
            inverted_[static_cast<std::size_t>(w)].emplace_back(static_cast<int>(k), v);
        ++k;
    }
}

std::vector<std::pair<int, float>> PlaceIndex::histogram(const cv::Mat& descriptors,
                                                         const std::vector<int>& rows) const {
    std::vector<int> w;
    w.reserve(rows.size());
    for (int i : rows)
        if (const int word = voc_.word(descriptors.ptr<uchar>(i)); word >= 0) w.push_back(word);
    std::sort(w.begin(), w.end());
    std::vector<std::pair<int, float>> h;
    double sum = 0;
    for (std::size_t j = 0; j < w.size();) {
        std::size_t e = j;
        while (e < w.size() && w[e] == w[j]) ++e;
        // tf * idf; the common 1 / rows of tf goes in the normalization.
        const float v = static_cast<float>(e - j) * idf_[static_cast<std::size_t>(w[j])];
        if (v > 0) {
            h.emplace_back(w[j], v);
            sum += v;
        }
        j = e;
    }
    for (auto& [word, v] : h) v = static_cast<float>(v / sum);
    return h;
}

std::vector<std::pair<double, KeyframeId>> PlaceIndex::query(const cv::Mat& descriptors,
                                                             std::size_t n) const {
    if (!descriptors.empty() && (descriptors.type() != CV_8U || descriptors.cols != 32))
        throw std::invalid_argument("PlaceIndex::query: descriptors must be CV_8U, 32 columns");
    std::vector<int> rows(static_cast<std::size_t>(descriptors.rows));
    for (int i = 0; i < descriptors.rows; ++i) rows[static_cast<std::size_t>(i)] = i;
    std::vector<double> score(kf_ids_.size(), 0.0);
    for (const auto& [w, q] : histogram(descriptors, rows))
        for (const auto& [kf, v] : inverted_[static_cast<std::size_t>(w)])
            score[static_cast<std::size_t>(kf)] += std::min(q, v);
    std::vector<std::pair<double, KeyframeId>> out;
    for (std::size_t k = 0; k < score.size(); ++k)
        if (score[k] > 0) out.emplace_back(score[k], kf_ids_[k]);
    const auto better = [](const auto& a, const auto& b) {
        return a.first != b.first ? a.first > b.first : a.second < b.second;
    };
    const std::size_t m = std::min(n, out.size());
    std::partial_sort(out.begin(), out.begin() + static_cast<std::ptrdiff_t>(m), out.end(), better);
    out.resize(m);
    return out;
}

}  // namespace devslam::slam
