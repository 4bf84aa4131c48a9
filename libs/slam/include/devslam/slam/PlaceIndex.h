#pragma once
/// Place recognition in a loaded map: which of its keyframes look like a frame, without
/// matching the frame against each of them (2 ms a keyframe: seconds a lost frame in a
/// building's map).
///
/// A bag of binary words: a vocabulary tree (Nister & Stewenius 2006, built as DBoW2 builds
/// it) of k-medians clusters of ORB descriptors, `branching` children a node over `levels`
/// levels, is trained on the map's own descriptors when the map is loaded. Each keyframe is
/// the tf-idf weighted, L1-normalized histogram of the words of its keypoints that have a
/// landmark (the ones a candidate is verified with); a frame is scored against them
/// through an inverted file with DBoW2's L1 score, sum over shared words of min(a, b), in
/// [0, 1].
///
/// Written here: neither MRPT nor OpenCV has a vocabulary for binary descriptors (OpenCV's
/// BOWKMeansTrainer clusters float vectors, whose means of bits are no descriptors), and
/// DBoW2 is not packaged in Debian.
///
/// Usage:
///   devslam::slam::PlaceIndex index(map, devslam::slam::PlaceIndexOptions{});
///   for (auto [score, kf] : index.query(frame.descriptors, 10)) ...
/// Deterministic: the same map and options give the same vocabulary. Immutable after
/// construction (queries may run from several threads).
#include <devslam/slam/Map.h>

#include <opencv2/core.hpp>

#include <array>
#include <cstdint>
#include <utility>
#include <vector>

namespace devslam::slam {

struct PlaceIndexOptions {
    int branching = 10;      ///< children of a vocabulary node (k of k-medians)
    int levels = 4;          ///< levels below the root: up to branching^levels words
    int iterations = 10;     ///< k-medians iterations at most, per node
    int max_train = 200000;  ///< descriptors the vocabulary is trained on (evenly sampled)
};

/// A vocabulary tree of binary (32-byte ORB) descriptors.
class BinaryVocabulary {
  public:
    BinaryVocabulary() = default;
    /// Trains on the rows of `descriptors` (CV_8U, 32 columns); k-means++ seeding from a
    /// fixed seed.
    BinaryVocabulary(const cv::Mat& descriptors, const PlaceIndexOptions& opts);
    /// The word of a 32-byte descriptor: the leaf reached by the nearest child at each level.
    [[nodiscard]] int word(const uchar* descriptor) const;
    [[nodiscard]] int words() const { return n_words_; }

  private:
    struct Node {
        std::array<uchar, 32> centre{};
        int first_child = -1;  ///< children are nodes first_child .. first_child + n_children - 1
        int n_children = 0;
        int word = -1;  ///< a leaf's word
    };
    void split(std::vector<const uchar*>& rows, int node, int level, const PlaceIndexOptions& o);
    std::vector<Node> nodes_;
    int n_words_ = 0;
};

class PlaceIndex {
  public:
    /// Trains the vocabulary on `map`'s keyframes and indexes them (a map with no keypoint
    /// that has a landmark gives an index that finds nothing).
    PlaceIndex(const Map& map, const PlaceIndexOptions& opts);
    /// The keyframes sharing words with the frame's `descriptors` (CV_8U, 32 columns, else
    /// std::invalid_argument), by score (best first; ties by id), at most `n`. Only words
    /// some keyframes have and others not count (idf > 0): a map of one keyframe, or of
    /// keyframes with the same words, gives none (the tracker then ranks by matches).
    [[nodiscard]] std::vector<std::pair<double, KeyframeId>> query(const cv::Mat& descriptors,
                                                                   std::size_t n) const;
    [[nodiscard]] int words() const { return voc_.words(); }
    [[nodiscard]] std::size_t keyframes() const { return kf_ids_.size(); }

  private:
    /// The L1-normalized tf-idf histogram of descriptor rows (sorted by word).
    [[nodiscard]] std::vector<std::pair<int, float>> histogram(const cv::Mat& descriptors,
                                                               const std::vector<int>& rows) const;
    BinaryVocabulary voc_;
    std::vector<float> idf_;                                    ///< per word
    std::vector<std::vector<std::pair<int, float>>> inverted_;  ///< word -> (keyframe, weight)
    std::vector<KeyframeId> kf_ids_;                            ///< index -> id
};

}  // namespace devslam::slam
