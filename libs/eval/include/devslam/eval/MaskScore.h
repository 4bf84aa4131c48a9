#pragma once
// Scores the dynamic-object filter's masks against the renderer's person truth
// (labels/<t>.png and persons.txt of a devslam-synth folder).
#include <opencv2/core/mat.hpp>
#include <opencv2/core/types.hpp>

#include <cstddef>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace devslam::eval {

/// One line of persons.txt.
struct PersonEntry {
    int id = 0;
    std::string name;
    bool moving = false;
    int visible_pixels = 0;
};

/// A box the filter tracked in the scored frame, with its state ("moving", "static",
/// "unknown"): tells for each mask error whether the detector missed the person or the
/// flow test judged them wrong.
struct FilterBox {
    cv::Rect2f box;
    std::string state;
};

/// persons.txt keyed by its timestamp string ("%.6f"). Throws naming file and line.
[[nodiscard]] std::map<std::string, std::vector<PersonEntry>> readPersons(const std::string& path);

struct MaskScore {
    std::size_t moving_instances = 0;  ///< (frame, walking person) pairs with enough visible pixels
    std::size_t moving_masked = 0;     ///< ... of which >= half the visible pixels were masked
    std::size_t static_instances = 0;  ///< same for sitting/standing people
    std::size_t static_masked = 0;
    double moving_px = 0, moving_px_masked = 0;  ///< visible / masked pixels of walking people
    double masked_px = 0;                        ///< all masked pixels
    /// Scored person instances whose mask state is wrong (a walker not masked, a static
    /// person masked), for diagnosis.
    struct Error {
        double timestamp = 0;
        int person_id = 0;
        bool moving = false;
        int visible_pixels = 0;
        double masked_fraction = 0;
        /// State of the filter box that covers most of the person's visible pixels, "none"
        /// when no box covers at least min_box_cover of them (the detector missed them).
        std::string filter_box = "none";
        double box_cover = 0;  ///< fraction of the visible pixels inside that box
    };
    std::vector<Error> errors;
    /// A box must cover this fraction of a person's visible pixels to be theirs.
    static constexpr double min_box_cover = 0.3;
    void add(const cv::Mat& mask, const cv::Mat& labels, const std::vector<PersonEntry>& persons,
             int min_pixels, double timestamp = 0, const std::vector<FilterBox>& boxes = {});
    /// Walker instances not masked whose person had no filter box ("none").
    [[nodiscard]] std::size_t movingMissedWithoutBox() const;
    /// Fraction of walking-person instances that were masked (recall per person and frame).
    [[nodiscard]] double movingRecall() const;
    /// Fraction of static-person instances that were masked (should be small).
    [[nodiscard]] double staticMasked() const;
    /// Fraction of the walking people's visible area that was masked.
    [[nodiscard]] double movingAreaRecall() const;
    /// Fraction of the masked area that lies on walking people.
    [[nodiscard]] double precision() const;
};

/// A frame whose person truth is missing or unreadable (no persons.txt entry, no label
/// image, a labelled id its entries do not list): a damaged folder, which a run treats as its end (devslam-run keeps the frames
/// before it).
struct MissingTruth : std::runtime_error {
    using std::runtime_error::runtime_error;
};

/// The person truth of a rendered folder (persons.txt + labels/<timestamp>.png), to score
/// the masks of a run frame by frame.
class PersonTruth {
  public:
    /// nullopt when `folder` lacks persons.txt or labels/ (real data, or rendered with
    /// --no-labels); throws on a malformed persons.txt.
    [[nodiscard]] static std::optional<PersonTruth> open(const std::string& folder);
    /// Whether `folder` has both parts of the truth (persons.txt and labels/), without
    /// reading them: what open() checks first.
    [[nodiscard]] static bool available(const std::string& folder);
    /// Whether `folder` has the truth and its persons.txt lists a walking person in some
    /// frame. Without one, walkerMask() is empty in every frame (mode `truth` is mode
    /// `none` there). Throws on a malformed persons.txt, as open() does.
    [[nodiscard]] static bool hasWalkers(const std::string& folder);
    /// Adds the frame at `timestamp` to `score`. Throws naming the file when the frame has
    /// no truth (a missing label image or persons.txt entry), or when a non-empty `mask` and
    /// the label image differ in size.
    void score(const cv::Mat& mask, double timestamp, int min_pixels, MaskScore& score,
               const std::vector<FilterBox>& boxes = {}) const;
    /// The ideal dynamic mask of the frame at `timestamp`: every visible pixel of the
    /// walking people, dilated by `margin` px (CV_8UC1, 255 = dynamic). devslam-run's
    /// diagnostic mode `truth` feeds it to the SLAM: the bound the filter can approach.
    /// Throws like score(); `frame_size`, when given, must be the label image's.
    [[nodiscard]] cv::Mat walkerMask(double timestamp, int margin, cv::Size frame_size = {}) const;

  private:
    struct FrameTruth {
        cv::Mat labels;
        const std::vector<PersonEntry>* persons = nullptr;
    };
    [[nodiscard]] FrameTruth frame(double timestamp, cv::Size expected = {}) const;
    std::string folder_;
    std::map<std::string, std::vector<PersonEntry>> persons_;
};

}  // namespace devslam::eval
