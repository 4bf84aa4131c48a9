#pragma once
/// One interface for every RGB-D source (TUM folders, MRPT rawlogs, rendered sequences).
///
/// Usage:
///   auto reader = devslam::io::openRgbd("data/tum/fr1_xyz_first37", {});
///   while (auto f = reader->next()) { process(*f); }
///   if (auto gt = reader->groundTruth()) { ... }
/// Not thread-safe.

#include <devslam/core/Camera.h>
#include <devslam/core/Frame.h>
#include <devslam/core/Trajectory.h>

#include <devslam/core/Progress.h>

#include <cstdint>
#include <cstdio>
#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace mrpt::config {
class CConfigFileBase;
}

namespace devslam::io {

/// Options shared by the readers; `[dataset]` in an experiment INI.
struct ReaderOptions {
    /// Camera preset or "auto": for TUM folders "auto" picks freiburg1/2/3 from the folder
    /// name ("rgbd_dataset_freiburg1_xyz", "fr1_xyz_first37"); for rawlogs it uses the
    /// calibration stored in the observations.
    std::string camera = "auto";
    /// Used instead of `camera` when set (e.g. from an INI `[camera]` section).
    std::optional<core::CameraIntrinsics> intrinsics;
    double max_dt = 0.02;           ///< [s] rgb-depth association window (TUM associate.py)
    double tum_depth_scale = 5000;  ///< [units/m] TUM depth PNG scale
    std::string sensor_label;       ///< rawlog: only observations with this label ("" = all)
    /// Use what is intact of a damaged input instead of failing with DamagedInput, and say
    /// what was left out in `RgbdReader::damage()`: of a rawlog cut short (a crash, a full
    /// disk) the frames before the damage, of a TUM folder the rgb-depth pairs whose listed
    /// images exist. Not an INI key: the command-line flag `--allow-damaged` sets it.
    bool allow_damaged = false;
    /// Called while a rawlog is read through as it opens (after each RGB-D observation found,
    /// and once more with bytes_read = bytes_total when it is read through and whole; a TUM
    /// folder opens at once and never calls it): the frames found so far, and how far into the
    /// file's bytes the reading is. For a progress bar (`OpenProgressBar`) and Ctrl-C: false
    /// stops the opening, which throws OpeningStopped. Not an INI key.
    std::function<bool(std::size_t frames, std::uint64_t bytes_read, std::uint64_t bytes_total)>
        on_open;

    void loadFromConfig(const mrpt::config::CConfigFileBase& cfg, const std::string& section);
    /// Throws std::invalid_argument "<what>: unknown camera preset '...' (known: ...) or auto"
    /// unless `camera` is "auto" or a preset ([dataset] camera, devslam-convert --camera).
    static void requireCameraName(const std::string& camera, const std::string& what);
};

/// A damaged input of which `intact()` frames could still be read (with
/// `ReaderOptions::allow_damaged` they are). The message names the file and where it is
/// damaged.
class DamagedInput : public std::runtime_error {
  public:
    DamagedInput(const std::string& what, std::size_t intact)
        : std::runtime_error(what), intact_(intact) {}
    [[nodiscard]] std::size_t intact() const { return intact_; }

  private:
    std::size_t intact_;
};

/// Thrown while an input opens when ReaderOptions::on_open asked to stop (a Ctrl-C during
/// the minutes a large rawlog may take): no reader is made.
class OpeningStopped : public std::runtime_error {
  public:
    using std::runtime_error::runtime_error;
};

/// Thrown by next() when no frame after this point can be read (a rawlog cut or written over
/// after it was opened): unlike a damaged frame it cannot be passed, and the next call ends
/// the input. Frames lost this way are not "left out" frames.
class InputBroken : public std::runtime_error {
  public:
    using std::runtime_error::runtime_error;
};

class RgbdReader {
  public:
    virtual ~RgbdReader() = default;
    /// The next frame, or std::nullopt at the end. Throws std::runtime_error naming the file
    /// (and line or observation index) when the data is damaged; the frame that threw is
    /// passed, so the next call reads the one after it.
    [[nodiscard]] virtual std::optional<core::Frame> next() = 0;
    /// Number of frames if known up front (TUM: yes; rawlog: counted while opening).
    [[nodiscard]] virtual std::optional<std::size_t> size() const = 0;
    /// Ground truth if the source has it (TUM groundtruth.txt).
    [[nodiscard]] virtual std::optional<core::Trajectory> groundTruth() const {
        return std::nullopt;
    }
    /// Intrinsics the frames will carry.
    [[nodiscard]] virtual core::CameraIntrinsics intrinsics() const = 0;
    [[nodiscard]] virtual std::string describe() const = 0;
    /// What of the input could not be read and is left out ("" = nothing), with
    /// `ReaderOptions::allow_damaged`.
    [[nodiscard]] virtual std::string damage() const { return {}; }
};

/// The next frame of `reader` that decodes, or std::nullopt at the end. A frame whose next()
/// throws (damaged: the reader passes it) is left out with `allow_damaged`, its message
/// added to `undecodable`, else its error is thrown; InputBroken (nothing after it can be
/// read) is thrown as it is.
[[nodiscard]] std::optional<core::Frame> nextDecodable(RgbdReader& reader, bool allow_damaged,
                                                       std::vector<std::string>& undecodable);

/// A progress bar for an input that takes a while to open (a rawlog is read through to count
/// its frames and check it: 6 s for 700 MB): "opening seq.rawlog [#####....] 350/705 MB ...
/// 312 frames". Drawn only once opening has taken ProgressBar's interval, so an input that
/// opens at once prints nothing.
///   io::OpenProgressBar bar(path);
///   opts.on_open = bar.callback([] { return core::stopSignal() != 0; });
///   auto reader = io::openRgbd(path, opts);
///   bar.finish();
/// (as openRgbdWithProgress, below, does)
class OpenProgressBar {
  public:
    explicit OpenProgressBar(const std::string& path, std::FILE* out = stderr);
    ~OpenProgressBar();  ///< ends a drawn line (an error printed after it starts its own)
    OpenProgressBar(const OpenProgressBar&) = delete;
    OpenProgressBar& operator=(const OpenProgressBar&) = delete;
    /// For ReaderOptions::on_open; refers to this bar, which must outlive the opening. The
    /// opening stops when `stop` (if given) returns true.
    [[nodiscard]] std::function<bool(std::size_t, std::uint64_t, std::uint64_t)> callback(
        std::function<bool()> stop = {});
    /// Draws the last line when a line was drawn; else nothing.
    void finish();

  private:
    std::string label_;
    std::FILE* out_;
    std::optional<core::ProgressBar> bar_;  // made at the first call (the size known then)
    std::size_t frames_ = 0;
};

/// A TUM folder (has rgb.txt) or a `.rawlog` file, chosen by what `path` is. Throws
/// std::runtime_error with the path when it is neither.
[[nodiscard]] std::unique_ptr<RgbdReader> openRgbd(const std::string& path,
                                                   const ReaderOptions& opts = {});

/// openRgbd as the programs open their input: an OpenProgressBar on `out` (nullptr: none),
/// and a Ctrl-C or SIGTERM recorded by core::installStopHandler stops the opening
/// (OpeningStopped). `opts.on_open` is replaced.
[[nodiscard]] std::unique_ptr<RgbdReader> openRgbdWithProgress(const std::string& path,
                                                               ReaderOptions opts,
                                                               std::FILE* out = stderr);

}  // namespace devslam::io
