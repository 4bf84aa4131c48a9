#pragma once
/// Writes a rendered Scenario as a TUM RGB-D folder (rgb/, depth/, rgb.txt, depth.txt,
/// groundtruth.txt), plus the person truth (persons.txt, labels/<t>.png), the intrinsics
/// (camera.ini) and optionally an MRPT rawlog.
///
/// Usage:
///   devslam::render::WriteOptions o; o.out_dir = "out/walking_xyz";
///   auto summary = devslam::render::writeSequence(scenario, o);

#include <devslam/render/Scenario.h>

#include <cstddef>
#include <functional>
#include <string>

namespace devslam::render {

struct RenderedFrame;

struct WriteOptions {
    std::string out_dir;         ///< created if missing; existing files are overwritten
    std::string rawlog_path;     ///< empty = no rawlog
    bool write_labels = true;    ///< labels/<timestamp>.png (person id per pixel)
    std::size_t max_frames = 0;  ///< 0 = all frames of the scenario
    /// Asked before each frame; true ends the render there (Ctrl-C): the frames rendered so
    /// far are written as a whole TUM folder (lists, ground truth, camera.ini), but without
    /// render.txt, so the folder is not a current render (isRenderCurrent). True before the
    /// first frame: nothing is written, the folder is left as it was.
    std::function<bool()> stop;
    /// Called with each frame (its index and the frame) once it is written, before the next
    /// is rendered: what a caller wants of the frames besides the files (devslam-synth's
    /// preview.png), without rendering them again. An exception from it ends the render.
    std::function<void(std::size_t, const RenderedFrame&)> on_frame;
};

struct WriteSummary {
    std::size_t n_frames = 0;
    std::size_t frames_with_moving_person = 0;  ///< frames where a walking person is visible
    std::size_t frames_with_static_person =
        0;                          ///< frames where a sitting/standing person is visible
    double render_ms_median = 0.0;  ///< GL render + read-back per frame [ms]
    /// Frames whose depth image (after [depth_noise]) has no value at all, though the scene
    /// was in view: a noise model or range that leaves the render useless for RGB-D.
    std::size_t frames_without_depth = 0;
    double depth_fraction_median = 0.0;  ///< of each frame's pixels, those with a depth
    bool stopped = false;           ///< WriteOptions::stop ended it before the last frame
};

/// Refuses outputs whose writing would destroy what is not a render: an `out_dir` holding
/// a TUM sequence (rgb.txt) that devslam-synth did not write (neither render.txt nor
/// persons.txt, one of which every render, even a stopped one, leaves before rgb.txt), and a
/// `rawlog_path` not ending in .rawlog or that is the scenario or its room file. Throws
/// std::invalid_argument naming the path. writeSequence checks this first.
void checkOutputs(const Scenario& sc, const WriteOptions& o);

/// Renders and writes every frame; `progress(done, total)` is called after each frame.
/// Throws std::runtime_error naming the path when a file cannot be written, and
/// std::invalid_argument for the outputs checkOutputs refuses.
WriteSummary writeSequence(const Scenario& sc, const WriteOptions& o,
                           const std::function<void(std::size_t, std::size_t)>& progress = {});

/// Bump when the renderer's output for an unchanged scenario changes: renders made by an
/// older version are then no longer current (isRenderCurrent).
inline constexpr int kRendererVersion = 4;  // 3: bilinear texture sampling by default;
                                            // 4: seated/standing people keep their yaw

/// What a render is made of, as text: the renderer version, the seed, the frame count, the
/// labels switch, the settings of the scenario and room files (their lines without comments:
/// editing a comment keeps a render current), and the size of every texture file.
/// writeSequence writes it to <out_dir>/render.txt after the last frame. Throws naming the
/// file when a scenario or room file cannot be read.
[[nodiscard]] std::string renderSignature(const Scenario& sc, const WriteOptions& o);

/// True when `o.out_dir` holds a complete render of exactly `sc` and `o`: its render.txt
/// equals renderSignature(sc, o). False for a folder written by an interrupted run, by an
/// older renderer, or from another scenario, room, seed or frame count (rawlogs are not checked).
[[nodiscard]] bool isRenderCurrent(const Scenario& sc, const WriteOptions& o);

/// persons.txt line format (also written as the file's header comment).
inline constexpr const char* kPersonsHeader =
    "# timestamp id name state x y w h visible_pixels   (state: moving|static; box of the "
    "visible pixels in px, w = h = 0 when not visible)";

}  // namespace devslam::render
