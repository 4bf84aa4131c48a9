#include "Pipeline.h"

#include "MaskSource.h"

#include <devslam/core/Config.h>
#include <devslam/core/GzFile.h>
#include <devslam/core/Interrupt.h>
#include <devslam/core/Pose.h>
#include <devslam/core/Progress.h>
#include <devslam/core/Results.h>
#include <devslam/core/Stats.h>
#include <devslam/eval/Report.h>
#include <devslam/io/TrajectoryIO.h>
#include <devslam/slam/MapExporter.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <functional>
#include <future>
#include <iostream>
#include <set>
#include <sstream>

namespace devslam::run {

namespace {
using Clock = std::chrono::steady_clock;
/// CPU time of the whole process (all threads) [ms].
double processCpuMs() {
    timespec ts{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

double msSince(Clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

std::string num(double v, int prec = 6) {
    char b[64];
    std::snprintf(b, sizeof b, "%.*f", prec, v);
    return b;
}

std::string summaryJson(const core::Summary& s) {
    return "{\"count\": " + std::to_string(s.count) + ", \"rmse\": " + num(s.rmse) +
           ", \"mean\": " + num(s.mean) + ", \"median\": " + num(s.median) +
           ", \"std\": " + num(s.std) + ", \"min\": " + num(s.min) + ", \"max\": " + num(s.max) +
           "}";
}

std::string timingJson(const FrameTiming& t) {
    return "{\"detect\": " + num(t.detect, 3) + ", \"filter\": " + num(t.filter, 3) +
           ", \"features\": " + num(t.features, 3) + ", \"tracking\": " + num(t.tracking, 3) +
           ", \"mapping\": " + num(t.mapping, 3) + ", \"backend\": " + num(t.backend, 3) +
           ", \"total\": " + num(t.total(), 3) + "}";
}
std::vector<double> loopErrors(const std::vector<LoopReport>& loops) {
    std::vector<double> e;
    for (const auto& l : loops)
        if (l.error_m) e.push_back(*l.error_m);
    return e;
}

}  // namespace

std::vector<LoopReport> scoreLoops(const std::vector<slam::Slam::ClosedLoop>& loops,
                                   const core::Trajectory* ground_truth, double max_dt) {
    std::vector<LoopReport> out;
    for (const auto& l : loops) {
        LoopReport r{l, std::nullopt, std::nullopt};
        if (ground_truth) {
            if (const auto e =
                    eval::relativePoseError(*ground_truth, l.t_old, l.t_new, l.T_old_new, max_dt)) {
                r.error_m = e->trans;
                r.error_deg = e->rot;
            }
        }
        out.push_back(r);
    }
    return out;
}

void resetPeakRss() {
    // Linux >= 4.0: writing 5 resets VmHWM to the current RSS; ignored where unsupported.
    std::ofstream f("/proc/self/clear_refs");
    if (f) f << "5";
}

double peakRssMb() {
    std::ifstream in("/proc/self/status");
    std::string line;
    while (std::getline(in, line))
        if (line.rfind("VmHWM:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;
    return 0.0;
}

namespace {
/// Whether `dir` holds the outputs of a run that went through its whole input.
bool holdsWholeRun(const std::string& dir) {
    std::ifstream in(std::filesystem::path(dir) / "run.json");
    if (!in) return false;
    std::stringstream ss;
    ss << in.rdbuf();
    const std::string j = ss.str();
    // run.json is written last, whole; a run that stopped says why in these two.
    return j.find("\"read_error\": \"\"") != std::string::npos &&
           j.find("\"interrupted\": \"\"") != std::string::npos;
}
}  // namespace

void checkOutputFolder(const std::string& dir) {
    namespace fs = std::filesystem;
    std::error_code ec;
    for (const char* f : kOutputFiles) {
        const fs::path p = fs::path(dir) / f;
        if (fs::exists(fs::symlink_status(p, ec)) &&
            !fs::is_regular_file(fs::symlink_status(p, ec)))
            throw std::runtime_error("'" + p.string() +
                                     "' is not a file: the run writes its output of that name "
                                     "there; move it or name another --out");
    }
}

namespace {
/// What a run is made of before its first frame, read from its INIs.
struct RunParts {
    slam::SlamOptions slam;
    slam::GridMapOptions grid;
    std::unique_ptr<MaskSource> masks;
};

RunParts readRunParts(const RunConfig& rc, const mrpt::config::CConfigFileBase& cfg,
                      const mrpt::config::CConfigFileBase& filter_cfg, const std::string& mode) {
    RunParts p;
    p.slam = core::namingSource(rc.config_source,
                                [&] { return slam::SlamOptions::fromConfig(cfg); });
    core::namingSource(rc.config_source, [&] { p.grid.loadFromConfig(cfg, "grid_map"); });
    p.masks = core::namingSource(rc.filter_source,
                                 [&] { return makeMaskSource(mode, filter_cfg, rc.input); });
    return p;
}
}  // namespace

void checkConfig(const RunConfig& rc, const mrpt::config::CConfigFileBase& cfg,
                 const mrpt::config::CConfigFileBase& filter_cfg,
                 const std::optional<core::CameraIntrinsics>& camera) {
    const RunParts parts =
        readRunParts(rc, cfg, filter_cfg, rc.mode == "truth" ? "dynamic" : rc.mode);
    if (!camera || rc.mode == "truth") return;
    const int need = parts.masks->minFrameSide();
    if (camera->width < need || camera->height < need)
        throw std::invalid_argument(
            rc.filter_source +
            ": [dynamic_filter] lk_window / flow_scale: the flow needs frames of at least " +
            std::to_string(need) + "x" + std::to_string(need) + " px; the input '" + rc.input +
            "' has " + std::to_string(camera->width) + "x" + std::to_string(camera->height));
}

RunReport runSequence(io::RgbdReader& reader, const RunConfig& rc,
                      const mrpt::config::CConfigFileBase& cfg,
                      const mrpt::config::CConfigFileBase& filter_cfg) {
    resetPeakRss();
    RunParts parts = readRunParts(rc, cfg, filter_cfg, rc.mode);
    const slam::SlamOptions& slam_opts = parts.slam;
    const slam::GridMapOptions& grid_opts = parts.grid;
    std::unique_ptr<MaskSource> masks = std::move(parts.masks);
    slam::Slam slam(slam_opts);
    // The camera slam_map.yml is written with: the input's, or a loaded map's own when it is
    // only localized in (its keyframes are that camera's).
    core::CameraIntrinsics map_camera = reader.intrinsics();
    double place_index_ms = 0;
    int place_words = 0;
    std::size_t place_keyframes = 0;
    if (rc.localize_in) {  // (its ORB pyramid was checked against the INI when it was read)
        if (rc.extend_map) slam::checkCameraMatches(*rc.localize_in, rc.localize_map, map_camera);
        map_camera = rc.localize_in->camera;
        const auto t0 = Clock::now();
        slam.localizeIn(std::move(rc.localize_in->map), rc.extend_map);
        if (const slam::PlaceIndex* place = slam.placeIndex()) {
            place_index_ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
            place_words = place->words();
            place_keyframes = place->keyframes();
        }
    }

    RunReport rep;
    rep.input = rc.input;
    rep.truth_file = rc.truth_file;
    if (rc.localize_in) {
        rep.localize_map = rc.localize_map;
        rep.extend_map = rc.extend_map;
        rep.place_words = place_words;
        rep.place_keyframes = place_keyframes;
        rep.place_index_ms = place_index_ms;
    }
    rep.input_damage = reader.damage();
    rep.mode = rc.mode;
    rep.mask_source = masks->describe();
    rep.async_filter = rc.async_filter;
    const auto K = reader.intrinsics();
    rep.camera = "fx=" + num(K.fx, 1) + " fy=" + num(K.fy, 1) + " cx=" + num(K.cx, 1) +
                 " cy=" + num(K.cy, 1) + " " + std::to_string(K.width) + "x" +
                 std::to_string(K.height);
    const std::size_t total = rc.max_frames ? std::min(rc.max_frames, reader.size().value_or(0))
                                            : reader.size().value_or(0);
    std::optional<eval::PersonTruth> truth;
    if (rc.score_masks) truth = eval::PersonTruth::open(rc.input);
    if (truth) rep.mask_score.emplace();
    std::optional<core::ProgressBar> bar;
    if (rc.progress) bar.emplace("devslam-run " + rc.mode, total);
    std::size_t n = 0;
    double elapsed_ms = 0;
    // With async_filter the filter works on frame k+1 in a second thread while the SLAM
    // processes frame k (its prior is the constant-velocity motion known before frame k).
    std::future<MaskStep> pending;
    auto launch = [&](const core::Frame& f, const std::optional<Eigen::Isometry3d>& prior) {
        pending =
            std::async(std::launch::async, [&masks, f, prior] { return masks->step(f, prior); });
    };
    auto within = [&](std::size_t i) { return rc.max_frames == 0 || i < rc.max_frames; };
    // The next frame; one that does not decode is left out with allow_damaged (the readers
    // pass it), else its error ends the run there. Nothing after a broken stream can be read.
    const auto readNext = [&] {
        return io::nextDecodable(reader, rc.allow_damaged, rep.undecodable);
    };
    std::optional<core::Frame> cur = readNext();
    if (cur) cur->index = 0;
    // A Ctrl-C before the first frame (while the detector loads): no frame done, nothing
    // written (an earlier run's results in the output folder stay as they are).
    if (core::stopSignal()) {
        rep.interrupted = core::signalName(core::stopSignal());
        return rep;
    }
    if (rc.async_filter && cur) launch(*cur, std::nullopt);
    while (cur && within(n)) {
        const auto t_iter = Clock::now();
        const double cpu_iter = processCpuMs();
        FrameLog fl;
        fl.index = n;
        fl.t = cur->timestamp;
        MaskStep ms;
        try {
            ms = rc.async_filter ? pending.get()
                                 : masks->step(*cur, slam.predictPrevCur(cur->timestamp));
        } catch (const eval::MissingTruth& e) {
            // Mode truth: no person truth for this frame, so no mask: stop before it and keep
            // the frames done, as for a frame that does not read. (Other errors of the mask
            // step are the program's, and end it.)
            rep.read_error = e.what();
            break;
        } catch (const std::invalid_argument& e) {
            // A frame the filter refuses (smaller than its flow window): the input named, as
            // a reader's error names it.
            throw std::invalid_argument(rc.input + ": " + e.what());
        }
        // Reading/decoding the next frame is not part of the pipeline time.
        const auto t_read = Clock::now();
        const double cpu_read = processCpuMs();
        std::optional<core::Frame> nxt;
        try {
            if (within(n + 1)) nxt = readNext();
        } catch (const std::exception& e) {
            // A frame damaged in a way the reader cannot see at open (an image that does not
            // decode): stop here and keep what was computed, instead of losing the whole run.
            rep.read_error = e.what();
        }
        // Ctrl-C (core/Interrupt.h): end before the next frame as at the end of the input,
        // keeping the frames done. A signal after the last frame leaves the run whole.
        if (nxt && core::stopSignal()) {
            rep.interrupted = core::signalName(core::stopSignal());
            nxt.reset();
        }
        if (nxt) nxt->index = n + 1;
        fl.read_ms = msSince(t_read);
        fl.read_cpu_ms = processCpuMs() - cpu_read;
        if (rc.async_filter && nxt)
            launch(*nxt, slam.predictMotion(nxt->timestamp - cur->timestamp));
        if (truth) {  // not part of the pipeline time either
            const auto t_score = Clock::now();
            const double cpu_score = processCpuMs();
            try {
                const double px0 = rep.mask_score->moving_px,
                             masked0 = rep.mask_score->moving_px_masked;
                truth->score(ms.mask, cur->timestamp, rc.min_person_pixels, *rep.mask_score,
                             ms.boxes);
                fl.walker_px = rep.mask_score->moving_px - px0;
                fl.walker_px_unmasked =
                    fl.walker_px - (rep.mask_score->moving_px_masked - masked0);
            } catch (const eval::MissingTruth& e) {
                // No person truth for this frame: this frame is the last (its SLAM step runs,
                // its mask is unscored), and the frames done are kept.
                rep.read_error = e.what();
                nxt.reset();
            }
            fl.read_ms += msSince(t_score);
            fl.read_cpu_ms += processCpuMs() - cpu_score;
        }
        fl.ms.detect = ms.detect_ms;
        fl.ms.filter = ms.filter_ms;
        fl.n_boxes = ms.n_boxes;
        fl.n_moving = ms.n_moving;
        auto t0 = Clock::now();
        auto feats = slam.extract(*cur, ms.mask);
        if (!ms.static_people.empty()) {
            feats.weighWhere(ms.static_people, static_cast<float>(ms.static_weight));
            feats.gate_exponent = ms.static_gate_exponent;
        }
        fl.ms.features = msSince(t0);
        fl.n_features = static_cast<int>(feats.size());
        fl.n_masked = feats.n_masked;
        fl.masked_fraction = feats.masked_fraction;
        t0 = Clock::now();
        const auto tr = slam.track(*cur, feats, std::nullopt);
        fl.ms.tracking = msSince(t0);
        t0 = Clock::now();
        const auto mr = slam.mapStep(*cur, std::move(feats), tr);
        fl.ms.mapping = msSince(t0);
        t0 = Clock::now();
        const auto br = slam.backendStep(mr, cur->K);
        fl.ms.backend = msSince(t0);
        fl.state = slam::toString(tr.state);
        if (!tr.pose_valid) fl.lost_reason = tr.reason;
        if (rc.localize_in && tr.pose_valid && !rep.localized_at) rep.localized_at = n;
        fl.n_inliers = tr.n_inliers;
        fl.keyframe = mr.keyframe_inserted;
        fl.ba_rejected = mr.ba.rejected;
        if (mr.ba.n_keyframes > 0) ++rep.ba_runs;
        rep.keyframes_culled += static_cast<std::size_t>(mr.culled_keyframes);
        if (mr.ba.rejected) ++rep.ba_rejected;
        fl.keyframe_reason = slam::toString(mr.reason);
        fl.loop = br.loop_closed;
        fl.wall_ms = msSince(t_iter) - fl.read_ms;
        fl.cpu_ms = processCpuMs() - cpu_iter - fl.read_cpu_ms;
        elapsed_ms += fl.wall_ms;
        rep.log.push_back(fl);
        ++n;
        cur = std::move(nxt);
        if (bar) {
            const double fps = elapsed_ms > 0 ? 1000.0 * n / elapsed_ms : 0.0;
            bar->update(n, num(fps, 1) + " fps, " + fl.state);
        }
    }
    if (pending.valid()) pending.wait();
    if (bar) bar->finish();
    {
        const auto t0 = Clock::now();
        if (!rep.log.empty()) rep.final_ba = slam.finalize(reader.intrinsics());
        rep.finalize_ms = msSince(t0);
    }

    rep.frames = n;
    rep.ba_max_shift = slam_opts.local_ba.max_keyframe_shift;
    rep.keyframes = slam.map().keyframes().size();
    rep.landmarks = slam.map().landmarks().size();
    rep.loops = static_cast<std::size_t>(slam.loopsClosed());
    rep.lost = slam.lostFrames();
    rep.trajectory = slam.trajectory();
    rep.keyframe_trajectory = slam.keyframeTrajectory();
    std::vector<double> fps, total_ms, cpu_ms;
    std::vector<double> st[6];
    for (const auto& l : rep.log) {
        const double t = l.wall_ms;
        cpu_ms.push_back(l.cpu_ms);
        total_ms.push_back(t);
        fps.push_back(t > 0 ? 1000.0 / t : 0.0);
        const double v[6] = {l.ms.detect,   l.ms.filter,  l.ms.features,
                             l.ms.tracking, l.ms.mapping, l.ms.backend};
        for (int k = 0; k < 6; ++k) st[k].push_back(v[k]);
    }
    rep.median_fps = core::median(fps);
    rep.median_ms = core::median(total_ms);
    rep.median_cpu_ms = core::median(cpu_ms);
    rep.mean_fps = elapsed_ms > 0 ? 1000.0 * n / elapsed_ms : 0.0;
    double* mean_fields[6] = {&rep.stage_mean_ms.detect,   &rep.stage_mean_ms.filter,
                              &rep.stage_mean_ms.features, &rep.stage_mean_ms.tracking,
                              &rep.stage_mean_ms.mapping,  &rep.stage_mean_ms.backend};
    double* med_fields[6] = {&rep.stage_median_ms.detect,   &rep.stage_median_ms.filter,
                             &rep.stage_median_ms.features, &rep.stage_median_ms.tracking,
                             &rep.stage_median_ms.mapping,  &rep.stage_median_ms.backend};
    for (int k = 0; k < 6; ++k) {
        *mean_fields[k] = core::summarize(st[k]).mean;
        *med_fields[k] = core::median(st[k]);
    }
    rep.map_mb = static_cast<double>(slam.map().approxBytes()) / (1024.0 * 1024.0);
    rep.bytes_per_keyframe =
        rep.keyframes ? static_cast<double>(slam.map().approxBytes()) / rep.keyframes : 0.0;

    rep.ground_truth = reader.groundTruth();
    // The ATE counts the lost frames' poses (motion-model predictions), but only beside
    // tracked ones: a run that never initialised (all-black frames, depth in other units)
    // scored its identity poses against the truth and printed that as its ATE.
    const std::size_t tracked =
        rep.trajectory.size() - std::min(rep.lost.size(), rep.trajectory.size());
    if (rep.ground_truth && rep.trajectory.size() < 3)
        rep.ate_missing = std::to_string(rep.trajectory.size()) + " poses (the ATE needs 3)";
    else if (rep.ground_truth && tracked < 3)
        rep.ate_missing = std::to_string(tracked) + " of " + std::to_string(rep.trajectory.size()) +
                          " frames tracked (the ATE needs 3)";
    bool scored = rep.ground_truth && rep.ate_missing.empty();
    if (scored) {
        try {
            rep.ate = eval::computeAte(*rep.ground_truth, rep.trajectory);
        } catch (const std::invalid_argument& e) {
            // (no association: ground truth of another sequence, stamps in other units) The
            // reason is kept: run.json alone did not tell it from a folder without ground truth.
            rep.ate_missing = e.what();
        }
        // ... and 3 tracked among the poses the ATE paired with the truth: a truth that
        // covered only lost frames scored their held poses, and printed that as the ATE.
        if (rep.ate) {
            std::set<double> lost_stamps;
            for (const std::size_t i : rep.lost)
                if (i < rep.trajectory.size()) lost_stamps.insert(rep.trajectory[i].t);
            const std::size_t paired = rep.ate->stamps.size();
            const auto paired_tracked = static_cast<std::size_t>(
                std::count_if(rep.ate->stamps.begin(), rep.ate->stamps.end(),
                              [&](double t) { return lost_stamps.count(t) == 0; }));
            if (paired_tracked < 3) {
                rep.ate_missing = std::to_string(paired_tracked) + " of the " +
                                  std::to_string(paired) +
                                  " poses the ground truth covers are tracked (the ATE needs 3; "
                                  "the others are lost frames' held poses)";
                rep.ate.reset();
                scored = false;
            }
        }
    }
    if (scored) {
        if (rep.ate) try {
                eval::RpeOptions one_s;
                rep.rpe_1s = eval::computeRpe(*rep.ground_truth, rep.trajectory, one_s);
            } catch (const std::invalid_argument& e) {
                rep.rpe_missing = e.what();  // (a run under 1 s: the line vanished without a word)
            }
        try {
            eval::RpeOptions per_frame;
            per_frame.delta = 1;
            per_frame.delta_in_frames = true;
            rep.rpe_frame = eval::computeRpe(*rep.ground_truth, rep.trajectory, per_frame);
        } catch (const std::invalid_argument&) {
        }
    }
    rep.loop_reports =
        scoreLoops(slam.closedLoops(), rep.ground_truth ? &*rep.ground_truth : nullptr);

    rep.out_dir = rc.out_dir;
    // A run that stopped early (a frame that does not read, Ctrl-C) replaced the whole run
    // an earlier command had left in the folder with its few frames: it goes beside it.
    if (!rc.out_dir.empty() && (!rep.read_error.empty() || !rep.interrupted.empty()) &&
        holdsWholeRun(rc.out_dir)) {
        rep.out_dir = (std::filesystem::path(rc.out_dir) / "stopped_run").string();
        try {
            std::error_code ec;
            if (std::filesystem::exists(rep.out_dir, ec) &&
                !std::filesystem::is_directory(rep.out_dir, ec))
                throw std::runtime_error("'" + rep.out_dir +
                                         "' is not a folder: the stopped run's outputs go there");
            checkOutputFolder(rep.out_dir);
        } catch (const std::exception& e) {
            rep.output_errors.push_back(e.what());
            rep.out_dir.clear();  // nothing written; the earlier run stays whole
        }
    }
    if (!rep.out_dir.empty()) {
        namespace fs = std::filesystem;
        fs::create_directories(rep.out_dir);
        // An earlier run's outputs go first: a run that writes fewer (no ATE plot without
        // ground truth, no mask errors without person truth) or is killed while writing
        // leaves none of them beside its own. run.json comes last and says they are whole.
        // (Not the map this run was given to localize in, when it is this folder's: it is
        // replaced whole below, and a write that fails must not lose it.)
        for (const char* f : kOutputFiles) {
            const fs::path old = fs::path(rep.out_dir) / f;
            std::error_code ec;
            if (!rc.localize_map.empty() && std::string(f) == "slam_map.yml" &&
                fs::equivalent(old, rc.localize_map, ec))
                continue;
            fs::remove(old);
        }
        auto out = [&](const std::string& name) { return (fs::path(rep.out_dir) / name).string(); };
        // Each output on its own: one that cannot be written (a full disk) is named in
        // output_errors, and the others are still tried; the figures are printed whatever.
        const auto write = [&](const std::string& path, const std::function<void()>& fn) {
            try {
                fn();
                rep.outputs.push_back(path);
            } catch (const std::exception& e) {
                rep.output_errors.push_back(core::innermostMessage(e.what()));
            }
        };
        std::string lost_note =
            "lost frames (motion-model pose): " + std::to_string(rep.lost.size());
        write(out("trajectory.txt"), [&] {
            io::writeTumTrajectory(
                out("trajectory.txt"), rep.trajectory,
                "DEV-SLAM per-frame trajectory, mode " + rc.mode + "; " + lost_note);
        });
        write(out("keyframes.txt"), [&] {
            io::writeTumTrajectory(out("keyframes.txt"), rep.keyframe_trajectory,
                                   "DEV-SLAM keyframe trajectory, mode " + rc.mode);
        });
        {
            std::ostringstream lf;  // each file written whole, or an error
            lf << "# index timestamp reason (frames without a tracked pose)\n";
            for (std::size_t i : rep.lost) {
                lf << i << " " << num(rep.trajectory[i].t, 6);
                if (i < rep.log.size() && !rep.log[i].lost_reason.empty())
                    lf << " " << rep.log[i].lost_reason;
                lf << "\n";
            }
            write(out("lost_frames.txt"),
                  [&] { core::writeFileWhole(out("lost_frames.txt"), lf.str()); });
        }
        {
            std::ostringstream lp;
            lp << "# loops closed: t_old t_new inliers, measured T_old_new (tx ty tz qx qy qz qw), "
                  "its error against the ground truth [m] [deg] (- without truth)\n";
            for (const auto& l : rep.loop_reports) {
                const Eigen::Quaterniond q(l.loop.T_old_new.linear());
                const Eigen::Vector3d& t = l.loop.T_old_new.translation();
                lp << num(l.loop.t_old, 6) << " " << num(l.loop.t_new, 6) << " " << l.loop.inliers
                   << " " << num(t.x()) << " " << num(t.y()) << " " << num(t.z()) << " "
                   << num(q.x(), 7) << " " << num(q.y(), 7) << " " << num(q.z(), 7) << " "
                   << num(q.w(), 7) << " " << (l.error_m ? num(*l.error_m) : "-") << " "
                   << (l.error_deg ? num(*l.error_deg, 3) : "-") << "\n";
            }
            write(out("loops.txt"), [&] { core::writeFileWhole(out("loops.txt"), lp.str()); });
        }
        write(out("map.ply"), [&] { slam::writePly(out("map.ply"), slam.map()); });
        // The map to localize in later (--localize); a localizing run writes the map it used.
        // None without a keyframe (nothing could localize in it).
        if (rc.save_map && slam.map().empty())
            std::cerr << "devslam-run: slam_map.yml not written: the map has no keyframe\n";
        else if (rc.save_map)
            write(out("slam_map.yml"), [&] {
                slam::saveMap(out("slam_map.yml"), slam.map(), slam_opts.orb, map_camera);
            });
        std::optional<core::Trajectory> gt_in_est;
        if (rep.ate && rep.ground_truth) {
            // Ground truth brought into the SLAM frame for the 3D view.
            const Eigen::Isometry3d T_est_gt = rep.ate->T_gt_est.inverse();
            core::Trajectory g;
            for (const auto& sp : *rep.ground_truth) {
                if (sp.t < rep.trajectory.front().t - 0.05 || sp.t > rep.trajectory.back().t + 0.05)
                    continue;
                g.push_back({sp.t, core::toCPose3D(T_est_gt * core::toIsometry(sp.pose))});
            }
            gt_in_est = g;
        }
        write(out("map.3Dscene"), [&] {
            slam::write3DScene(out("map.3Dscene"), slam.map(), rep.trajectory, gt_in_est);
        });
        // A grid too large for its [grid_map] resolution is left out, not the run's other
        // outputs.
        std::optional<mrpt::maps::COccupancyGridMap2D> grid;
        try {
            grid = slam::buildOccupancyGrid(slam.map(), grid_opts);
        } catch (const std::invalid_argument& e) {
            std::cerr << "devslam-run: map_grid not written: " << e.what() << "\n";
        }
        // (it was left out without a word)
        if (!grid && (rep.keyframes == 0 || slam.map().landmarks().empty()))
            std::cerr << "devslam-run: map_grid not written: the map has no "
                      << (rep.keyframes == 0 ? "keyframe" : "landmark") << "\n";
        if (grid) {
            const std::string stem = (fs::path(rep.out_dir) / "map_grid").string();
            const std::size_t errors = rep.output_errors.size();
            write(stem + ".png", [&] { slam::saveGrid(*grid, stem); });
            if (rep.output_errors.size() == errors) rep.outputs.push_back(stem + ".gridmap");
        }
        if (rep.ate)
            write(out("trajectory.png"), [&] {
                // The input's name, also when given with a trailing '/' (the title was empty).
                const fs::path in = fs::path(rc.input).lexically_normal();
                const std::string name =
                    (in.has_filename() ? in.filename() : in.parent_path().filename()).string();
                eval::plotAte(out("trajectory.png"), *rep.ate, name + ", mode " + rc.mode);
            });
        if (rep.mask_score) {
            std::ostringstream mf;
            mf << "# person instances the masks got wrong (renderer truth): walkers not masked, "
                  "static people masked. filter_box: state of the filter box covering most of "
                  "the person (none: no box covers "
               << num(100 * eval::MaskScore::min_box_cover, 0)
               << " % of them, the detector missed them)\ntimestamp,frame,person_id,truth,"
                  "visible_px,masked_fraction,filter_box,box_cover\n";
            // The errors are in frame order: one running index finds each one's frame.
            std::size_t frame = 0;
            for (const auto& e : rep.mask_score->errors) {
                while (frame + 1 < rep.log.size() && rep.log[frame].t < e.timestamp - 1e-6) ++frame;
                mf << num(e.timestamp, 6) << "," << frame << "," << e.person_id << ","
                   << (e.moving ? "moving" : "static") << "," << e.visible_pixels << ","
                   << num(e.masked_fraction, 3) << "," << e.filter_box << "," << num(e.box_cover, 2)
                   << "\n";
            }
            write(out("mask_errors.csv"),
                  [&] { core::writeFileWhole(out("mask_errors.csv"), mf.str()); });
        }
        rep.peak_rss_mb = peakRssMb();
        // run.json says the outputs are whole: not written beside ones that are not (it would
        // pass the run for a whole one, to devslam-bench too).
        if (rep.output_errors.empty())
            write(out("run.json"), [&] { core::writeFileWhole(out("run.json"), toJson(rep)); });
    }
    rep.peak_rss_mb = peakRssMb();
    return rep;
}

std::string formatSummary(const RunReport& r) {
    std::ostringstream o;
    o << "input      : " << r.input << "\n";
    if (!r.truth_file.empty()) o << "truth      : " << r.truth_file << " (--groundtruth)\n";
    if (!r.input_damage.empty()) o << "left out   : " << r.input_damage << "\n";
    if (!r.undecodable.empty())
        o << "left out   : " << r.undecodable.size()
          << " frames that do not decode (--allow-damaged), the first: " << r.undecodable.front()
          << "\n";
    if (!r.read_error.empty())
        o << "STOPPED    : after " << r.frames << " frames: " << r.read_error << "\n";
    if (!r.interrupted.empty())
        o << "STOPPED    : after " << r.frames << " frames: interrupted (" << r.interrupted
          << ")\n";
    o << "mode       : " << r.mode << " (" << r.mask_source
      << (r.async_filter ? ", filter one frame ahead in a second thread" : "") << ")\n"
      << "camera     : " << r.camera << "\n"
      << "frames     : " << r.frames << "   keyframes: " << r.keyframes
      << (r.keyframes_culled ? " (" + std::to_string(r.keyframes_culled) + " culled)" : "")
      << "   landmarks: " << r.landmarks << "   loops closed: " << r.loops << "\n";
    if (!r.localize_map.empty() && r.localized_at)
        o << "localized  : in " << r.localize_map << " from frame " << *r.localized_at
          << (r.extend_map ? ", and mapped on from there (--extend-map)"
                           : " (its keyframes and landmarks kept as they were)")
          << "\n";
    else if (!r.localize_map.empty())
        o << "localized  : NOT in " << r.localize_map << ": no frame found its pose in the map"
          << (r.extend_map ? " (--extend-map: nothing mapped)" : "") << "\n";
    if (r.place_words > 0)
        o << "place index: " << r.place_words << " words over " << r.place_keyframes
          << " keyframes, trained on the map in " << num(r.place_index_ms, 0)
          << " ms ([tracker] place_recognition)\n";
    if (const auto e = loopErrors(r.loop_reports); !e.empty()) {
        const auto s = core::summarize(e);
        o << "loops      : measured relative poses vs truth: median " << num(1000 * s.median, 1)
          << " mm, max " << num(1000 * s.max, 1) << " mm"
          << (r.out_dir.empty() ? "" : " (loops.txt)") << "\n";  // (--out '' writes none)
    }
    o << "lost frames: " << r.lost.size();
    if (!r.lost.empty()) {
        o << " (indices:";
        for (std::size_t i = 0; i < r.lost.size() && i < 20; ++i) o << " " << r.lost[i];
        if (r.lost.size() > 20) o << " ...";
        o << ")";
        // Why, for the first of them (lost_frames.txt and run.json give each frame's): 32 lost
        // frames that never initialised said nothing of the 0 keypoints with depth.
        const std::size_t first = r.lost.front();
        if (first < r.log.size() && !r.log[first].lost_reason.empty())
            o << "\n             first (" << first << "): " << r.log[first].lost_reason;
    }
    o << "\n";
    if (r.ba_rejected > 0)
        o << "local BA   : " << r.ba_rejected << " of " << r.ba_runs
          << " optimisations not applied (a keyframe would have moved > "
          << num(r.ba_max_shift, 3) << " m)\n";
    o << "speed      : median " << num(r.median_fps, 1) << " FPS (" << num(r.median_ms, 1)
      << " ms/frame), mean " << num(r.mean_fps, 1) << " FPS (wall clock)\n"
      << "cpu time   : median " << num(r.median_cpu_ms, 1)
      << " ms/frame, all threads (load-independent; = "
      << num(r.median_cpu_ms > 0 ? 1000.0 / r.median_cpu_ms : 0.0, 1) << " FPS on one free core)\n"
      << "stages [ms]: median / mean\n";
    const char* names[6] = {"detect", "filter", "features", "tracking", "mapping", "backend"};
    const double med[6] = {r.stage_median_ms.detect,   r.stage_median_ms.filter,
                           r.stage_median_ms.features, r.stage_median_ms.tracking,
                           r.stage_median_ms.mapping,  r.stage_median_ms.backend};
    const double mean[6] = {r.stage_mean_ms.detect,   r.stage_mean_ms.filter,
                            r.stage_mean_ms.features, r.stage_mean_ms.tracking,
                            r.stage_mean_ms.mapping,  r.stage_mean_ms.backend};
    for (int k = 0; k < 6; ++k) {
        char line[96];
        std::snprintf(line, sizeof line, "  %-9s %8.2f / %8.2f\n", names[k], med[k], mean[k]);
        o << line;
    }
    o << "finalize   : " << num(r.finalize_ms, 1)
      << " ms once at the end (final BA and frame refinement; not in the FPS)\n";
    if (const auto& b = r.final_ba; b.n_keyframes > 0) {
        o << "final BA   : " << b.n_keyframes << " keyframes, " << b.n_landmarks
          << " landmarks, largest keyframe shift " << num(1000 * b.max_shift, 1) << " mm";
        if (b.rejected)
            o << ": not applied (over [local_ba] max_keyframe_shift " << num(r.ba_max_shift, 3)
              << " m)";
        o << "\n";
    }
    o << "memory     : peak RSS " << num(r.peak_rss_mb, 1) << " MB, map " << num(r.map_mb, 2)
      << " MB (" << num(r.bytes_per_keyframe / 1024.0, 1) << " KiB per keyframe)\n";
    if (r.ate) {
        o << "ATE        : RMSE " << num(r.ate->trans.rmse, 4) << " m, mean "
          << num(r.ate->trans.mean, 4) << " m, median " << num(r.ate->trans.median, 4) << " m, max "
          << num(r.ate->trans.max, 4) << " m (" << r.ate->trans.count
          << (r.ate->trans.count < r.trajectory.size()
                  ? " of " + std::to_string(r.trajectory.size()) +
                        " poses: the others have no ground-truth pose left to pair with;"
                  : std::string(" poses,"))
          << " lost frames included)\n";
    } else if (r.ground_truth) {
        o << "ATE        : not computed (" << r.ate_missing << ")\n";
    } else {
        o << "ATE        : no ground truth\n";
    }
    if (r.rpe_1s)
        o << "RPE (1 s)  : trans RMSE " << num(r.rpe_1s->trans.rmse, 4) << " m, rot RMSE "
          << num(r.rpe_1s->rot.rmse, 3) << " deg (" << r.rpe_1s->n_pairs << " pairs)\n";
    else if (!r.rpe_missing.empty())
        o << "RPE (1 s)  : not computed (" << r.rpe_missing << ")\n";
    if (r.rpe_frame)
        o << "RPE (1 f)  : trans RMSE " << num(r.rpe_frame->trans.rmse, 4) << " m, rot RMSE "
          << num(r.rpe_frame->rot.rmse, 3) << " deg (" << r.rpe_frame->n_pairs << " pairs)\n";
    if (r.mask_score && r.mode == "none") {
        o << "masks      : none (mode none)\n";
    } else if (r.mask_score) {
        const auto& m = *r.mask_score;
        o << "masks      : ";
        if (m.moving_instances > 0)
            o << "walking people masked in " << num(100.0 * m.movingRecall(), 1) << " % of "
              << m.moving_instances << " person-frames (" << num(100.0 * m.movingAreaRecall(), 1)
              << " % of their area), ";
        else
            o << "no walking people, ";
        if (m.static_instances > 0)
            o << "static people in " << num(100.0 * m.staticMasked(), 1) << " % of "
              << m.static_instances << "; ";
        else
            o << "no static people; ";
        if (m.masked_px > 0)
            o << num(100.0 * m.precision(), 1)
              << " % of the masked area is on walking people (renderer truth)\n";
        else
            o << "nothing masked (renderer truth)\n";
        const std::size_t missed = m.moving_instances - m.moving_masked;
        if (missed > 0)
            o << "             of the " << missed << " walker-frames not masked, "
              << m.movingMissedWithoutBox()
              << " had no filter box (detector miss), the rest a box judged not moving "
                 "(mask_errors.csv)\n";
    }
    if (!r.outputs.empty()) {
        o << "outputs    :";
        for (const auto& p : r.outputs) o << "\n  " << p;
        o << "\n";
    }
    return o.str();
}

std::string toJson(const RunReport& r) {
    std::ostringstream o;
    // A JSON string: '"' and '\' escaped, and every control character (a tab or newline in
    // a path or an error message made the file invalid JSON).
    auto esc = [](const std::string& s) {
        std::string e;
        for (char c : s) {
            if (static_cast<unsigned char>(c) < 0x20) {
                char u[8];
                std::snprintf(u, sizeof u, "\\u%04x", static_cast<unsigned>(c));
                e += u;
                continue;
            }
            if (c == '"' || c == '\\') e += '\\';
            e += c;
        }
        return e;
    };
    o << "{\n  \"input\": \"" << esc(r.input) << "\",\n  \"groundtruth_file\": \""
      << esc(r.truth_file) << "\",\n  \"localize_map\": \"" << esc(r.localize_map)
      << "\",\n  \"extend_map\": " << (r.extend_map ? "true" : "false")
      << ",\n  \"localized_from_frame\": "
      << (r.localized_at ? std::to_string(*r.localized_at) : std::string("null"))
      << ",\n  \"place_index\": "
      << (r.place_words > 0 ? "{\"words\": " + std::to_string(r.place_words) +
                                  ", \"keyframes\": " + std::to_string(r.place_keyframes) +
                                  ", \"build_ms\": " + num(r.place_index_ms, 1) + "}"
                            : std::string("null"))
      << ",\n  \"input_damage\": \"" << esc(r.input_damage) << "\",\n  \"read_error\": \""
      << esc(r.read_error) << "\",\n  \"interrupted\": \"" << r.interrupted << "\",\n  \"mode\": \""
      << r.mode << "\",\n  \"mask_source\": \"" << esc(r.mask_source)
      << "\",\n  \"frames\": " << r.frames << ",\n  \"keyframes\": " << r.keyframes
      << ",\n  \"keyframes_culled\": " << r.keyframes_culled
      << ",\n  \"landmarks\": " << r.landmarks << ",\n  \"local_ba_runs\": " << r.ba_runs
      << ",\n  \"local_ba_rejected\": " << r.ba_rejected << ",\n  \"loops_closed\": " << r.loops
      << ",\n  \"lost_frames\": " << r.lost.size() << ",\n  \"lost_frame_indices\": [";
    for (std::size_t i = 0; i < r.lost.size(); ++i) o << (i ? ", " : "") << r.lost[i];
    o << "],\n  \"median_fps\": " << num(r.median_fps, 2)
      << ",\n  \"median_cpu_ms\": " << num(r.median_cpu_ms, 3)
      << ",\n  \"mean_fps\": " << num(r.mean_fps, 2)
      << ",\n  \"stage_median_ms\": " << timingJson(r.stage_median_ms)
      << ",\n  \"stage_mean_ms\": " << timingJson(r.stage_mean_ms)
      << ",\n  \"finalize_ms\": " << num(r.finalize_ms, 3)
      << ",\n  \"final_ba\": {\"keyframes\": " << r.final_ba.n_keyframes
      << ", \"landmarks\": " << r.final_ba.n_landmarks
      << ", \"max_shift_m\": " << num(r.final_ba.max_shift, 6)
      << ", \"rejected\": " << (r.final_ba.rejected ? "true" : "false") << "}"
      << ",\n  \"peak_rss_mb\": " << num(r.peak_rss_mb, 1)
      << ",\n  \"map_mb\": " << num(r.map_mb, 3)
      << ",\n  \"bytes_per_keyframe\": " << num(r.bytes_per_keyframe, 0);
    if (r.ate) o << ",\n  \"ate\": " << summaryJson(r.ate->trans);
    if (!r.ate && r.ground_truth) o << ",\n  \"ate_missing\": \"" << esc(r.ate_missing) << "\"";
    if (!r.rpe_missing.empty())
        o << ",\n  \"rpe_1s_missing\": \"" << esc(r.rpe_missing) << "\"";
    if (const auto e = loopErrors(r.loop_reports); !e.empty())
        o << ",\n  \"loop_error_m\": " << summaryJson(core::summarize(e));
    if (r.mask_score) {
        const auto& m = *r.mask_score;
        o << ",\n  \"mask_truth\": {\"moving_recall\": " << num(m.movingRecall())
          << ", \"moving_area_recall\": " << num(m.movingAreaRecall())
          << ", \"precision\": " << num(m.precision())
          << ", \"static_masked\": " << num(m.staticMasked())
          << ", \"moving_instances\": " << m.moving_instances
          << ", \"static_instances\": " << m.static_instances
          << ", \"moving_missed_without_box\": " << m.movingMissedWithoutBox() << "}";
    }
    if (r.rpe_1s)
        o << ",\n  \"rpe_1s\": {\"trans\": " << summaryJson(r.rpe_1s->trans)
          << ", \"rot_deg\": " << summaryJson(r.rpe_1s->rot) << "}";
    if (r.rpe_frame)
        o << ",\n  \"rpe_1frame\": {\"trans\": " << summaryJson(r.rpe_frame->trans)
          << ", \"rot_deg\": " << summaryJson(r.rpe_frame->rot) << "}";
    o << ",\n  \"per_frame\": [";
    for (std::size_t i = 0; i < r.log.size(); ++i) {
        const auto& l = r.log[i];
        o << (i ? ",\n    " : "\n    ") << "{\"index\": " << l.index << ", \"t\": " << num(l.t, 6)
          << ", \"state\": \"" << l.state << "\""
          << (l.lost_reason.empty() ? std::string()
                                    : ", \"reason\": \"" + esc(l.lost_reason) + "\"")
          << ", \"features\": " << l.n_features
          << ", \"masked\": " << l.n_masked << ", \"masked_area\": " << num(l.masked_fraction, 3);
        if (l.walker_px >= 0)
            o << ", \"walker_px\": " << num(l.walker_px, 0)
              << ", \"walker_px_unmasked\": " << num(l.walker_px_unmasked, 0);
        o
          << ", \"inliers\": " << l.n_inliers << ", \"boxes\": " << l.n_boxes
          << ", \"moving\": " << l.n_moving << ", \"keyframe\": " << (l.keyframe ? "true" : "false")
          << ", \"keyframe_reason\": \"" << l.keyframe_reason << "\""
          << (l.ba_rejected ? ", \"ba_rejected\": true" : "")
          << ", \"wall_ms\": " << num(l.wall_ms, 3) << ", \"cpu_ms\": " << num(l.cpu_ms, 3)
          << ", \"ms\": " << timingJson(l.ms) << "}";
    }
    o << "\n  ]\n}\n";
    return o.str();
}

}  // namespace devslam::run
