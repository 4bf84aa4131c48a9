// devslam-overlay: runs the dynamic-object filter over a TUM folder, an MRPT rawlog, a
// synthetic sequence or a video from a fixed camera (real walking people, no depth) and
// writes overlay PNGs like the DEV-SLAM paper's Fig. 2/3: person boxes coloured by state
// (red moving, green static, yellow unknown; thin = carried by the flow), flow vectors (red =
// residual above the threshold), and the ORB keypoints the mask drops (magenta crosses) over
// the masked area (tinted).
//
//   devslam-overlay --input data/tum/fr1_xyz_first37 --out /tmp/ov
//   devslam-overlay --input synthetic:walking|synthetic:static [--frames 30] --out DIR
//   devslam-overlay --input video:/usr/share/doc/opencv-doc/examples/data/vtest.avi --out DIR
//                   [--config config_ini/dynamic_filter.ini] [--mode none|all_persons|dynamic]
//                   [--every N] [--threads N] [--no-prior]
#include <devslam/core/Config.h>
#include <devslam/core/Interrupt.h>
#include <devslam/core/Parse.h>
#include <devslam/core/Picture.h>
#include <devslam/core/Progress.h>
#include <devslam/core/Results.h>
#include <devslam/dynamic/DynamicObjectFilter.h>
#include <devslam/dynamic/SyntheticSequence.h>
#include <devslam/io/RgbdReader.h>
#include <devslam/io/VideoReader.h>

#include <opencv2/core/utility.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <cstdio>
#include <filesystem>
#include <iostream>
#include <optional>
#include <string>
#include <variant>

namespace fs = std::filesystem;
using namespace devslam;

namespace {

const char* kUsage =
    "usage: devslam-overlay --input DIR|FILE.rawlog|synthetic:walking|synthetic:static|"
    "video:FILE\n"
    "                       --out DIR [--config INI] [--mode none|all_persons|dynamic]\n"
    "                       [--every N (write every N-th frame, default 1)] [--frames N (default: "
    "synthetic 30, files all)]\n"
    "                       [--threads N (OpenCV threads, default 1)] [--no-prior]\n"
    "video:FILE is a fixed camera (identity motion, depth a plane: io::VideoReader), e.g.\n"
    "OpenCV's vtest.avi from Debian's opencv-doc.\n";

cv::Scalar stateColour(dynamic::BoxState s) {
    switch (s) {
        case dynamic::BoxState::Moving:
            return {0, 0, 255};
        case dynamic::BoxState::Static:
            return {0, 200, 0};
        case dynamic::BoxState::Unknown:
            return {0, 220, 255};
    }
    return {255, 255, 255};
}

cv::Mat drawOverlay(const core::Frame& f, const dynamic::FilterOutput& out) {
    cv::Mat img = f.bgr.clone();
    // Tint the masked area.
    if (!out.mask.empty() && cv::countNonZero(out.mask) > 0) {
        cv::Mat tint(img.size(), CV_8UC3, cv::Scalar(80, 0, 160));
        cv::Mat blended;
        cv::addWeighted(img, 0.6, tint, 0.4, 0, blended);
        blended.copyTo(img, out.mask);
    }
    for (const auto& fp : out.flow) {
        if (fp.residual < 0.f) continue;
        const cv::Scalar c = fp.dynamic ? cv::Scalar(0, 0, 255) : cv::Scalar(255, 200, 0);
        cv::line(img, fp.prev, fp.cur, c, 1, cv::LINE_AA);
        cv::circle(img, fp.cur, 1, c, -1);
    }
    // Keypoints an ORB front end would find, and those the mask drops.
    cv::Mat gray;
    cv::cvtColor(f.bgr, gray, cv::COLOR_BGR2GRAY);
    std::vector<cv::KeyPoint> kps;
    // ORB keeps keypoints edgeThreshold (31) px from the border, so a smaller image has none;
    // a 1 px one made cv::ORB assert inside cv::resize.
    const auto orb = cv::ORB::create(1000);
    if (std::min(gray.cols, gray.rows) > 2 * orb->getEdgeThreshold()) orb->detect(gray, kps);
    for (const auto& kp : kps)
        if (!out.mask.empty() && out.mask.at<uchar>(cvRound(kp.pt.y), cvRound(kp.pt.x)))
            cv::drawMarker(img, kp.pt, {255, 0, 255}, cv::MARKER_TILTED_CROSS, 6, 1);
    for (const auto& b : out.boxes) {
        const cv::Scalar c = stateColour(b.state);
        cv::rectangle(img, cv::Rect(b.box), c, b.detected_this_frame ? 2 : 1);
        char text[96];
        std::snprintf(text, sizeof text, "#%d %s %d/%d", b.id, dynamic::toString(b.state).c_str(),
                      b.n_dynamic_points, b.n_points);
        cv::putText(img, text, cv::Point(cvRound(b.box.x), std::max(12, cvRound(b.box.y) - 4)),
                    cv::FONT_HERSHEY_SIMPLEX, 0.45, c, 1, cv::LINE_AA);
    }
    char line[128];
    std::snprintf(line, sizeof line, "frame %zu  thr %.1f px  detect %.1f ms  filter %.1f ms%s",
                  f.index, out.threshold, out.detect_ms, out.filter_ms,
                  out.detector_ran ? "" : "  (boxes carried)");
    cv::putText(img, line, {6, img.rows - 8}, cv::FONT_HERSHEY_SIMPLEX, 0.45, {255, 255, 255}, 1,
                cv::LINE_AA);
    return img;
}

struct Args {
    std::string input, out_dir, mode;
    std::string config = std::string(DEVSLAM_SOURCE_DIR) + "/config_ini/dynamic_filter.ini";
    int every = 1, frames = 0, threads = 1;  // frames 0: synthetic 30, real input all
    bool use_prior = true;
};

/// The command line, or the exit code to return now (0 after --help, 2 for a bad argument).
std::variant<Args, int> parseArgs(int argc, char** argv) {
    Args a;
    try {
        devslam::core::refuseRepeatedOptions(argc, argv);
    } catch (const std::exception& e) {
        std::cerr << "devslam-overlay: " << e.what() << "\n" << kUsage;
        return 2;
    }
    for (int i = 1; i < argc; ++i) {
        const std::string arg = argv[i];
        auto next = [&] { return devslam::core::optionValue(argc, argv, i); };
        try {
            if (arg == "--input")
                a.input = next();
            else if (arg == "--out")
                a.out_dir = next();
            else if (arg == "--config")
                a.config = next();
            else if (arg == "--mode")
                a.mode = next();
            else if (arg == "--every")
                a.every = int(devslam::core::parseInteger(next(), "--every", 1, 1000000));
            else if (arg == "--frames")
                a.frames = int(devslam::core::parseInteger(next(), "--frames", 0, 100000000));
            else if (arg == "--threads")
                a.threads = int(devslam::core::parseInteger(next(), "--threads", 1, 256));
            else if (arg == "--no-prior")
                a.use_prior = false;
            else if (arg == "-h" || arg == "--help") {
                std::cout << kUsage;
                return 0;
            } else
                throw std::invalid_argument("unknown argument '" + arg + "'");
        } catch (const std::exception& e) {
            std::cerr << "devslam-overlay: " << e.what() << "\n" << kUsage;
            return 2;
        }
    }
    if (a.input.empty() || a.out_dir.empty()) {  // (the usage alone named neither)
        std::cerr << "devslam-overlay: " << (a.input.empty() ? "--input" : "--out")
                  << " is required (and not empty)\n"
                  << kUsage;
        return 2;
    }
    return a;
}

/// What the overlays are drawn on: a synthetic sequence made in memory, or a reader.
struct Input {
    std::vector<dynamic::SyntheticFrame> synth;
    std::unique_ptr<io::RgbdReader> reader;
    bool fixed_camera = false;  // video: the camera's motion is known to be the identity
    std::size_t total = 0;      // frames to expect (0: unknown), for the progress bar
};

/// synthetic:walking|static, made from the shipped images (the whole sequence in memory).
std::vector<dynamic::SyntheticFrame> syntheticInput(const std::string& kind, int frames) {
    dynamic::SyntheticOptions so;
    if (frames > dynamic::kMaxSyntheticFrames)
        throw std::invalid_argument("--frames: a synthetic sequence has at most " +
                                    std::to_string(dynamic::kMaxSyntheticFrames) +
                                    " frames, got " + std::to_string(frames));
    so.n_frames = frames > 0 ? frames : 30;
    if (kind == "walking")
        so.person = dynamic::PersonMotion::Walking;
    else if (kind == "static") {
        so.person = dynamic::PersonMotion::Static;
        so.person_x0 = 0.3;
    } else
        throw std::invalid_argument("unknown synthetic sequence '" + kind +
                                    "' (known: walking, static)");
    const cv::Mat wall = cv::imread(std::string(DEVSLAM_SOURCE_DIR) +
                                    "/data/tum/fr1_xyz_first37/rgb/1305031102.175304.png");
    const cv::Mat person = cv::imread(std::string(DEVSLAM_SOURCE_DIR) + "/data/images/person.jpg");
    if (wall.empty() || person.empty()) throw std::runtime_error("shipped images missing");
    return dynamic::makeSyntheticSequence(so, wall, person(cv::Rect(180, 90, 105, 295)).clone());
}

Input openInput(const Args& a) {
    Input in;
    if (a.input.rfind("synthetic:", 0) == 0) {
        in.synth = syntheticInput(a.input.substr(10), a.frames);
        in.total = in.synth.size();
        return in;
    }
    if (a.input.rfind("video:", 0) == 0) {
        in.reader =
            std::make_unique<io::VideoReader>(a.input.substr(6), io::VideoReader::Options{});
        in.fixed_camera = true;
    } else {
        in.reader = io::openRgbdWithProgress(a.input, {});
    }
    in.total = in.reader->size().value_or(0);
    if (a.frames > 0 && (in.total == 0 || static_cast<std::size_t>(a.frames) < in.total))
        in.total = static_cast<std::size_t>(a.frames);
    return in;
}

/// Frame k's overlay file name: overlay_<k, 5 digits or more>.png.
std::string overlayName(std::size_t k) {
    std::string digits = std::to_string(k);
    if (digits.size() < 5) digits.insert(0, 5 - digits.size(), '0');
    return "overlay_" + digits + ".png";
}

/// The frame whose overlay `name` is, or nothing where overlayName does not make `name`
/// (read back through overlayName, so the name has one spelling).
std::optional<std::size_t> overlayIndex(const std::string& name) {
    const std::size_t first = name.find_first_of("0123456789");
    if (first == std::string::npos) return std::nullopt;
    const std::string digits =
        name.substr(first, name.find_first_not_of("0123456789", first) - first);
    if (digits.size() > 18) return std::nullopt;  // no frame count has as many (nor std::stoull)
    const std::size_t k = std::stoull(digits);
    if (overlayName(k) != name) return std::nullopt;
    return k;
}

/// "; overlays there of later frames are an earlier run's" when `dir` holds any of frame k
/// on, else nothing (a fresh folder has no earlier run to warn of).
std::string earlierOverlaysNote(const std::string& dir, std::size_t k) {
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(dir, ec))
        if (const auto index = overlayIndex(e.path().filename().string()); index && *index >= k)
            return "; overlays there of later frames are an earlier run's";
    return "";
}

/// Frame k's overlay as DIR/overlayName(k); `written` overlays came before it.
void writeOverlay(const std::string& out_dir, std::size_t k, const core::Frame& f,
                  const dynamic::FilterOutput& out, std::size_t written) {
    const std::string file = (fs::path(out_dir) / overlayName(k)).string();
    // Drawn outside the write's try: a drawing error is not a write error.
    const cv::Mat picture = drawOverlay(f, out);
    // Whole or not at all: a disk that fills or a Ctrl-C leaves no cut overlay among the
    // ones written.
    try {
        core::writePngWhole(file, picture);
    } catch (const std::runtime_error& e) {  // "cannot write 'FILE': why"
        throw std::runtime_error(e.what() + (" (" + std::to_string(written) +
                                             " overlays written before it)"));
    }
}

int appMain(int argc, char** argv) {
    // Ctrl-C or SIGTERM: the overlay being written is finished, the run stops there (an
    // overlay cut in the middle of its write was left empty, among an earlier run's).
    core::installStopHandler("devslam-overlay");
    const auto parsed = parseArgs(argc, argv);
    if (const int* rc = std::get_if<int>(&parsed)) return *rc;
    const Args& a = std::get<Args>(parsed);
    try {
        cv::setNumThreads(a.threads);
        // A filter INI, or a SLAM INI naming one ([run] filter_config, filter_overrides).
        std::string filter_source;
        auto cfg = core::loadFilterConfig(a.config, &filter_source);
        std::optional<dynamic::MaskMode> mode_override;
        if (!a.mode.empty()) {
            try {
                mode_override = dynamic::parseMaskMode(a.mode);
            } catch (const std::invalid_argument& e) {
                std::cerr << "devslam-overlay: --mode: " << e.what() << "\n" << kUsage;
                return 2;
            }
        }
        auto filter = core::namingSource(
            filter_source, [&] { return dynamic::makeFilterFromConfig(*cfg, mode_override); });
        const core::FolderClaim claim(a.out_dir);  // (two runs into it at once mixed overlays)

        Input in;
        try {
            in = openInput(a);
        } catch (const io::OpeningStopped&) {  // (main ends by the signal, the claim let go)
            std::cerr << "devslam-overlay: interrupted (" << core::signalName(core::stopSignal())
                      << ") while opening the input; nothing written\n";
            return 1;
        }
        core::ProgressBar bar("overlay", in.total);
        std::size_t k = 0, written = 0;
        while (!core::stopSignal()) {
            std::optional<core::Frame> f;
            std::optional<Eigen::Isometry3d> prior;
            if (!in.synth.empty()) {
                if (k >= in.synth.size()) break;
                f = in.synth[k].frame;
                if (a.use_prior) prior = in.synth[k].T_prev_cur;
            } else {
                if (a.frames > 0 && k >= static_cast<std::size_t>(a.frames)) break;
                try {
                    f = in.reader->next();
                } catch (const std::exception& e) {
                    // A frame that does not decode: the overlays written so far replaced an
                    // earlier run's, whose later ones stay; said as an interrupt says it.
                    throw std::runtime_error(std::string(e.what()) + "; stopped after " +
                                             std::to_string(k) + " frames: wrote " +
                                             std::to_string(written) + " overlays to " + a.out_dir +
                                             earlierOverlaysNote(a.out_dir, k));
                }
                if (!f) break;
                if (in.fixed_camera && a.use_prior) prior = Eigen::Isometry3d::Identity();
            }
            const auto out = filter->step(*f, prior);
            if (k % static_cast<std::size_t>(a.every) == 0)
                writeOverlay(a.out_dir, k, *f, out, written++);
            bar.update(++k);
        }
        bar.finish();
        // An earlier run's overlays past this one's (or between, with --every) would pass for
        // this run's: removed once this run's are all written (an interrupted run leaves
        // them, and says so: it would otherwise lose them for a run it did not finish).
        const int sig = core::stopSignal();
        if (sig) {
            std::cerr << "devslam-overlay: interrupted (" << core::signalName(sig) << ") after "
                      << k << " frames: wrote " << written << " overlays to " << a.out_dir
                      << earlierOverlaysNote(a.out_dir, k) << "\n";
            core::exitBySignal(sig);
        }
        std::vector<fs::path> stale;
        for (const auto& e : fs::directory_iterator(a.out_dir)) {
            const auto index = overlayIndex(e.path().filename().string());
            if (index && (*index >= k || *index % static_cast<std::size_t>(a.every) != 0))
                stale.push_back(e.path());
        }
        for (const auto& p : stale) fs::remove(p);
        std::cout << "wrote " << written << " overlays to " << a.out_dir
                  << (stale.empty() ? std::string()
                                    : " (removed " + std::to_string(stale.size()) +
                                          " of an earlier run)")
                  << "\n";
        if (in.reader && !in.reader->damage().empty())
            std::cerr << "devslam-overlay: warning: " << in.reader->damage() << "\n";
    } catch (const std::exception& e) {
        std::cerr << "devslam-overlay: " << e.what() << "\n";
        return 1;
    }
    return 0;
}
}  // namespace

int main(int argc, char** argv) {
    const int rc = appMain(argc, argv);
    // Stopped by Ctrl-C: end by the signal, so that a shell script running this stops too.
    if (const int sig = core::stopSignal()) core::exitBySignal(sig);
    return core::withStandardOutput("devslam-overlay", rc);
}
