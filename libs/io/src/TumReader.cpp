#include <devslam/io/TrajectoryIO.h>
#include <devslam/io/TumReader.h>

#include "TextFile.h"

#include <devslam/core/Association.h>
#include <devslam/core/Config.h>
#include <devslam/core/Picture.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <cstdio>
#include <filesystem>
#include <map>
#include <regex>
#include <stdexcept>

namespace fs = std::filesystem;

namespace devslam::io {

namespace {
/// Why `path` is no file to read ("not found", "is a folder, not a file", "is a pipe or
/// device, not a file"), "" for a regular file: a pipe in a TUM folder blocked the reader,
/// for ever, at its opening (a signal only asks for a stop after the current frame), and a
/// folder read as empty.
std::string notAFile(const std::string& path) {
    const auto st = fs::status(path);
    if (!fs::exists(st)) return "not found";
    if (fs::is_regular_file(st)) return "";
    return fs::is_directory(st) ? "is a folder, not a file" : "is a pipe or device, not a file";
}

/// Throws "<path>: <what> <notAFile's reason>" unless `path` is a regular file.
void requireFileInFolder(const std::string& path, const std::string& what) {
    if (const std::string why = notAFile(path); !why.empty())
        throw std::runtime_error(path + ": " + what + " " + why);
}
}  // namespace

std::vector<TumListEntry> readTumList(const std::string& path) {
    requireFileInFolder(path, "file");
    std::vector<TumListEntry> out;
    std::map<std::string, int> listed;  // file -> its line
    detail::forEachDataLine(path, [&](int line, const std::vector<std::string>& tok) {
        if (tok.size() != 2)
            throw std::runtime_error(detail::lineError(
                path, line,
                "expected 'timestamp filename', got " + std::to_string(tok.size()) + " fields"));
        const double t = detail::parseNumber(tok[0], path, line, "timestamp");
        // Seconds since 1970 (TUM's) or since a start: -1 or 1e300 only left the frame unpaired.
        if (t < 0 || t > 1e11)
            throw std::runtime_error(detail::lineError(
                path, line, "timestamp " + tok[0] + " is not in [0, 1e11] s"));
        if (!out.empty() && t <= out.back().t)
            throw std::runtime_error(detail::lineError(
                path, line,
                detail::stampNotAfter(t, out.back().t, tok[0]) + " (previous entry at line " +
                    std::to_string(out.back().line) + ")"));
        // One image under two stamps is two frames of one picture (the ATE went from 0.0059
        // to 0.0077 m on fr1_xyz_first37).
        if (const auto [at, fresh] = listed.emplace(tok[1], line); !fresh)
            throw std::runtime_error(detail::lineError(
                path, line,
                "'" + tok[1] + "' is listed again (first at line " + std::to_string(at->second) +
                    ")"));
        out.push_back({t, tok[1], line});
    });
    if (out.empty()) throw std::runtime_error(path + ": no entries");
    return out;
}

std::optional<std::string> tumPresetFromName(const std::string& folder) {
    static const std::regex kFr(R"((freiburg|fr)([123]))", std::regex::icase);
    std::smatch m;
    const std::string name =
        fs::path(folder).lexically_normal().filename().string().empty()
            ? fs::path(folder).lexically_normal().parent_path().filename().string()
            : fs::path(folder).lexically_normal().filename().string();
    if (std::regex_search(name, m, kFr)) return "freiburg" + m[2].str();
    return std::nullopt;
}

void loadTumImages(const std::string& rgb_path, const std::string& depth_path, double depth_scale,
                   core::Frame& f) {
    requireFileInFolder(rgb_path, "colour image");
    requireFileInFolder(depth_path, "depth image");
    std::string why;
    cv::Mat rgb = core::readImage(rgb_path, cv::IMREAD_UNCHANGED, why);
    if (rgb.empty()) throw std::runtime_error(rgb_path + ": cannot decode colour image" + why);
    if (rgb.depth() != CV_8U)
        throw std::runtime_error(rgb_path + ": colour image must be 8 bits per channel");
    if (rgb.channels() == 1)
        cv::cvtColor(rgb, rgb, cv::COLOR_GRAY2BGR);
    else if (rgb.channels() == 4)
        cv::cvtColor(rgb, rgb, cv::COLOR_BGRA2BGR);
    cv::Mat raw = core::readImage(depth_path, cv::IMREAD_UNCHANGED, why);
    if (raw.empty()) throw std::runtime_error(depth_path + ": cannot decode depth image" + why);
    if (raw.type() != CV_16UC1)
        throw std::runtime_error(depth_path +
                                 ": depth must be a 16-bit single-channel PNG (TUM format)");
    if (raw.size() != rgb.size())
        throw std::runtime_error(depth_path + ": depth is " + std::to_string(raw.cols) + "x" +
                                 std::to_string(raw.rows) + " but " + rgb_path + " is " +
                                 std::to_string(rgb.cols) + "x" + std::to_string(rgb.rows));
    f.bgr = rgb;
    raw.convertTo(f.depth, CV_32F, 1.0 / depth_scale);
    f.depth_scale = depth_scale;
    f.rgb_source = rgb_path;
    f.depth_source = depth_path;
}

TumReader::TumReader(std::string folder, ReaderOptions opts)
    : folder_(std::move(folder)), opts_(std::move(opts)) {
    if (!fs::is_directory(folder_))
        throw std::runtime_error(folder_ + ": not a TUM RGB-D folder (not a directory)");
    const auto rgb = readTumList(folder_ + "/rgb.txt");
    const auto depth = readTumList(folder_ + "/depth.txt");
    std::vector<double> ta, tb;
    for (const auto& e : rgb) ta.push_back(e.t);
    for (const auto& e : depth) tb.push_back(e.t);
    std::vector<std::string> missing;  // one message per listed image that is not there
    std::size_t n_pairs = 0;
    for (const auto& [i, j] : core::associate(ta, tb, opts_.max_dt)) {
        ++n_pairs;
        bool complete = true;
        for (const auto* e : {&rgb[i], &depth[j]}) {
            const std::string list = e == &rgb[i] ? "/rgb.txt" : "/depth.txt";
            const std::string why = notAFile(imagePath(e->file));
            if (why.empty()) continue;
            missing.push_back(
                detail::lineError(folder_ + list, e->line, "image '" + e->file + "' " + why));
            complete = false;
        }
        if (complete) pairs_.emplace_back(rgb[i], depth[j]);
    }
    if (n_pairs == 0) {
        // Say what the two lists hold, to tell two recordings apart (readTumList refuses an
        // empty list and stamps that do not increase: first and last are the range)
        const auto span = [](const std::vector<double>& t) {
            return std::to_string(t.size()) + (t.size() == 1 ? " image" : " images") + ", stamps " +
                   detail::stampText(t.front()) + " to " + detail::stampText(t.back());
        };
        char dt[32];
        std::snprintf(dt, sizeof dt, "%g", opts_.max_dt);
        throw std::runtime_error(folder_ + ": no rgb/depth pair within " + dt +
                                 " s (rgb.txt: " + span(ta) + "; depth.txt: " + span(tb) + ")");
    }
    if (!missing.empty()) {
        damage_ = missing.front();
        if (missing.size() > 1)
            damage_ += " (and " + std::to_string(missing.size() - 1) + " more missing images)";
        damage_ += "; " + std::to_string(n_pairs - pairs_.size()) + " of " +
                   std::to_string(n_pairs) + " rgb-depth pairs left out";
        if (!opts_.allow_damaged || pairs_.empty()) throw DamagedInput(damage_, pairs_.size());
    }

    const std::string camera_ini = folder_ + "/camera.ini";
    if (opts_.intrinsics) {
        K_ = *opts_.intrinsics;
        camera_source_ = "given intrinsics";
    } else if (opts_.camera != "auto") {
        K_ = core::CameraIntrinsics::fromPreset(opts_.camera);
        camera_source_ = "preset " + opts_.camera;
    } else if (fs::exists(camera_ini)) {
        requireFileInFolder(camera_ini, "camera file");
        const auto cfg = core::loadIni(camera_ini);
        try {
            core::requireKnownSections(*cfg, {"camera"});
            K_ = core::CameraIntrinsics::fromConfig(*cfg, "camera");
        } catch (const std::exception& e) {
            throw std::runtime_error(camera_ini + ": " + e.what());
        }
        camera_source_ = "camera.ini";
    } else {
        const auto preset = tumPresetFromName(folder_);
        K_ = core::CameraIntrinsics::fromPreset(preset.value_or("ros_default"));
        camera_source_ = preset ? "preset " + *preset + " (from the folder name)"
                                : "preset ros_default (no camera.ini, folder name names no camera)";
    }
    const std::string gt = folder_ + "/groundtruth.txt";
    if (fs::exists(gt)) {
        requireFileInFolder(gt, "ground truth");
        try {
            gt_ = readTumTrajectory(gt);
        } catch (const std::runtime_error& e) {
            throw std::runtime_error(std::string(e.what()) +
                                     " (a folder without groundtruth.txt runs without ATE)");
        }
    }
}

std::string TumReader::imagePath(const std::string& listed) const {
    return fs::path(listed).is_absolute() ? listed : folder_ + "/" + listed;
}

core::Frame TumReader::read(std::size_t i) const {
    if (i >= pairs_.size())
        throw std::out_of_range(folder_ + ": frame " + std::to_string(i) + " of " +
                                std::to_string(pairs_.size()));
    const auto& [r, d] = pairs_[i];
    core::Frame f;
    f.index = i;
    f.timestamp = r.t;
    f.depth_timestamp = d.t;
    f.K = K_;
    loadTumImages(imagePath(r.file), imagePath(d.file), opts_.tum_depth_scale, f);
    if (f.K.width != f.bgr.cols || f.K.height != f.bgr.rows) {
        // Presets are for 640x480; other sizes need explicit intrinsics.
        throw std::runtime_error(f.rgb_source + ": image is " + std::to_string(f.bgr.cols) + "x" +
                                 std::to_string(f.bgr.rows) +
                                 " but the camera intrinsics are for " + std::to_string(f.K.width) +
                                 "x" + std::to_string(f.K.height));
    }
    return f;
}

std::optional<core::Frame> TumReader::next() {
    if (cursor_ >= pairs_.size()) return std::nullopt;
    return read(cursor_++);
}

std::string TumReader::describe() const {
    return "TUM folder " + folder_ + " (" + std::to_string(pairs_.size()) + " rgb-depth pairs" +
           (gt_ ? ", ground truth " + std::to_string(gt_->size()) + " poses" : "") + ", camera " +
           camera_source_ + (damage_.empty() ? "" : ", DAMAGED: " + damage_) + ")";
}

}  // namespace devslam::io
