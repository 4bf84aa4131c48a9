#pragma once
/// The dynamic mask for each frame: engineer A's DynamicObjectFilter when the build has
/// devslam::dynamic (DEVSLAM_HAVE_DYNAMIC), otherwise an empty mask (MaskMode::None
/// behaviour) and an error for the other modes.
#include <devslam/core/Frame.h>
#include <devslam/eval/MaskScore.h>

#include <mrpt/config/CConfigFileBase.h>
#include <Eigen/Geometry>
#include <opencv2/core/mat.hpp>

#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace devslam::run {

struct MaskStep {
    cv::Mat mask;  ///< empty or CV_8UC1, 255 = dynamic
    double detect_ms = 0, filter_ms = 0;
    bool detector_ran = false;
    int n_boxes = 0, n_moving = 0;
    std::vector<eval::FilterBox> boxes;  ///< tracked boxes and their states
    std::optional<Eigen::Isometry3d> T_prev_cur_refined;
    /// empty or CV_8UC1, 255 = a person judged static (FilterOutput::static_people)
    cv::Mat static_people;
    /// the SLAM's weight for keypoints where static_people is set
    /// ([dynamic_filter] static_person_weight; 1 = like any keypoint)
    double static_weight = 1.0;
    /// what that weight does to their chi2 tests (slam::FrameFeatures::gate_exponent;
    /// [dynamic_filter] static_person_gate)
    double static_gate_exponent = 1.0;
};

class MaskSource {
  public:
    virtual ~MaskSource() = default;
    [[nodiscard]] virtual MaskStep step(const core::Frame& frame,
                                        const std::optional<Eigen::Isometry3d>& prior) = 0;
    virtual void reset() = 0;
    [[nodiscard]] virtual std::string describe() const = 0;
    /// The smallest frame width and height step() takes [px] (0: any).
    [[nodiscard]] virtual int minFrameSide() const { return 0; }
};

/// Throws std::invalid_argument "unknown mode 'x' (known: none, all_persons, dynamic, truth)"
/// unless `mode` is one makeMaskSource makes.
void requireMode(const std::string& mode);

/// mode: "none" | "all_persons" | "dynamic" | "truth". `cfg` holds [detector] and
/// [dynamic_filter]. "truth" is a diagnostic: the renderer's walker pixels of `input` (a
/// devslam-synth folder) dilated by [dynamic_filter] mask_margin, i.e. a perfect filter's
/// silhouette mask; it throws when `input` has no person truth.
[[nodiscard]] std::unique_ptr<MaskSource> makeMaskSource(const std::string& mode,
                                                         const mrpt::config::CConfigFileBase& cfg,
                                                         const std::string& input);

}  // namespace devslam::run
