// devslam-synth: renders a synthetic dynamic RGB-D sequence with exact ground truth.
//
//   devslam-synth walking_xyz          # sim_worlds/synth/walking_xyz.ini -> out/synth/walking_xyz
//   devslam-synth path/to/scenario.ini -o DIR [--rawlog FILE] [--frames N] [--no-labels]
//   devslam-synth --list               # the shipped scenarios
//   devslam-synth walking_xyz --check [--set ...]   # reads the scenario, renders nothing
//   devslam-synth --cut-texture IMAGE X,Y,W,H OUT.png   # person photo -> RGBA texture
//
// Ctrl-C stops the render after the current frame: the frames so far are written as a TUM
// folder, without render.txt (so --if-changed renders it again).
#include <devslam/core/Interrupt.h>
#include <devslam/core/Parse.h>
#include <devslam/core/Picture.h>
#include <devslam/core/Progress.h>
#include <devslam/core/Results.h>
#include <devslam/render/PersonTexture.h>
#include <devslam/render/Scenario.h>
#include <devslam/render/SequenceRenderer.h>
#include <devslam/render/SequenceWriter.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using namespace devslam;

namespace {

const char* kUsage =
    "usage: devslam-synth SCENARIO [-o|--out DIR] [--rawlog FILE] [--frames N] [--no-labels]\n"
    "                     [--seed N]  (another render of the scenario: noise, panel crops)\n"
    "                     [--if-changed]  (skip when DIR already holds this exact render)\n"
    "                     [--set SECTION.KEY=VALUE]...  (over the scenario file's settings)\n"
    "                     [--check]  (read the scenario, its room and photos; render nothing)\n"
    "       devslam-synth --list\n"
    "       devslam-synth --cut-texture IMAGE X,Y,W,H OUT.png\n"
    "SCENARIO: a name from sim_worlds/synth/ (e.g. walking_xyz) or an INI file.\n"
    "Writes a TUM folder (rgb/ depth/ rgb.txt depth.txt groundtruth.txt) plus persons.txt,\n"
    "labels/, camera.ini and preview.png, and render.txt last (what the render is made of:\n"
    "scenario and room text, seed, frames); default DIR: out/synth/<name>.\n"
    "Ctrl-C stops after the current frame: DIR then holds the frames rendered so far as a\n"
    "TUM folder with their ground truth, and no render.txt.\n";

const std::string kSynthDir = std::string(DEVSLAM_SOURCE_DIR) + "/sim_worlds/synth";

std::string resolveScenario(const std::string& arg) {
    if (fs::is_regular_file(arg)) return arg;
    // A path is not a name ("no '.../synth//tmp/x.ini.ini'" was no help).
    if (arg.find('/') != std::string::npos || core::endsWithNoCase(arg, ".ini"))
        throw std::invalid_argument("no scenario file '" + arg + "'");
    const std::string p = kSynthDir + "/" + arg + ".ini";
    if (fs::is_regular_file(p)) return p;
    throw std::invalid_argument("no scenario file '" + arg + "' and no '" + p +
                                "' (devslam-synth --list shows the shipped ones)");
}

/// RGB with person boxes (red = moving, green = static) beside the colourised depth.
cv::Mat preview(const render::RenderedFrame& f) {
    cv::Mat rgb = f.frame.bgr.clone();
    for (const auto& p : f.persons)
        if (p.visible_pixels > 0) {
            const cv::Scalar c = p.moving ? cv::Scalar(0, 0, 255) : cv::Scalar(0, 200, 0);
            cv::rectangle(rgb, p.box, c, 2);
            cv::putText(rgb, p.name + (p.moving ? " moving" : " static"),
                        p.box.tl() + cv::Point(2, 14), cv::FONT_HERSHEY_SIMPLEX, 0.45, c, 1,
                        cv::LINE_AA);
        }
    cv::Mat d8, dc;
    f.frame.depth.convertTo(d8, CV_8U, 255.0 / 5.0);  // 0..5 m
    cv::applyColorMap(d8, dc, cv::COLORMAP_JET);
    dc.setTo(cv::Scalar(0, 0, 0), f.frame.depth == 0);  // missing = black
    cv::Mat both;
    cv::hconcat(rgb, dc, both);
    return both;
}

int cutTexture(const std::vector<std::string>& a) {
    if (a.size() != 4) throw std::invalid_argument("--cut-texture needs IMAGE X,Y,W,H OUT.png");
    // The texture's alpha mask needs PNG (a .jpg dropped it, a .txt failed in OpenCV), and
    // the photo is not written over.
    if (!core::endsWithNoCase(a[3], ".png"))
        throw std::invalid_argument("--cut-texture OUT '" + a[3] + "': the name must end in .png");
    if (core::sameFile(a[1], a[3]))
        throw std::invalid_argument("--cut-texture OUT '" + a[3] + "' is the IMAGE '" + a[1] +
                                    "': writing it would destroy the photo; name another");
    std::string why;
    const cv::Mat img = core::readImage(a[1], cv::IMREAD_COLOR, why);
    if (img.empty()) throw std::runtime_error("cannot read '" + a[1] + "'" + why);
    const auto v = core::parseNumberList(a[2], "--cut-texture box", 4);
    // Pixels: 180.5 was cut at 180 without a word, and 1e10 overflowed the int.
    for (double x : v)
        if (x != std::floor(x) || std::abs(x) > 1e6)
            throw std::invalid_argument("--cut-texture box '" + a[2] +
                                        "': X,Y,W,H must be whole pixels");
    const cv::Rect box{int(v[0]), int(v[1]), int(v[2]), int(v[3])};
    const cv::Mat rgba = render::cutPersonTexture(img, box);
    core::writePngWhole(a[3], rgba);
    std::vector<cv::Mat> ch;
    cv::split(rgba, ch);
    std::cout << "wrote " << a[3] << " (" << rgba.cols << "x" << rgba.rows << ", "
              << cv::countNonZero(ch[3]) << " person pixels)\n";
    return 0;
}

int run(int argc, char** argv) {
    std::vector<std::string> a(argv + 1, argv + argc);
    if (a.empty() || a[0] == "-h" || a[0] == "--help") {
        std::cout << kUsage;
        return a.empty() ? 2 : 0;
    }
    if (a[0] == "--list") {
        // (anything after it, "--list --check" included, was ignored without a word)
        if (a.size() > 1)
            throw std::invalid_argument("--list takes nothing more, got '" + a[1] + "'");
        std::vector<std::string> names;
        for (const auto& e : fs::directory_iterator(kSynthDir))
            if (e.path().extension() == ".ini" &&
                e.path().stem().string().find("_room") == std::string::npos)
                names.push_back(e.path().stem().string());
        std::sort(names.begin(), names.end());
        for (const auto& n : names) {
            const auto sc = render::loadScenario(kSynthDir + "/" + n + ".ini");
            const auto v = render::meanSpeeds(sc.trajectory, sc.n_frames, sc.rate_hz);
            char speeds[64];
            std::snprintf(speeds, sizeof speeds, "%.3f m/s, %.1f deg/s", v.m_per_s, v.deg_per_s);
            std::cout << n << ": " << sc.n_frames << " frames at " << sc.rate_hz
                      << " Hz, trajectory " << render::toString(sc.trajectory.type) << " ("
                      << speeds << " on average), " << sc.people.size() << " people\n";
        }
        return 0;
    }
    if (a[0] == "--cut-texture") return cutTexture(a);

    devslam::core::refuseRepeatedOptions(a, {"--set"}, {{"-o", "--out"}});
    std::string scenario_arg, out_dir, rawlog;
    std::size_t frames = 0;
    std::optional<std::uint64_t> seed;
    std::vector<std::string> sets;
    bool labels = true, if_changed = false, check = false;
    for (std::size_t i = 0; i < a.size(); ++i) {
        const auto value = [&] { return devslam::core::optionValue(a, i); };
        // An empty name (a script's unset variable) rendered into out/synth/<name>, over the
        // render there, or wrote no rawlog, without a word.
        const auto name = [&] {
            const std::string option = a[i], v = value();
            if (v.empty()) throw std::invalid_argument(option + ": the name is empty");
            return v;
        };
        if (a[i] == "-o" || a[i] == "--out")
            out_dir = name();
        else if (a[i] == "--rawlog")
            rawlog = name();
        else if (a[i] == "--frames")
            frames = std::size_t(devslam::core::parseInteger(value(), "--frames", 1));
        else if (a[i] == "--no-labels")
            labels = false;
        else if (a[i] == "--if-changed")
            if_changed = true;
        else if (a[i] == "--check")
            check = true;
        else if (a[i] == "--set")
            sets.push_back(value());
        else if (a[i] == "--seed")
            seed = std::uint64_t(devslam::core::parseInteger(value(), "--seed", 0));
        else if (!a[i].empty() && a[i][0] == '-')
            throw std::invalid_argument("unknown option '" + a[i] + "'\n" + kUsage);
        else if (scenario_arg.empty())
            scenario_arg = a[i];
        else
            throw std::invalid_argument("more than one scenario given ('" + scenario_arg + "', '" +
                                        a[i] + "')");
    }
    if (scenario_arg.empty())
        throw std::invalid_argument(std::string("no scenario given\n") + kUsage);
    // --check writes nothing, so an output option with it is a mistake, not a no-op.
    if (check)
        for (const std::string o : {"-o", "--out", "--rawlog", "--no-labels", "--if-changed"})
            if (std::find(a.begin(), a.end(), o) != a.end())
                throw std::invalid_argument(o + " does not go with --check (it renders nothing)");
    const std::string scenario_file = resolveScenario(scenario_arg);
    auto sc = render::loadScenario(scenario_file, sets);
    // The same scene and motion, other noise and panel crops: renders to tell a setting's
    // effect from the SLAM's sensitivity to small changes (docs/render.md).
    if (seed) sc.seed = *seed;
    // A cap, as devslam-bench passes it to every sequence; more than the scenario has rendered
    // the scenario's frames without a word on the number asked for.
    if (frames > sc.n_frames)
        std::cerr << "devslam-synth: --frames " << frames << ": scenario " << sc.name << " has "
                  << sc.n_frames << " frames ([scenario] n_frames, or duration x rate_hz), "
                  << "and renders them all; --set scenario.n_frames=N or scenario.duration=S "
                  << "(the one it gives) makes it longer\n";
    // What devslam-bench asks of each synthetic sequence before its renders: a name it does
    // not know, a --set key the scenario lacks or a photo that does not decode stopped the
    // bench at that sequence's render, after the others'.
    if (check) {
        std::cout << "scenario " << sc.name << " (" << scenario_file
                  << "): " << (frames > 0 ? std::min(frames, sc.n_frames) : sc.n_frames)
                  << " frames at " << sc.rate_hz << " Hz, trajectory "
                  << render::toString(sc.trajectory.type) << ", " << sc.people.size()
                  << " people; checked, nothing rendered\n";
        return 0;
    }
    if (out_dir.empty()) out_dir = "out/synth/" + sc.name;

    render::WriteOptions o;
    o.out_dir = out_dir;
    o.rawlog_path = rawlog;
    o.write_labels = labels;
    o.max_frames = frames;
    // The folder is this render's until it ends: a second render into it at once is refused
    // (the two mixed their images, labels and ground truth, both saying 0).
    const core::FolderClaim claim(out_dir);
    render::checkOutputs(sc, o);  // before the preview: a real TUM folder is left as it was
    if (if_changed && render::isRenderCurrent(sc, o)) {
        std::cout << "scenario " << sc.name << ": " << out_dir
                  << " holds this render already (render.txt), not rendered again\n";
        return 0;
    }
    const std::size_t n = frames > 0 ? std::min(frames, sc.n_frames) : sc.n_frames;
    // A picture of the middle frame, for people, written as the render passes it (before
    // render.txt, which comes last), from the frame the render made: a second renderer for
    // it cost two seconds. An earlier render's picture goes with the first frame.
    const std::string prev = (fs::path(out_dir) / "preview.png").string();
    o.on_frame = [&](std::size_t i, const render::RenderedFrame& f) {
        if (i == 0) fs::remove(prev);
        if (i == n / 2) core::writePngWhole(prev, preview(f));
    };
    core::ProgressBar bar("render " + sc.name, n);
    o.stop = [] { return core::stopSignal() != 0; };
    const auto sum =
        render::writeSequence(sc, o, [&](std::size_t done, std::size_t) { bar.update(done); });
    bar.finish();
    if (sum.stopped && sum.n_frames == 0) {
        std::cerr << "devslam-synth: interrupted (" << core::signalName(core::stopSignal())
                  << ") before the first frame: " << out_dir << " was left as it was\n";
        return 1;
    }
    if (sum.stopped) {
        std::cerr << "devslam-synth: interrupted (" << core::signalName(core::stopSignal())
                  << ") after " << sum.n_frames << " of " << n << " frames: " << out_dir
                  << " holds them as a TUM folder with their ground truth; render.txt was not "
                     "written, so it is not a current render (--if-changed renders it again)\n";
        return 1;
    }

    std::cout << "scenario " << sc.name << " -> " << out_dir << "\n"
              << "  frames " << sum.n_frames << " (" << sc.rate_hz << " Hz), intrinsics fx "
              << sc.K.fx << " fy " << sc.K.fy << " cx " << sc.K.cx << " cy " << sc.K.cy << " "
              << sc.K.width << "x" << sc.K.height << "\n"
              << "  frames with a visible moving person " << sum.frames_with_moving_person
              << ", with a visible static person " << sum.frames_with_static_person << "\n"
              << "  render median " << sum.render_ms_median << " ms/frame\n"
              << "  depth on " << std::lround(100 * sum.depth_fraction_median)
              << " % of the pixels (median over frames)\n"
              << "  preview " << prev << (rawlog.empty() ? "" : ", rawlog " + rawlog) << "\n";
    // The render is written as asked; a sensor that measures nothing is said loudly (a
    // sigma_a of 1e300 or a max_range short of the room rendered depth of zeros, exit 0).
    if (sum.frames_without_depth > 0)
        std::cerr << "devslam-synth: WARNING: " << sum.frames_without_depth << " of "
                  << sum.n_frames
                  << " frames have no depth value at all with this [depth_noise] (min_range "
                  << sc.depth_noise.min_range << ", max_range " << sc.depth_noise.max_range
                  << " m, sigma_a " << sc.depth_noise.sigma_a << ", sigma_b "
                  << sc.depth_noise.sigma_b << ", disparity_step " << sc.depth_noise.disparity_step
                  << ", dropout " << sc.depth_noise.dropout << "): no RGB-D SLAM can run on them\n";
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    core::installStopHandler("devslam-synth");
    int rc = 1;
    try {
        rc = run(argc, argv);
    } catch (const std::bad_alloc&) {  // (it said only "std::bad_alloc")
        std::cerr << "devslam-synth: out of memory (the scenario's image size, or its "
                     "texture photos: each wall panel keeps its own crop)\n";
    } catch (const std::exception& e) {
        std::cerr << "devslam-synth: " << e.what() << "\n";
    }
    // After Ctrl-C, with every file closed: end by the signal, so that a script stops too.
    if (const int sig = core::stopSignal()) core::exitBySignal(sig);
    return core::withStandardOutput("devslam-synth", rc);
}
