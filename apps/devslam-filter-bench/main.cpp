// devslam-filter-bench: speed of the person detectors and of the dynamic-object filter at
// 640x480, and the accuracy/speed trade-off of detecting every k-th frame on the synthetic
// sequences (real detector, exact truth). Writes the `detect` section of docs/RESULTS.md.
//
//   devslam-filter-bench                      # defaults below, writes docs/RESULTS.md
//   devslam-filter-bench --threads 1 --frames 30 --results FILE|none
#include <devslam/core/Config.h>
#include <devslam/core/Interrupt.h>
#include <devslam/core/Parse.h>
#include <devslam/core/Progress.h>
#include <devslam/core/Results.h>
#include <devslam/core/Stats.h>
#include <devslam/detect/PersonDetector.h>
#include <devslam/dynamic/DynamicObjectFilter.h>
#include <devslam/dynamic/ShiTomasi.h>
#include <devslam/dynamic/SyntheticSequence.h>
#include <devslam/io/RgbdReader.h>

#include <malloc.h>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <iostream>
#include <iterator>
#include <optional>
#include <sstream>
#include <string>
#include <tuple>

using namespace devslam;

namespace {
const std::string kRoot = DEVSLAM_SOURCE_DIR;
const char* kUsage =
    "usage: devslam-filter-bench [--threads N] [--frames N] [--config INI] [--results FILE|none]\n";

double msSince(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

/// CPU time of the calling thread [ms]: with --threads 1 OpenCV runs its loops in this
/// thread, so this is robust to other processes sharing the cores.
double threadCpuMs() {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

std::string fmt(double v, int prec = 1) {
    char b[32];
    std::snprintf(b, sizeof b, "%.*f", prec, v);
    return b;
}

/// Runs `f` with OpenCV at `n` threads, then restores the previous setting.
template <class F>
auto withThreads(int n, F&& f) {
    const int before = cv::getNumThreads();
    cv::setNumThreads(n);
    struct Restore {
        int n;
        ~Restore() { cv::setNumThreads(n); }
    } restore{before};
    return f();
}

/// The filter's per-stage times (FilterOutput::stage_ms) over many steps.
struct StageSamples {
    static constexpr const char* kNames[] = {
        "images: grey, scaling, LK pyramid, kept for the next step",
        "corners: Shi-Tomasi map and selection",
        "flow: pyramidal LK, forward and back",
        "boxes: carrying, association, person depths",
        "ego-motion: 3D points, PnP-RANSAC",
        "residual flow and threshold",
        "per-box evidence and states",
        "mask"};
    static_assert(std::size(kNames) ==
                  std::tuple_size_v<decltype(dynamic::FilterOutput::StageTimes{}.values())>);
    std::vector<double> ms[std::size(kNames)];
    void add(const dynamic::FilterOutput::StageTimes& t) {
        const auto v = t.values();
        for (std::size_t i = 0; i < v.size(); ++i) ms[i].push_back(v[i]);
    }
};

/// Detector that returns the true box (times the filter alone on synthetic data).
class TruthDetector : public detect::PersonDetector {
  public:
    std::vector<detect::Detection> next;
    std::vector<detect::Detection> detect(const cv::Mat&) override { return next; }
    std::string name() const override { return "truth"; }
};

/// Per-frame wall and thread-CPU times [ms] of `det` over `frames`, after three warm-up runs.
struct DetectorTimes {
    std::vector<double> ms, cpu;
};
DetectorTimes timeDetector(detect::PersonDetector& det, const std::vector<core::Frame>& frames,
                           core::ProgressBar* bar = nullptr) {
    for (int w = 0; w < 3; ++w) (void)det.detect(frames.front().bgr);  // warm-up
    DetectorTimes t;
    for (const auto& f : frames) {
        const auto t0 = std::chrono::steady_clock::now();
        const double c0 = threadCpuMs();
        (void)det.detect(f.bgr);
        t.cpu.push_back(threadCpuMs() - c0);
        t.ms.push_back(msSince(t0));
        if (bar) bar->update(t.ms.size());
    }
    return t;
}

struct TradeOff {
    int frames = 0, walking_moving = 0, static_ok = 0, none_flagged = 0;
    // Frames 1..N-1 of each sequence that show its person (the rates' denominators): on a
    // long --frames the people leave the view, and those frames are no miss of the filter.
    int walking_seen = 0, standing_seen = 0, empty_frames = 0;
    double iou_sum = 0;
    int iou_n = 0;
    std::vector<double> total_ms;
};

/// The command line.
struct Args {
    int threads = 1, n_frames = 30;
    std::string results = kRoot + "/docs/RESULTS.md";  ///< "none": no file
    std::string filter_ini = kRoot + "/config_ini/dynamic_filter.ini";
};

/// Reads the command line into `a`; the exit code when the program should end here (0 after
/// --help, 2 for a bad argument, said on stderr).
std::optional<int> parseArgs(int argc, char** argv, Args& a) {
    try {
        devslam::core::refuseRepeatedOptions(argc, argv);
        for (int i = 1; i < argc; ++i) {
            const std::string k = argv[i];
            const auto value = [&] { return devslam::core::optionValue(argc, argv, i); };
            if (k == "--threads")
                a.threads = int(devslam::core::parseInteger(value(), "--threads", 1, 256));
            else if (k == "--frames")
                a.n_frames = int(devslam::core::parseInteger(value(), "--frames", 2,
                                                             dynamic::kMaxSyntheticFrames));
            else if (k == "--results")
                a.results = value();
            else if (k == "--config")
                a.filter_ini = value();
            else if (k == "-h" || k == "--help") {
                std::cout << kUsage
                          << "  the detectors and the dynamic-object filter on synthetic and "
                             "shipped frames;\n  writes the 'detect' section of --results "
                             "(default docs/RESULTS.md)\n"
                             "  defaults: --threads 1 (OpenCV threads), --frames 30 (of each "
                             "synthetic sequence),\n  --config config_ini/dynamic_filter.ini\n";
                return 0;
            } else {
                std::cerr << "devslam-filter-bench: unknown argument '" << k << "'\n" << kUsage;
                return 2;
            }
        }
    } catch (const std::invalid_argument& e) {
        std::cerr << "devslam-filter-bench: " << e.what() << "\n";
        return 2;
    }
    return std::nullopt;
}

/// The frames the sections run on: the shipped real ones (640x480) and the synthetic
/// sequences (TUM wall, pasted person.jpg) of the input sweep, the filter's timing and the
/// detect_every trade-off.
struct Frames {
    std::vector<core::Frame> tum;
    std::vector<dynamic::SyntheticFrame> walking, standing, empty;
    cv::Mat person_jpg;
};

Frames loadFrames(int n_frames) {
    Frames f;
    auto reader = io::openRgbd(kRoot + "/data/tum/fr1_xyz_first37", {});
    while (auto fr = reader->next()) f.tum.push_back(*fr);
    const cv::Mat wall = cv::imread(kRoot + "/data/tum/fr1_xyz_first37/rgb/1305031102.175304.png");
    f.person_jpg = cv::imread(kRoot + "/data/images/person.jpg");
    const cv::Mat person = f.person_jpg(cv::Rect(180, 90, 105, 295)).clone();
    auto render = [&](dynamic::PersonMotion m) {
        dynamic::SyntheticOptions so;
        so.n_frames = n_frames;
        so.person = m;
        if (m == dynamic::PersonMotion::Static) so.person_x0 = 0.3;
        return dynamic::makeSyntheticSequence(so, wall, person);
    };
    f.walking = render(dynamic::PersonMotion::Walking);
    f.standing = render(dynamic::PersonMotion::Static);
    f.empty = render(dynamic::PersonMotion::None);
    return f;
}

/// 1. The detectors on the real frames, with one and with all OpenCV threads; each YOLO
/// model also with all its convolutions by OpenCV (fast_convolutions = false), measured right
/// after the default, for the ratio.
std::string detectorsSection(const Frames& fr, int all_threads) {
    std::ostringstream md;
    md << "| detector | INI | median ms | mean ms | median thread-CPU ms | frames | median ms, "
       << all_threads << " OpenCV threads (devslam-run's setting) |\n"
       << "|---|---|---|---|---|---|---|\n";
    const std::vector<std::pair<std::string, bool>> detectors{
        {"detector_yolo_fastest.ini", true},
        {"detector_yolo_fastest.ini", false},
        {"detector_yolo_fastest_small.ini", true},
        {"detector_yolo_fastest_small.ini", false},
        {"detector_hog.ini", true}};
    for (const auto& [ini_file, fast] : detectors) {
        auto cfg = core::loadIni(kRoot + "/config_ini/" + ini_file);
        std::string ini = ini_file;
        if (!fast) {
            cfg->write("detector", "fast_convolutions", false);
            ini += ", `fast_convolutions = false`";
        }
        auto det = detect::makeDetector(*cfg);
        core::ProgressBar bar("detector " + det->name(), fr.tum.size());
        const auto t = timeDetector(*det, fr.tum, &bar);
        bar.finish();
        const auto t_all = withThreads(all_threads, [&] { return timeDetector(*det, fr.tum); });
        const auto s = core::summarize(t.ms);
        md << "| " << det->name() << " | " << ini << " | " << fmt(s.median) << " | " << fmt(s.mean)
           << " | " << fmt(core::median(t.cpu)) << " | " << t.ms.size() << " | "
           << fmt(core::median(t_all.ms)) << " |\n";
    }
    return md.str();
}

/// 1b. The default model at smaller network inputs: speed against accuracy (the hand box of
/// person.jpg, no person in dog.jpg, the person of the synthetic frames).
std::string inputSweepSection(const Frames& fr, int all_threads) {
    const cv::Mat dog_jpg = cv::imread(kRoot + "/data/images/dog.jpg");
    const cv::Rect2f person_box(190.f, 98.f, 85.f, 277.f);  // as tests/detect
    std::vector<const dynamic::SyntheticFrame*> sweep_frames;
    for (const auto* seq : {&fr.walking, &fr.standing})
        for (const auto& f : *seq)
            if (f.person_box) sweep_frames.push_back(&f);
    std::ostringstream md;
    md << "\n**Default model (Yolo-Fastest-XL) at smaller network inputs** (the 640x480 frame "
          "is stretched to the input; same frames as above; person.jpg IoU against the "
          "hand-measured box of tests/detect; synthetic: the pasted person found with IoU "
          ">= 0.5 in the "
       << sweep_frames.size()
       << " frames of the walking and standing sequences):\n\n"
          "| input (w x h) | median ms | median thread-CPU ms | median ms, "
       << all_threads
       << " OpenCV threads | person.jpg IoU | dog.jpg persons | synthetic person found | "
          "mean IoU |\n|---|---|---|---|---|---|---|---|\n";
    for (const auto& [w, h] : std::vector<std::pair<int, int>>{
             {320, 320}, {320, 256}, {288, 224}, {256, 192}, {224, 160}}) {
        auto dcfg = core::loadIni(kRoot + "/config_ini/detector_yolo_fastest.ini");
        dcfg->write("detector", "input_width", w);
        dcfg->write("detector", "input_height", h);
        auto det = detect::makeDetector(*dcfg);
        const auto t = timeDetector(*det, fr.tum);
        const auto t_all = withThreads(all_threads, [&] { return timeDetector(*det, fr.tum); });
        double best = 0;
        for (const auto& d : det->detect(fr.person_jpg))
            best = std::max(best, static_cast<double>(detect::iou(d.box, person_box)));
        const auto dog = det->detect(dog_jpg).size();
        int found = 0;
        double iou_sum = 0;
        for (const auto* f : sweep_frames) {
            double b = 0;
            for (const auto& d : det->detect(f->frame.bgr))
                b = std::max(b, static_cast<double>(detect::iou(d.box, *f->person_box)));
            found += b >= 0.5;
            iou_sum += b;
        }
        md << "| " << w << " x " << h << " | " << fmt(core::median(t.ms)) << " | "
           << fmt(core::median(t.cpu)) << " | " << fmt(core::median(t_all.ms)) << " | "
           << fmt(best, 2) << " | " << dog << " | " << found << "/" << sweep_frames.size() << " | "
           << fmt(sweep_frames.empty() ? 0.0 : iou_sum / sweep_frames.size(), 2) << " |\n";
    }
    return md.str();
}

/// 2. The filter alone (detector time excluded): on the synthetic walker with its true box,
/// and on the real frames with the INI's detector; then where its time goes, stage by stage.
std::string filterSection(const Frames& fr, const dynamic::DynamicObjectFilter::Options& fo,
                          const mrpt::config::CConfigFileBase& filter_cfg,
                          const std::string& filter_detector, int all_threads) {
    std::ostringstream md;
    StageSamples stages_synthetic, stages_tum;
    md << "\n| filter stage (detector excluded) | sequence | median ms | mean ms | median "
          "thread-CPU ms | frames | median ms, "
       << all_threads << " OpenCV threads |\n|---|---|---|---|---|---|---|\n";
    {
        // Five passes over the sequence (a fresh filter each): a median over ~150 steps,
        // since single 29-step medians moved by +-25 % between runs on this VM.
        auto passes = [&] {
            std::vector<double> ms, cpu;
            StageSamples stages;
            for (int pass = 0; pass < 5; ++pass) {
                auto det = std::make_unique<TruthDetector>();
                TruthDetector* truth = det.get();
                dynamic::DynamicObjectFilter filter(fo, std::move(det));
                for (const auto& s : fr.walking) {
                    // (No box once the walker has left the view, on a long --frames.)
                    truth->next.clear();
                    if (s.person_box) truth->next = {{*s.person_box, 0, "person", 0.9f}};
                    const double c0 = threadCpuMs();
                    const auto out = filter.step(s.frame, s.T_prev_cur);
                    if (s.frame.index == 0) continue;
                    cpu.push_back(threadCpuMs() - c0);
                    ms.push_back(out.filter_ms);
                    stages.add(out.stage_ms);
                }
            }
            return std::tuple{ms, cpu, stages};
        };
        const auto [ms, cpu, stages] = passes();
        stages_synthetic = stages;
        const auto ms_all = std::get<0>(withThreads(all_threads, passes));
        const auto st = core::summarize(ms);
        md << "| DynamicObjectFilter::step | synthetic walking person (true box) | "
           << fmt(st.median, 2) << " | " << fmt(st.mean, 2) << " | " << fmt(core::median(cpu), 2)
           << " | " << ms.size() << " | " << fmt(core::median(ms_all), 2) << " |\n";
    }
    {
        auto passes = [&] {
            std::vector<double> ms;
            StageSamples stages;
            for (int pass = 0; pass < 5; ++pass) {
                auto filter = dynamic::makeFilterFromConfig(filter_cfg);
                for (const auto& f : fr.tum) {
                    const auto out = filter->step(f, std::nullopt);
                    if (f.index == 0) continue;
                    ms.push_back(out.filter_ms);
                    stages.add(out.stage_ms);
                }
            }
            return std::pair{ms, stages};
        };
        const auto [ms, stages] = passes();
        stages_tum = stages;
        const auto ms_all = withThreads(all_threads, passes).first;
        const auto st = core::summarize(ms);
        md << "| DynamicObjectFilter::step | fr1_xyz_first37 (" << filter_detector
           << "; one seated person, frames 0-3) | " << fmt(st.median, 2) << " | " << fmt(st.mean, 2)
           << " | - | " << ms.size() << " | " << fmt(core::median(ms_all), 2) << " |\n";
    }
    md << "\n**Where the filter's time goes** (its stages, `FilterOutput::stage_ms`; "
          "medians over the one-thread steps above):\n\n"
          "| stage | synthetic walking person, ms | fr1_xyz_first37, ms |\n|---|---|---|\n";
    for (std::size_t i = 0; i < std::size(StageSamples::kNames); ++i)
        md << "| " << StageSamples::kNames[i] << " | "
           << fmt(core::median(stages_synthetic.ms[i]), 3) << " | "
           << fmt(core::median(stages_tum.ms[i]), 3) << " |\n";
    return md.str();
}

/// The image the filter's corners and LK work on: grey, scaled by flow_scale.
cv::Mat toWork(const cv::Mat& bgr, const dynamic::DynamicObjectFilter::Options& fo) {
    cv::Mat gray, work;
    cv::cvtColor(bgr, gray, cv::COLOR_BGR2GRAY);
    cv::resize(gray, work, cv::Size(), fo.flow_scale, fo.flow_scale, cv::INTER_AREA);
    return work;
}

/// The filter's corner map, timed against what it replaces: the three ways are interleaved
/// frame by frame, so the VM's drift hits them alike and the ratio holds even where the
/// absolute figures move.
std::string shiTomasiSection(const Frames& fr, const dynamic::DynamicObjectFilter::Options& fo) {
    std::vector<cv::Mat> works;
    for (const auto& f : fr.tum) works.push_back(toWork(f.bgr, fo));
    std::vector<double> t_cv, t_compute, t_update;
    dynamic::ShiTomasiMap kept;
    for (int pass = 0; pass < 10; ++pass)
        for (const auto& w : works) {
            auto t0 = std::chrono::steady_clock::now();
            cv::Mat eig, eig_max;
            cv::cornerMinEigenVal(w, eig, 3, 3);
            cv::dilate(eig, eig_max, cv::Mat());
            t_cv.push_back(msSince(t0));
            t0 = std::chrono::steady_clock::now();
            (void)dynamic::ShiTomasiMap::compute(w);
            t_compute.push_back(msSince(t0));
            t0 = std::chrono::steady_clock::now();
            kept.update(w);
            t_update.push_back(msSince(t0));
        }
    const double base = core::median(t_cv);
    std::ostringstream md;
    const auto row = [&](const std::string& what, const std::vector<double>& t) {
        md << "| " << what << " | " << fmt(core::median(t), 3) << " | "
           << fmt(core::median(t) / base, 2) << " |\n";
    };
    md << "\n**Shi-Tomasi eigenvalue map** (the filter's corner map, fr1_xyz_first37 at "
       << works.front().cols << "x" << works.front().rows << ", " << t_cv.size()
       << " maps each, the three interleaved frame by frame):\n\n"
          "| computed by | median ms | ratio |\n|---|---|---|\n";
    row("`cv::cornerMinEigenVal` + 3x3 dilation (the filter until session 11)", t_cv);
    row("`ShiTomasiMap::compute` (OpenCV primitives, new buffers each call)", t_compute);
    row("`ShiTomasiMap::update` (the same, buffers kept: the filter since session 12)", t_update);
    return md.str();
}

/// The forward-backward check, as the filter runs it (backward LK started at the forward
/// track's start, OPTFLOW_USE_INITIAL_FLOW) and as it is usually written (started at the
/// forward track's end), on an fr1 frame shifted by a known number of pixels, and with its
/// right half replaced by other content (the half turned upside down: no true match there).
/// LK settings as in the filter's trackCorners.
std::string forwardBackwardSection(const Frames& fr,
                                   const dynamic::DynamicObjectFilter::Options& fo) {
    const cv::Mat& bgr = fr.tum.front().bgr;
    const cv::Size win(fo.lk_window, fo.lk_window);
    const cv::TermCriteria term = dynamic::lkTermination();
    const cv::Mat w0 = toWork(bgr, fo);
    const auto p0 = dynamic::selectShiTomasi(dynamic::ShiTomasiMap::compute(w0),
                                             cv::Rect(0, 0, w0.cols, w0.rows), fo.max_corners,
                                             fo.corner_quality, fo.corner_min_distance);
    const auto inv = 1.0 / fo.flow_scale;
    const double margin = fo.lk_window * inv;  // [px, full resolution]
    std::ostringstream md;
    md << "\n**Forward-backward check** (fr1_xyz_first37 frame 0 against itself moved "
          "by a known shift, and against itself with its right half turned upside down, "
          "where no point has a true match; the filter's corners and LK settings; a kept "
          "track is wrong when it ends more than 1 px from the truth; points whose true "
          "match leaves the image are not counted):\n\n"
          "| second frame | points | kept, backward from the start (the filter) | "
          "wrong among them | kept, backward from the end | wrong among them |\n"
          "|---|---|---|---|---|---|\n";
    for (const double shift : {0.0, 10.0, 20.0, 40.0, 60.0, -1.0}) {
        cv::Mat moved;
        if (shift >= 0) {
            const cv::Mat M = (cv::Mat_<double>(2, 3) << 1, 0, shift, 0, 1, 0);
            cv::warpAffine(bgr, moved, M, bgr.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT);
        } else {
            moved = bgr.clone();
            const cv::Rect right(bgr.cols / 2, 0, bgr.cols / 2, bgr.rows);
            cv::Mat turned;
            cv::flip(bgr(right), turned, -1);
            turned.copyTo(moved(right));
        }
        const cv::Mat w1 = toWork(moved, fo);
        std::vector<cv::Point2f> p1, back_start = p0, back_end;
        std::vector<uchar> st, st_start, st_end;
        std::vector<float> err;
        cv::calcOpticalFlowPyrLK(w0, w1, p0, p1, st, err, win, fo.lk_levels, term);
        cv::calcOpticalFlowPyrLK(w1, w0, p1, back_start, st_start, err, win, fo.lk_levels, term,
                                 cv::OPTFLOW_USE_INITIAL_FLOW);
        cv::calcOpticalFlowPyrLK(w1, w0, p1, back_end, st_end, err, win, fo.lk_levels, term);
        int points = 0, kept_start = 0, wrong_start = 0, kept_end = 0, wrong_end = 0;
        for (std::size_t i = 0; i < p0.size(); ++i) {
            const double x = p0[i].x * inv;
            if (shift >= 0 ? x + shift > bgr.cols - margin : x < 0.5 * bgr.cols + margin) continue;
            ++points;
            if (!st[i]) continue;
            // With a shift the truth is p0 + shift; in the turned half every track is wrong.
            const bool wrong = shift < 0 || std::hypot((p1[i].x - p0[i].x) * inv - shift,
                                                       (p1[i].y - p0[i].y) * inv) > 1.0;
            const auto keep = [&](const std::vector<cv::Point2f>& back,
                                  const std::vector<uchar>& ok) {
                return ok[i] && cv::norm(back[i] - p0[i]) * inv <= fo.fb_max_error;
            };
            if (keep(back_start, st_start)) {
                ++kept_start;
                wrong_start += wrong;
            }
            if (keep(back_end, st_end)) {
                ++kept_end;
                wrong_end += wrong;
            }
        }
        md << "| " << (shift >= 0 ? "shifted " + fmt(shift, 0) + " px" : "right half turned")
           << " | " << points << " | " << kept_start << " | " << wrong_start << " | " << kept_end
           << " | " << wrong_end << " |\n";
    }
    return md.str();
}

/// 3. The detect_every trade-off with the INI's real detector, on the synthetic walking,
/// standing and empty sequences.
std::string detectEverySection(const Frames& fr, const dynamic::DynamicObjectFilter::Options& fo,
                               const mrpt::config::CConfigFileBase& filter_cfg, const Args& a) {
    std::ostringstream md;
    md << "\n**detect_every trade-off** (real detector from `"
       << core::shownPath(a.filter_ini, kRoot) << "`, synthetic sequences of " << a.n_frames
       << " frames at 640x480 with exact truth, true relative pose as prior; rates over "
          "frames 1..N-1, the person's over the frames that show them):\n\n"
          "| detect_every | walking person Moving | standing person Static | no person: "
          "frames flagged | mean IoU box vs truth | median ms/frame | mean ms/frame |\n"
          "|---|---|---|---|---|---|---|\n";
    for (int k : {1, 2, 3, 5}) {
        TradeOff r;
        auto o = fo;
        o.detect_every = k;
        core::ProgressBar bar("detect_every=" + std::to_string(k), 3 * fr.walking.size());
        std::size_t done = 0;
        for (int seq = 0; seq < 3; ++seq) {
            const auto& frames = seq == 0 ? fr.walking : seq == 1 ? fr.standing : fr.empty;
            dynamic::DynamicObjectFilter filter(o, detect::makeDetector(filter_cfg));
            for (const auto& s : frames) {
                const auto out = filter.step(s.frame, s.T_prev_cur);
                bar.update(++done);
                r.total_ms.push_back(out.detect_ms + out.filter_ms);
                if (s.frame.index == 0) continue;
                bool person_moving = false, person_static = false, any_moving = false;
                double best_iou = 0;
                for (const auto& b : out.boxes) {
                    any_moving |= b.state == dynamic::BoxState::Moving;
                    if (!s.person_box) continue;
                    const double v = detect::iou(b.box, *s.person_box);
                    best_iou = std::max(best_iou, v);
                    if (v > 0.5) {
                        person_moving |= b.state == dynamic::BoxState::Moving;
                        person_static |= b.state == dynamic::BoxState::Static;
                    }
                }
                if (seq == 0 && s.person_box) {
                    r.walking_moving += person_moving;
                    ++r.walking_seen;
                }
                if (seq == 1 && s.person_box) {
                    r.static_ok += person_static && !person_moving;
                    ++r.standing_seen;
                }
                if (seq == 2) {
                    r.none_flagged += any_moving;
                    ++r.empty_frames;
                }
                if (s.person_box) {
                    r.iou_sum += best_iou;
                    ++r.iou_n;
                }
            }
        }
        bar.finish();
        const auto st = core::summarize(r.total_ms);
        md << "| " << k << " | " << r.walking_moving << "/" << r.walking_seen << " | "
           << r.static_ok << "/" << r.standing_seen << " | " << r.none_flagged << "/"
           << r.empty_frames << " | "
           << fmt(r.iou_n ? r.iou_sum / r.iou_n : 0.0, 2) << " | " << fmt(st.median) << " | "
           << fmt(st.mean) << " |\n";
    }
    return md.str();
}

int appMain(int argc, char** argv) {
    // glibc serves large blocks with fresh pages (mmap, or heap it trims back) until a large
    // block is freed, which raises its thresholds for the rest of the process. Until then each
    // forward pass of the network faulted in about 640 new pages here, and the first detector
    // timed in the process was up to 1.7x slower than the same detector timed after the HOG
    // row (27.9 against 16.5 ms with two threads, session 14). Thresholds fixed at the start
    // give every row the same allocator, whatever the order of the rows.
    mallopt(M_MMAP_THRESHOLD, 32 << 20);
    mallopt(M_TRIM_THRESHOLD, 64 << 20);
    Args a;
    if (const auto rc = parseArgs(argc, argv, a)) return *rc;
    try {
        // Read, and its values checked by building the filter once, before the detectors'
        // minutes of work, so a bad file stops the bench at once.
        std::string filter_source;
        const auto filter_cfg = core::loadFilterConfig(a.filter_ini, &filter_source);
        // The detector too: in mode none the filter makes none, but the bench runs it.
        const std::string filter_detector = core::namingSource(filter_source, [&] {
            (void)dynamic::makeFilterFromConfig(*filter_cfg);
            return detect::makeDetector(*filter_cfg)->name();
        });
        if (a.results != "none") core::checkResultsSection(a.results, "detect");
        cv::setNumThreads(a.threads);
        std::ostringstream md;
        md << "## Person detection and dynamic-object filter (`devslam-filter-bench`)\n\n"
           << "Command: `devslam-filter-bench --threads " << a.threads << " --frames " << a.n_frames
           << (a.filter_ini == kRoot + "/config_ini/dynamic_filter.ini"
                   ? std::string()
                   : " --config " + core::shownPath(a.filter_ini, kRoot))
           << "` (OpenCV threads = " << a.threads
           << "). Times are per-frame medians of wall time at 640x480. This 2-core VM's speed "
              "drifts by 20 % and more within minutes (docs/detect.md), so a single figure moves "
              "by that much; compare figures measured side by side.\n\n";
        const Frames fr = loadFrames(a.n_frames);
        // devslam-run leaves OpenCV at its default: one thread per hardware thread.
        const int all_threads = cv::getNumberOfCPUs();
        dynamic::DynamicObjectFilter::Options fo;
        fo.loadFromConfig(*filter_cfg);
        md << detectorsSection(fr, all_threads) << inputSweepSection(fr, all_threads)
           << filterSection(fr, fo, *filter_cfg, filter_detector, all_threads)
           << shiTomasiSection(fr, fo) << forwardBackwardSection(fr, fo)
           << detectEverySection(fr, fo, *filter_cfg, a);
        md << "\nMeasured " << core::measuredOnLine() << ".\n";
        std::cout << md.str();
        if (a.results != "none") {
            core::replaceResultsSection(a.results, "detect", md.str());
            std::cout << "wrote section 'detect' of " << a.results << "\n";
        }
    } catch (const std::exception& e) {
        std::cerr << "devslam-filter-bench: " << e.what() << "\n";
        return 1;
    }
    return 0;
}
}  // namespace

int main(int argc, char** argv) {
    core::ignoreFileSizeSignal();  // a write past ulimit -f is reported, not a kill
    return core::withStandardOutput("devslam-filter-bench", appMain(argc, argv));
}
