#include <devslam/io/Rawlog.h>
#include <devslam/io/RgbdReader.h>
#include <devslam/io/TumReader.h>

#include <devslam/core/Config.h>
#include <devslam/core/Interrupt.h>

#include <mrpt/config/CConfigFileBase.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <stdexcept>

namespace fs = std::filesystem;

namespace devslam::io {

std::optional<core::Frame> nextDecodable(RgbdReader& reader, bool allow_damaged,
                                         std::vector<std::string>& undecodable) {
    while (true) {
        try {
            return reader.next();
        } catch (const InputBroken&) {
            throw;
        } catch (const std::exception& e) {
            if (!allow_damaged) throw;
            undecodable.emplace_back(e.what());
        }
    }
}

void ReaderOptions::loadFromConfig(const mrpt::config::CConfigFileBase& c, const std::string& s) {
    core::requireKnownKeys(c, s, {"camera", "max_dt", "tum_depth_scale", "sensor_label"});
    camera = c.read_string(s, "camera", camera);
    max_dt = core::readDouble(c, s, "max_dt", max_dt);
    tum_depth_scale = core::readDouble(c, s, "tum_depth_scale", tum_depth_scale);
    sensor_label = c.read_string(s, "sensor_label", sensor_label);
    // (1e9 s paired every colour image with some depth image; a scale of 1e-9 put every
    // depth beyond range: nothing tracked, and no setting was blamed)
    core::requireValue(max_dt > 0 && max_dt <= 1, s, "max_dt", "must be in (0, 1] s");
    core::requireValue(tum_depth_scale >= 10 && tum_depth_scale <= 1e6, s, "tum_depth_scale",
                       "must be in [10, 1e6] units per metre (TUM: 5000, millimetres: 1000)");
    requireCameraName(camera, "[" + s + "] camera");
}

void ReaderOptions::requireCameraName(const std::string& camera, const std::string& what) {
    try {
        if (camera != "auto") (void)core::CameraIntrinsics::fromPreset(camera);
    } catch (const std::invalid_argument& e) {
        throw std::invalid_argument(what + ": " + e.what() + " or auto");
    }
}

OpenProgressBar::OpenProgressBar(const std::string& path, std::FILE* out)
    : label_("opening " + fs::path(path).filename().string()), out_(out) {}

OpenProgressBar::~OpenProgressBar() {
    if (bar_ && bar_->shown()) bar_->finish("(not opened)");
}

std::function<bool(std::size_t, std::uint64_t, std::uint64_t)> OpenProgressBar::callback(
    std::function<bool()> stop) {
    return [this, stop = std::move(stop)](std::size_t frames, std::uint64_t read,
                                          std::uint64_t total) {
        // (whole MB, the file's size rounded up: a file under 1 MB is 1, and read through it
        // is all of it)
        const auto mb = [](std::uint64_t bytes, bool up) {
            return static_cast<std::size_t>((bytes + (up ? 999999 : 0)) / 1000000);
        };
        if (!bar_) bar_.emplace(label_, mb(total, true), out_);
        frames_ = frames;
        bar_->update(mb(read, read == total), "MB read, " + std::to_string(frames) + " frames");
        return !(stop && stop());
    };
}

void OpenProgressBar::finish() {
    if (bar_ && bar_->shown()) bar_->finish("MB read, " + std::to_string(frames_) + " frames");
}

std::unique_ptr<RgbdReader> openRgbd(const std::string& path, const ReaderOptions& opts) {
    // (error codes: a name too long or a folder that cannot be entered threw a bare
    // "filesystem error: status: ..." that named no option)
    std::error_code ec;
    const fs::file_status st = fs::status(path, ec);
    if (ec && ec != std::errc::no_such_file_or_directory && ec != std::errc::not_a_directory)
        throw std::runtime_error(path + ": " + ec.message());
    if (fs::is_directory(st)) {
        if (!fs::exists(fs::path(path) / "rgb.txt"))
            throw std::runtime_error(path + ": folder has no rgb.txt (not a TUM RGB-D folder)");
        return std::make_unique<TumReader>(path, opts);
    }
    if (fs::is_regular_file(st)) {
        std::string ext = fs::path(path).extension().string();
        std::transform(ext.begin(), ext.end(), ext.begin(),
                       [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
        if (ext == ".avi" || ext == ".mp4" || ext == ".mkv" || ext == ".mov")
            throw std::runtime_error(path +
                                     ": a video has no depth, so it is no RGB-D input (for the "
                                     "dynamic-object filter on a fixed camera's video: "
                                     "devslam-overlay --input video:FILE)");
        return std::make_unique<RawlogReader>(path, opts);
    }
    // (a device, a pipe or a socket given as the input was "no such" input, which is there;
    // an empty name was quoted as nothing at all)
    if (path.empty())
        throw std::runtime_error("the input's name is empty: give a TUM folder or rawlog");
    throw std::runtime_error(path + (fs::exists(st) ? ": neither a TUM folder nor a rawlog file"
                                                    : ": no such TUM folder or rawlog file"));
}

std::unique_ptr<RgbdReader> openRgbdWithProgress(const std::string& path, ReaderOptions opts,
                                                 std::FILE* out) {
    OpenProgressBar opening(path, out);
    opts.on_open = opening.callback([] { return core::stopSignal() != 0; });
    auto reader = openRgbd(path, opts);
    opening.finish();
    return reader;
}

}  // namespace devslam::io
