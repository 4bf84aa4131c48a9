// devslam-convert: TUM RGB-D folder <-> MRPT rawlog of CObservation3DRangeScan.
// Depth keeps the source's raw 16-bit units and colour is stored losslessly, so a
// TUM -> rawlog -> TUM round trip is bit-exact in both images.
#include <devslam/core/Interrupt.h>
#include <devslam/core/Parse.h>
#include <devslam/core/Progress.h>
#include <devslam/core/Results.h>
#include <devslam/io/Rawlog.h>
#include <devslam/io/RgbdReader.h>
#include <devslam/io/TumWriter.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <optional>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

namespace {

const char* kUsage = R"(usage: devslam-convert INPUT OUTPUT [options]
  INPUT   a TUM RGB-D folder (with rgb.txt) or a .rawlog file
  OUTPUT  a path ending in .rawlog (write a rawlog) or a folder (write a TUM folder); an
          existing rawlog or a folder that holds a TUM sequence is refused
options:
  --camera NAME       intrinsics preset for a TUM input (auto|freiburg1|freiburg2|freiburg3|ros_default)
  --sensory-frames    rawlog in the action/sensory-frame layout (default: observations only)
  --external          rawlog with images in <name>_Images/ (default: inline)
  --compression N     gzip level 0..9 (default 1)
  --label TEXT        sensor label of the observations (default RGBD)
  --max-frames N      stop after N frames (N >= 1)
  --allow-damaged     a damaged input (a rawlog cut short by a crash or a full disk, a TUM
                      folder missing images, a frame whose image does not decode): convert
                      what is intact, say what was left out
)";

/// Whether the output is a rawlog (else a TUM folder), by its name as given.
bool isRawlog(const std::string& out) {
    return devslam::core::endsWithNoCase(out, ".rawlog");  // (out.RAWLOG made a folder)
}

/// The writers open their output before the first frame is read: an output that is the
/// input (or holds another sequence) would be emptied before it was read.
void refuseOverwritingInput(const std::string& in, const std::string& out, bool external) {
    namespace fs = std::filesystem;
    if (devslam::core::sameFile(in, out))
        throw std::invalid_argument("OUTPUT '" + out + "' is the input '" + in +
                                    "': writing it would destroy what is read; name another");
    // A conversion that fails midway (a frame that does not decode) leaves a partial rawlog:
    // it must not be written over one that was there.
    if (isRawlog(out) && (fs::exists(out) || fs::is_symlink(out)))
        throw std::invalid_argument("OUTPUT '" + out +
                                    "' already exists; remove it or name another");
    if (!isRawlog(out) && fs::exists(fs::path(out) / "rgb.txt"))
        throw std::invalid_argument("OUTPUT '" + out +
                                    "' already holds a TUM sequence (rgb.txt); remove it or name "
                                    "another folder");
    // Nor what else the TUM writer writes there: a folder without rgb.txt had its ground
    // truth, camera.ini and images replaced without a word (devslam-synth refuses them too).
    if (!isRawlog(out))
        for (const char* name : {"depth.txt", "groundtruth.txt", "camera.ini", "rgb", "depth"})
            if (const auto p = fs::path(out) / name; fs::exists(p) || fs::is_symlink(p))
                throw std::invalid_argument("OUTPUT '" + out + "' already holds " + name +
                                            ", which the conversion would write over; remove "
                                            "it or name another folder");
    // A rawlog's external images go to <name>_Images/: one there (an older conversion's, or
    // anyone's) had its images replaced and the rest left beside the new ones.
    if (isRawlog(out) && external)
        if (const auto images = devslam::io::rawlogImagesDir(out);
            fs::is_symlink(images) || (fs::exists(images) && !fs::is_directory(images)) ||
            (fs::is_directory(images) && !fs::is_empty(images)))
            throw std::invalid_argument("OUTPUT '" + out + "': its images' folder '" + images +
                                        "' is already there and not empty; remove it or name "
                                        "another rawlog");
}

struct Args {
    std::string input, output;
    devslam::io::ReaderOptions ro;
    devslam::io::RawlogWriterOptions wo;
    std::size_t max_frames = static_cast<std::size_t>(-1);
};

/// The command line, or the exit code to return now (0 after --help, 2 without two paths).
/// Throws std::invalid_argument for a bad option.
std::variant<Args, int> parseArgs(int argc, char** argv) {
    Args args;
    std::vector<std::string> pos;
    devslam::core::refuseRepeatedOptions(argc, argv);
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        auto value = [&] { return devslam::core::optionValue(argc, argv, i); };
        if (a == "-h" || a == "--help") {
            std::cout << kUsage;
            return 0;
        } else if (a == "--camera") {
            args.ro.camera = value();
            // Checked here, as devslam-run's [dataset] camera (the reader's message left out
            // "auto", which --help lists).
            devslam::io::ReaderOptions::requireCameraName(args.ro.camera, "--camera");
        }
        else if (a == "--sensory-frames")
            args.wo.sensory_frames = true;
        else if (a == "--external")
            args.wo.external_images = true;
        else if (a == "--compression")
            args.wo.compression = int(devslam::core::parseInteger(value(), "--compression", 0, 9));
        else if (a == "--label") {
            args.wo.sensor_label = value();
            // (every observation then had no label, or one that split the rawlog's listings)
            if (args.wo.sensor_label.empty() ||
                args.wo.sensor_label.find_first_of("\n\r") != std::string::npos)
                throw std::invalid_argument("--label must not be empty or hold a line break");
        }
        else if (a == "--allow-damaged")
            args.ro.allow_damaged = true;
        else if (a == "--max-frames")
            args.max_frames = std::size_t(devslam::core::parseInteger(value(), "--max-frames", 1));
        else if (!a.empty() && a[0] == '-')
            throw std::invalid_argument("unknown option " + a);
        else
            pos.push_back(a);
    }
    if (pos.size() != 2) {  // (the usage alone did not say what was wrong)
        std::cerr << "devslam-convert: expected two files, INPUT and OUTPUT, got " << pos.size()
                  << (pos.size() > 2 ? " (the third: '" + pos[2] + "')" : std::string()) << "\n"
                  << kUsage;
        return 2;
    }
    // (an empty OUTPUT wrote its TUM folder into /, a script's unset variable)
    for (const auto& [name, p] : {std::pair{"INPUT", pos[0]}, {"OUTPUT", pos[1]}})
        if (p.empty())
            throw std::invalid_argument(std::string(name) + " is empty: name a file or folder");
    args.input = pos[0];
    args.output = pos[1];
    return args;
}

/// Copies frames from a reader to a writer and keeps what the summary reports.
struct Conversion {
    std::size_t n = 0;  // frames written
    // A frame the reader finds bad only when it reads it (an image that is there but does not
    // decode) stops the conversion with the frames before it written, or, with
    // --allow-damaged, is left out and the rest converted. The readers pass such a frame.
    std::string stopped;
    std::vector<std::string> undecodable;
    std::string write_error;  // the writer refused a frame (or the disk did): stopped there
    std::string close_error;  // closing the output failed: its end (or ground truth) is lost
    bool removed = false;     // nothing converted: the output this run made was removed
    int interrupted = 0;      // the signal that stopped the conversion
    double depth_gap = 0;     // [s] the largest colour-depth stamp difference written

    template <class Writer>
    void copy(devslam::io::RgbdReader& reader, Writer& out, const Args& args,
              devslam::core::ProgressBar& bar) {
        while (n < args.max_frames) {
            std::optional<devslam::core::Frame> f;
            try {
                f = reader.next();
            } catch (const devslam::io::InputBroken& e) {
                stopped = e.what();  // nothing after it can be read, --allow-damaged or not
                break;
            } catch (const std::exception& e) {
                if (!args.ro.allow_damaged) {
                    stopped = e.what();
                    break;
                }
                undecodable.push_back(e.what());
                if ((interrupted = devslam::core::stopSignal())) break;
                continue;
            }
            if (!f) break;
            // Ctrl-C (core/Interrupt.h) ends the conversion before this frame, the output
            // closed whole; one after the last frame leaves it whole.
            if ((interrupted = devslam::core::stopSignal())) break;
            if (f->depth_timestamp)
                depth_gap = std::max(depth_gap, std::abs(*f->depth_timestamp - f->timestamp));
            try {
                out.write(*f);
            } catch (const std::exception& e) {
                write_error = e.what();  // the frames before it stay written, closed whole
                break;
            }
            bar.update(++n);
        }
    }

    /// What was written and what was not; the exit code.
    int report(const devslam::io::RgbdReader& reader, const Args& args) const {
        std::cout << "wrote " << n << " frames to " << args.output << "\n";
        if (isRawlog(args.output)) {  // one stamp per observation, no ground truth
            if (depth_gap > 0)
                std::cout << "not kept: the depth images' own stamps (up to "
                          << std::lround(1e3 * depth_gap)
                          << " ms from the colour image's; a rawlog keeps one per frame)\n";
            if (reader.groundTruth())
                std::cout << "not kept: groundtruth.txt (a rawlog holds no ground truth)\n";
        }
        if (const std::string lost = reader.damage(); !lost.empty())
            std::cout << "left out (damaged input): " << lost << "\n";
        if (!undecodable.empty())
            std::cout << "left out (frames that do not decode): " << undecodable.size()
                      << ", the first: " << undecodable.front() << "\n";
        // An output with no frame would only stand in the way of the next try (an existing
        // output is refused), so the one this run made is removed.
        const std::string kept = args.output + " holds the " + std::to_string(n) + " frames";
        const std::string holds =
            removed ? "nothing was written (" + args.output + " removed)"
                    : kept + " before it" +
                          (close_error.empty() ? "" : ", but not whole (" + close_error + ")");
        if (!close_error.empty() && write_error.empty() && stopped.empty() && !interrupted) {
            std::cerr << "devslam-convert: " << close_error << "\ndevslam-convert: "
                      << (removed ? holds : kept + " written, but is not whole") << "\n";
            return 1;
        }
        if (n == 0 && stopped.empty() && write_error.empty() && !interrupted) {
            std::cerr << "devslam-convert: no frame converted (every one left out); "
                      << (removed ? holds : args.output + " holds none") << "\n";
            return 1;
        }
        if (!write_error.empty()) {
            std::cerr << "devslam-convert: " << write_error << "\ndevslam-convert: stopped there; "
                      << holds << "\n";
            return 1;
        }
        if (!stopped.empty()) {
            std::cerr << "devslam-convert: " << stopped << "\ndevslam-convert: stopped there; "
                      << holds
                      << " (--allow-damaged leaves such frames out and converts the rest)\n";
            return 1;
        }
        if (interrupted) {
            std::cerr << "devslam-convert: interrupted (" << devslam::core::signalName(interrupted)
                      << "); " << holds << "\n";
            return 1;
        }
        return 0;
    }
};

int convert(int argc, char** argv) {
    try {
        const auto parsed = parseArgs(argc, argv);
        if (const int* rc = std::get_if<int>(&parsed)) return *rc;
        const Args& args = std::get<Args>(parsed);
        refuseOverwritingInput(args.input, args.output, args.wo.external_images);
        std::unique_ptr<devslam::io::RgbdReader> reader;
        try {
            reader = devslam::io::openRgbdWithProgress(args.input, args.ro);
        } catch (const devslam::io::OpeningStopped&) {
            std::cerr << "devslam-convert: interrupted ("
                      << devslam::core::signalName(devslam::core::stopSignal())
                      << ") while opening the input; nothing written\n";
            return 1;
        }
        // Each observation of a rawlog carries its own camera: --camera was ignored, and the
        // output kept the rawlog's intrinsics without a word.
        if (args.ro.camera != "auto" && dynamic_cast<devslam::io::RawlogReader*>(reader.get()))
            throw std::invalid_argument("--camera " + args.ro.camera + ": '" + args.input +
                                        "' is a rawlog, whose observations carry their own "
                                        "camera; --camera is for TUM folders");
        if (const int sig = devslam::core::stopSignal()) {  // before the output is opened
            std::cerr << "devslam-convert: interrupted (" << devslam::core::signalName(sig)
                      << ") before the first frame; nothing written\n";
            return 1;
        }
        std::cerr << "reading " << reader->describe() << "\n";
        const std::size_t total = std::min(reader->size().value_or(0), args.max_frames);
        devslam::core::ProgressBar bar("converting", total);
        Conversion c;
        const bool existed = std::filesystem::exists(args.output);
        const std::string images = devslam::io::rawlogImagesDir(args.output);
        const bool images_existed = std::filesystem::exists(images);
        // Closing the output can fail too (a full disk: the rawlog's end, the ground truth):
        // caught, so that an output without a frame is still removed and the first error,
        // not the closing one, is the one reported.
        const auto finish = [&](auto&& step) {
            try {
                step();
            } catch (const std::exception& e) {
                if (c.close_error.empty()) c.close_error = e.what();
            }
        };
        if (isRawlog(args.output)) {
            auto wo = args.wo;
            wo.fresh = true;  // (refused above if it is there; this catches one made since)
            // Its folder is made, as a TUM output's folder is (with its parents).
            if (const auto parent = std::filesystem::path(args.output).parent_path();
                !parent.empty()) {
                std::error_code ec;
                std::filesystem::create_directories(parent, ec);
                if (!std::filesystem::is_directory(parent))
                    throw std::runtime_error(
                        "cannot write rawlog '" + args.output + "': cannot make folder '" +
                        parent.string() + "': " + (ec ? ec.message() : "a file is there"));
            }
            devslam::io::RawlogWriter out(args.output, wo);
            c.copy(*reader, out, args, bar);
            finish([&] { out.close(); });
        } else {
            devslam::io::TumWriter out(args.output,
                                       "converted by devslam-convert from " + args.input, true);
            c.copy(*reader, out, args, bar);
            finish([&] {
                if (auto gt = reader->groundTruth()) out.writeGroundTruth(*gt);
            });
            finish([&] { out.close(); });
        }
        bar.finish();
        if (c.n == 0 && !existed) {
            std::error_code ec;
            std::filesystem::remove_all(args.output, ec);
            c.removed = !ec;
            if (isRawlog(args.output) && args.wo.external_images && !images_existed)
                std::filesystem::remove_all(images, ec);
        }
        return c.report(*reader, args);
    } catch (const devslam::io::DamagedInput& e) {
        std::cerr << "devslam-convert: " << e.what() << "\n";
        if (e.intact() > 0)
            std::cerr << "devslam-convert: --allow-damaged converts those " << e.intact()
                      << " intact frames\n";
        return 1;
    } catch (const std::exception& e) {
        std::cerr << "devslam-convert: " << e.what() << "\n";
        return 1;
    }
}

}  // namespace

int main(int argc, char** argv) {
    devslam::core::installStopHandler("devslam-convert");
    const int rc = convert(argc, argv);
    // After Ctrl-C, with the output closed: end by the signal, so that a script stops too.
    if (const int sig = devslam::core::stopSignal()) devslam::core::exitBySignal(sig);
    return devslam::core::withStandardOutput("devslam-convert", rc);
}
