#pragma once
/// One run of the whole pipeline over a sequence: reader -> dynamic mask -> SLAM, with
/// per-frame timings per stage, then evaluation against ground truth and the output files.
#include <devslam/core/Trajectory.h>
#include <devslam/eval/MaskScore.h>
#include <devslam/eval/Metrics.h>
#include <devslam/io/RgbdReader.h>
#include <devslam/slam/MapFile.h>
#include <devslam/slam/Slam.h>

#include <mrpt/config/CConfigFileBase.h>

#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace devslam::run {

struct RunConfig {
    std::string input;  ///< TUM folder or .rawlog
    std::string truth_file;  ///< where the reader's ground truth came from, if not the input
    /// --localize: localization only, in this map (slam::Slam::localizeIn), read from
    /// `localize_map` and checked against the INI's [orb] (slam::checkOrbMatches) before the
    /// input opened. runSequence moves its map into the SLAM (a map of 14 MB was held twice).
    std::shared_ptr<slam::MapFile> localize_in;
    std::string localize_map;
    /// --extend-map: with localize_in, map on from the first pose found in it.
    bool extend_map = false;
    bool save_map = true;  ///< write slam_map.yml (--no-slam-map: not)
    std::string mode = "dynamic";
    /// Named in front of the "[section] key: ..." errors of the SLAM INI (`cfg`) and of the
    /// filter's (`filter_cfg`): the files, and what was written over them.
    std::string config_source = "SLAM INI", filter_source = "filter INI";
    std::string out_dir;         ///< empty: write nothing
    bool progress = true;        ///< progress bar on stderr
    /// A frame that does not decode (an image that is there but damaged) is left out and the
    /// run goes on (--allow-damaged, as devslam-convert does); else the run stops before it.
    bool allow_damaged = false;
    std::size_t max_frames = 0;  ///< 0 = all
    /// Run the dynamic filter for frame k+1 in a second thread while the SLAM processes
    /// frame k (INI [run] async_filter). Results do not depend on timing.
    bool async_filter = true;
    /// Score each frame's mask against the renderer's person truth when the input folder
    /// has one (persons.txt + labels/, written by devslam-synth). Off for replayed inputs.
    bool score_masks = true;
    int min_person_pixels = 500;  ///< [px] smaller person instances are not scored
};

/// Wall time per stage of one frame [ms].
struct FrameTiming {
    double detect = 0, filter = 0, features = 0, tracking = 0, mapping = 0, backend = 0;
    [[nodiscard]] double total() const {
        return detect + filter + features + tracking + mapping + backend;
    }
};

struct FrameLog {
    std::size_t index = 0;
    double t = 0;
    std::string state, keyframe_reason;
    std::string lost_reason;  ///< why the frame has no tracked pose ("" when tracked)
    int n_features = 0, n_masked = 0, n_inliers = 0, n_boxes = 0, n_moving = 0;
    double masked_fraction = 0;  ///< of the image, by the dynamic mask
    /// With the renderer's person truth: the walking people's visible pixels in the frame and
    /// those the mask left open (-1: no truth). A walker partly outside its box shows here,
    /// not in the per-person recall, which counts them masked from half their area.
    double walker_px = -1, walker_px_unmasked = 0;
    bool keyframe = false, loop = false;
    bool ba_rejected = false;  ///< the keyframe's local BA was not applied (max_keyframe_shift)
    FrameTiming ms;      ///< per stage (detect/filter overlap the SLAM when async)
    double wall_ms = 0;  ///< wall time of the frame's pipeline step (disk reading excluded)
    double cpu_ms = 0;   ///< process CPU time (all threads) of that step
    double read_ms = 0, read_cpu_ms = 0;  ///< reading the next frame and scoring (excluded)
};

/// A loop the SLAM closed and, with ground truth, how far its measured relative pose is from
/// the true one (the loop's own error, whatever the trajectory's drift).
struct LoopReport {
    slam::Slam::ClosedLoop loop;
    std::optional<double> error_m, error_deg;
};

/// Scores each closed loop's measured relative pose against `ground_truth` (the poses nearest
/// in time to the two keyframes, within `max_dt` [s]; no error where either has none).
[[nodiscard]] std::vector<LoopReport> scoreLoops(const std::vector<slam::Slam::ClosedLoop>& loops,
                                                 const core::Trajectory* ground_truth,
                                                 double max_dt = 0.02);

struct RunReport {
    std::string input, mode, camera, mask_source;
    std::string input_damage;  ///< what of the input was unreadable and left out ("" = none)
    std::string truth_file;    ///< RunConfig::truth_file
    std::string localize_map;  ///< RunConfig::localize_map ("" = a map made by this run)
    bool extend_map = false;   ///< RunConfig::extend_map
    /// Localizing: the first frame that found its pose in the map (none: no frame did).
    std::optional<std::size_t> localized_at;
    /// Localizing with [tracker] place_recognition: the words of the vocabulary trained on
    /// the map, over how many keyframes, and the time it took with indexing them (0: none).
    int place_words = 0;
    std::size_t place_keyframes = 0;
    double place_index_ms = 0;
    /// A frame that failed to read during the run, or whose mask or person truth failed
    /// ("" = none): the run stopped there and its outputs hold the frames before it.
    std::string read_error;
    /// The signal (core/Interrupt.h) that stopped the run early ("SIGINT"; "" = none): its
    /// outputs hold the frames before it.
    std::string interrupted;
    /// Where the outputs went: RunConfig::out_dir, or its `stopped_run` subfolder for a run
    /// that stopped early where a whole earlier run's outputs were (kept, not replaced).
    std::string out_dir;
    bool async_filter = false;
    std::size_t frames = 0, keyframes = 0, landmarks = 0, loops = 0;
    std::size_t keyframes_culled = 0;  ///< redundant keyframes removed ([mapping])
    std::vector<std::size_t> lost;  ///< frame indices without a tracked pose
    std::size_t ba_runs = 0, ba_rejected = 0;  ///< local BAs, and those not applied
    double ba_max_shift = 0;  ///< [m] [local_ba] max_keyframe_shift (0 = off)
    std::vector<FrameLog> log;
    core::Trajectory trajectory, keyframe_trajectory;
    std::optional<core::Trajectory> ground_truth;
    std::optional<eval::AteResult> ate;
    /// Why there is no `ate` though there is ground truth (too few poses, no pose associated
    /// with the ground truth's stamps); "" otherwise.
    std::string ate_missing;
    std::string rpe_missing;  ///< why there is an ATE but no RPE (1 s), e.g. a run under 1 s
    std::optional<eval::RpeResult> rpe_1s, rpe_frame;
    double median_fps = 0, mean_fps = 0, median_ms = 0;
    double median_cpu_ms = 0;  ///< process CPU time per frame, all threads (load-independent)
    FrameTiming stage_mean_ms, stage_median_ms;
    double finalize_ms = 0;  ///< end-of-sequence BA + frame refinement (not in FPS)
    slam::LocalBaResult final_ba;  ///< the end-of-sequence BA (Slam::finalize)
    double peak_rss_mb = 0;  ///< VmHWM of the process at the end
    double map_mb = 0;       ///< approximate map heap
    double bytes_per_keyframe = 0;
    std::vector<std::string> outputs;  ///< files written
    /// Frames left out because they do not decode (RunConfig::allow_damaged): why, each.
    std::vector<std::string> undecodable;
    /// Outputs that could not be written ("cannot write 'PATH': No space left on device"):
    /// each output is tried on its own, so one that fails loses neither the others nor the
    /// figures.
    std::vector<std::string> output_errors;
    /// The masks scored against the person truth (rendered inputs only).
    std::optional<eval::MaskScore> mask_score;
    std::vector<LoopReport> loop_reports;  ///< every closed loop (loops.txt)
};

/// The files a run writes into its --out folder (an earlier run's are removed first).
inline constexpr const char* kOutputFiles[] = {
    "run.json",       "run.json.part",   "trajectory.txt", "keyframes.txt",    "lost_frames.txt",
    "loops.txt",      "map.ply",         "map.3Dscene",    "map_grid.png",     "map_grid.gridmap",
    "trajectory.png", "mask_errors.csv", "slam_map.yml",   "slam_map.yml.part"};

/// Throws unless each of kOutputFiles in `dir` is a file or not there: found before the run,
/// not after it (a folder named trajectory.png stopped the run's outputs, the earlier run's
/// all removed).
void checkOutputFolder(const std::string& dir);

/// Reads every setting a run in `rc.mode` reads from `cfg` and `filter_cfg` and makes its
/// filter and detector, as runSequence does before the first frame, throwing what it would
/// throw; reads no frame (mode truth, whose mask is the input's person truth, is checked as
/// dynamic: it reads the same sections). Given the input's `camera`, also refuses frames
/// smaller than the filter's flow window ([dynamic_filter] lk_window / flow_scale), which a
/// run would refuse at its first frame. devslam-run --check-config.
void checkConfig(const RunConfig& rc, const mrpt::config::CConfigFileBase& cfg,
                 const mrpt::config::CConfigFileBase& filter_cfg,
                 const std::optional<core::CameraIntrinsics>& camera = std::nullopt);

/// Runs the pipeline over `reader` with the INI `cfg` (SLAM sections) and `filter_cfg`
/// ([detector], [dynamic_filter]). Throws on setup errors (bad INI, unknown mode).
[[nodiscard]] RunReport runSequence(io::RgbdReader& reader, const RunConfig& rc,
                                    const mrpt::config::CConfigFileBase& cfg,
                                    const mrpt::config::CConfigFileBase& filter_cfg);

/// Human-readable summary (frames, keyframes, landmarks, lost, FPS, stages, ATE/RPE).
[[nodiscard]] std::string formatSummary(const RunReport& r);
/// All figures of the run as one JSON object.
[[nodiscard]] std::string toJson(const RunReport& r);
/// Resets the peak-RSS counter (each run reports its own peak).
void resetPeakRss();
/// Peak resident memory of this process [MB] (VmHWM), 0 if unknown.
[[nodiscard]] double peakRssMb();

}  // namespace devslam::run
