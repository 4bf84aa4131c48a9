#pragma once
/// Renders the frames of a Scenario headless (mrpt::opengl::CFBORender, EGL) with exact
/// ground truth: camera pose, perfect depth, per-person pixel labels and boxes.
///
/// Usage:
///   devslam::render::SequenceRenderer r(devslam::render::loadScenario(path));
///   for (std::size_t i = 0; i < r.frameCount(); ++i) { auto f = r.render(i); ... }
/// Not thread-safe (one GL context per renderer).

#include <devslam/core/Frame.h>
#include <devslam/render/Scenario.h>

#include <mrpt/poses/CPose3D.h>

#include <opencv2/core/mat.hpp>

#include <memory>
#include <string>
#include <vector>

namespace devslam::render {

/// What the renderer knows about one person in one frame.
struct PersonTruth {
    int id = 0;              ///< 1-based, also the value in RenderedFrame::labels
    std::string name;        ///< INI section name
    bool moving = false;     ///< walking at this instant
    cv::Rect box;            ///< bounding box of the visible pixels (empty when not visible) [px]
    int visible_pixels = 0;  ///< pixels where this person is the nearest surface
};

struct RenderedFrame {
    core::Frame frame;          ///< colour + (noisy) depth + K + timestamp
    mrpt::poses::CPose3D T_wc;  ///< exact pose of the optical centre
    cv::Mat clean_depth;        ///< CV_32FC1 perfect depth [m] (0 = nothing rendered)
    cv::Mat labels;             ///< CV_8UC1, 0 = background, k = PersonTruth::id
    std::vector<PersonTruth> persons;
};

class SequenceRenderer {
  public:
    /// Builds the GL scene (loads all textures). Throws std::runtime_error naming the file
    /// on a missing texture, or when no EGL context can be created.
    explicit SequenceRenderer(Scenario sc);
    ~SequenceRenderer();
    SequenceRenderer(const SequenceRenderer&) = delete;
    SequenceRenderer& operator=(const SequenceRenderer&) = delete;

    [[nodiscard]] std::size_t frameCount() const { return sc_.n_frames; }
    [[nodiscard]] const Scenario& scenario() const { return sc_; }
    /// Renders frame i (any order; the result depends only on the scenario and i).
    [[nodiscard]] RenderedFrame render(std::size_t i);

  private:
    struct Impl;
    Scenario sc_;
    std::unique_ptr<Impl> impl_;
};

}  // namespace devslam::render
